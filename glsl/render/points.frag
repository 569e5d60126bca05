// Colour by age for additive fire: white-yellow at birth, orange, red, fading out.
// Written with additive blending (GL_SRC_ALPHA, GL_ONE), so the order of particles is irrelevant
// and no sort is needed. With u_soft (render.mode = "sprites") each point is a round sprite whose
// opacity falls smoothly to 0 at its rim, (1 - r^2)^2, instead of the thesis's hard square: the
// thesis names the look of plain points a flaw to improve on (§4.1, §4.5.1).

uniform float u_intensity;
uniform int u_soft;

in float v_age;
layout(location = 0) out vec4 o_color;

vec3 fire_ramp(float a) {
    vec3 c0 = vec3(1.0, 0.95, 0.7);
    vec3 c1 = vec3(1.0, 0.55, 0.1);
    vec3 c2 = vec3(0.75, 0.12, 0.02);
    vec3 c3 = vec3(0.15, 0.05, 0.03);
    if (a < 0.25) return mix(c0, c1, a / 0.25);
    if (a < 0.6) return mix(c1, c2, (a - 0.25) / 0.35);
    return mix(c2, c3, (a - 0.6) / 0.4);
}

void main() {
    // Fade in over the first tenth of the life (no hard edge at the emitter), then out.
    float fade = smoothstep(0.0, 0.1, v_age) * pow(1.0 - v_age, 1.5);
    if (u_soft != 0) {
        vec2 c = gl_PointCoord * 2.0 - 1.0;
        float k = max(1.0 - dot(c, c), 0.0);
        fade *= k * k;
    }
    o_color = vec4(fire_ramp(v_age), u_intensity * fade);
}
