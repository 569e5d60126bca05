// Colour and opacity by relative age (Latta §3.4.6): four keyframes of age make three linear
// segments, converted on the CPU into the form the GPU evaluates cheaply, colour = offset + age ·
// slope per segment (KeyframeRamp in src/render/keyframes.rs is the CPU twin). "These keyframes
// are defined for each particle type": one set per type, uploaded with the type data
// (ParticleStyle::set_keyframes).
// State conventions: position.w is the remaining life, statics.z the total life (0 or +inf:
// permanent, relative age 0). Also the finiteness tests the vertex stage uses.

uniform vec4 u_key_age[4];      // per type: ages of the four keyframes, ascending from 0 to 1
uniform vec4 u_key_offset[12];  // per type and segment (3·type + k): colour at age 0 of the line
uniform vec4 u_key_slope[12];   // per type and segment: change of colour per unit of age

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
    vec4 a = u_key_age[type];
    int k = 3 * type + (age < a.y ? 0 : (age < a.z ? 1 : 2));
    return u_key_offset[k] + age * u_key_slope[k];
}

// Colour of type 0 (the CPU engine's points: one set for the scene).
vec4 keyframe_color(float age) {
    return keyframe_color_of(0, age);
}
