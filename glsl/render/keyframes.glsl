// Colour and opacity by relative age (Latta §3.4.6, which uses four keyframes): up to eight
// keyframes of age make linear segments, converted on the CPU into the form the GPU evaluates
// cheaply, colour = offset + age · slope per segment (KeyframeRamp in src/render/keyframes.rs is
// the CPU twin: fewer keyframes are padded with the last, the colour is held before the first and
// after the last). "These keyframes are defined for each particle type": one set per type,
// uploaded with the type data (ParticleStyle::set_keyframes).
// State conventions: position.w is the remaining life, statics.z the total life (0 or +inf:
// permanent, relative age 0). Also the finiteness tests the vertex stage uses.

uniform vec4 u_key_age[8];      // per type (2·type, 2·type + 1): the eight keyframe ages, ascending
uniform vec4 u_key_offset[32];  // per type and segment (8·type + k): colour at age 0 of the line
uniform vec4 u_key_slope[32];   // per type and segment: change of colour per unit of age

// Finite (neither inf nor NaN), tested on the exponent bits so that no fast-math assumption
// about NaN can remove the test.
bool is_finite(float x) {
    return (floatBitsToUint(x) & 0x7F800000u) != 0x7F800000u;
}

bool all_finite(vec4 v) {
    uvec4 e = floatBitsToUint(v) & uvec4(0x7F800000u);
    return all(notEqual(e, uvec4(0x7F800000u)));
}

float relative_age(float remaining, float total) {
    if (!is_finite(total) || !(total > 0.0)) {
        return 0.0;
    }
    return clamp(1.0 - remaining / total, 0.0, 1.0);
}

// Colour of particle type `type` (0..3) at relative age `age`.
vec4 keyframe_color_of(int type, float age) {
    vec4 lo = u_key_age[2 * type];
    vec4 hi = u_key_age[2 * type + 1];
    age = max(age, lo.x);
    // The segment: how many keyframes after the first have an age at or below `age`.
    vec3 past_lo = vec3(greaterThanEqual(vec3(age), lo.yzw));
    vec4 past_hi = vec4(greaterThanEqual(vec4(age), hi));
    int k = 8 * type + int(dot(past_lo, vec3(1.0)) + dot(past_hi, vec4(1.0)));
    return u_key_offset[k] + age * u_key_slope[k];
}

// Colour of type 0 (the CPU engine's points: one set for the scene).
vec4 keyframe_color(float age) {
    return keyframe_color_of(0, age);
}
