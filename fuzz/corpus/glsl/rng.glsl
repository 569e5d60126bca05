#define GAIN 2.0
// Uses the built-in random numbers (common/rng.glsl is already included).
vec3 force(vec3 x, vec3 v, float age, int type) {
    return GAIN * vec3(0.0, 1.0, 0.0) - 0.5 * v;
}
