// The cloth's shading: Lambert from one fixed light plus an ambient term, in the scene's colour,
// lit on the side facing the eye (the normal flipped towards it: a sheet is seen from both
// sides). Opaque, with a depth write.

uniform vec3 u_eye;
uniform vec3 u_light;  // unit vector towards the light
uniform vec3 u_color;
uniform float u_ambient;

in vec3 v_world;
in vec3 v_normal;
in float v_ok;
layout(location = 0) out vec4 o_color;

void main() {
    if (v_ok < 0.999) {  // below 1 by more than interpolation's rounding
        discard;  // a primitive with a non-finite vertex
    }
    vec3 n = v_normal;
    float len = length(n);
    n = len > 0.0 ? n / len : vec3(0.0);
    if (dot(n, u_eye - v_world) < 0.0) {
        n = -n;
    }
    float diffuse = max(dot(n, u_light), 0.0);
    o_color = vec4(u_color * (u_ambient + (1.0 - u_ambient) * diffuse), 1.0);
}
