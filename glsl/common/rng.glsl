// Shader random numbers: the PCG hash (Jarzynski and Olano, "Hash Functions for GPU Rendering",
// JCGT 2020), keyed by particle index, step and seed. The fire thesis (§4.1, §4.5.1) had no
// shader random number generator and names the artefacts that follows; this replaces it.
// Never fract(sin(x)): its quality depends on the driver's sin precision.

uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Start of the random stream of one particle at one step.
uint rng_seed(uint index, uint step, uint seed) {
    return pcg_hash(index ^ pcg_hash(step ^ pcg_hash(seed)));
}

// Uniform in [0, 1), 24 bits (exact in a float).
float rng_uniform(inout uint state) {
    state = pcg_hash(state);
    return float(state >> 8u) * (1.0 / 16777216.0);
}

// Uniform in [-1, 1)^3.
vec3 rng_signed3(inout uint state) {
    return vec3(rng_uniform(state), rng_uniform(state), rng_uniform(state)) * 2.0 - 1.0;
}

// Uniform on the unit disc (area-uniform: radius from the square root).
vec2 rng_disc(inout uint state) {
    float r = sqrt(rng_uniform(state));
    float a = 6.28318530718 * rng_uniform(state);
    return r * vec2(cos(a), sin(a));
}
