// The fire's colour by relative age a in [0, 1] (the GLSL fire thesis): white-yellow at birth,
// orange, red, then a dark red as it fades out.
vec3 fire_ramp(float a) {
    vec3 c0 = vec3(1.0, 0.95, 0.7);
    vec3 c1 = vec3(1.0, 0.55, 0.1);
    vec3 c2 = vec3(0.75, 0.12, 0.02);
    vec3 c3 = vec3(0.15, 0.05, 0.03);
    if (a < 0.25) return mix(c0, c1, a / 0.25);
    if (a < 0.6) return mix(c1, c2, (a - 0.25) / 0.35);
    return mix(c2, c3, (a - 0.6) / 0.4);
}
