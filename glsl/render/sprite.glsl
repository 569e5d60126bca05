// Sprite attributes per particle type (Latta §3.4.6: "computed inside the vertex shader from the
// particle type parameters ... Some of them take into account the relative age of the particle
// or a pseudo-random function"): size over life and the rotation, angle = angle0 + speed · age,
// with angle0 = 2π·r and the speed drawn in the type's range by a hash of r. The CPU twins are
// in src/render/sprite.rs (SizeCurve::eval, second_random, age_seconds, sprite_angle). The type's
// sprite scale and tint, curves of the emitter's time taken at each particle's birth, are in
// render/birth_curves.glsl.

#include "render/birth_curves.glsl"

uniform ivec4 u_type_tile;    // atlas tile of each type
uniform vec4 u_spin_min;      // rotation speed range per type, radians per second
uniform vec4 u_spin_max;
uniform vec4 u_size_age[4];   // per type: relative ages of the size curve's four points
uniform vec4 u_size_scale[4]; // per type: the scale at each point
uniform float u_time;         // simulation time (the age of permanent particles)
uniform vec4 u_size_min;      // per type: the random size factor's range (Latta §3.4.6)
uniform vec4 u_size_max;
uniform vec4 u_flip_frames;   // per type: flipbook tiles (1: none)
uniform vec4 u_flip_rate;     // per type: tiles per second of age (0: the tiles over the life)

// Scale of type `type` at relative age `age`: linear on the segment it falls on.
float size_scale(int type, float age) {
    vec4 a = u_size_age[type];
    vec4 v = u_size_scale[type];
    int k = age < a.y ? 0 : (age < a.z ? 1 : 2);
    float a0 = a[k], a1 = a[k + 1];
    float t = clamp((age - a0) / max(a1 - a0, 1e-6), 0.0, 1.0);
    return v[k] + t * (v[k + 1] - v[k]);
}

// A second random number in [0, 1) from the bits of the first (lowbias32 integer hash).
float second_random(float r) {
    uint x = floatBitsToUint(r) ^ 0x9e3779b9u;
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return float(x >> 8) / 16777216.0;
}

// Age in seconds: total − remaining life, or for permanent particles the time since birth.
float age_seconds(float remaining, float total, float birth) {
    if (is_finite(total) && total > 0.0) {
        return max(total - remaining, 0.0);
    }
    return max(u_time - birth, 0.0);
}

// Birth time on the emitter's clock: the render time less the age (total − remaining life), or
// for permanent particles the stamped birth.
float birth_time(float remaining, float total, float birth) {
    if (is_finite(total) && total > 0.0) {
        return u_time - max(total - remaining, 0.0);
    }
    return birth;
}

// Screen-space angle of the sprite of a particle of type `type`, random number r, age_s seconds.
float sprite_angle(int type, float r, float age_s) {
    float speed = mix(u_spin_min[type], u_spin_max[type], second_random(r));
    return 6.28318530718 * r + speed * age_s;
}

// A third random number in [0, 1): the hash applied twice (CPU twin: third_random).
float third_random(float r) {
    return second_random(second_random(r));
}

// The particle's random size factor in the type's range, lo + (hi - lo) t: exactly 1 for [1, 1].
float random_size(int type, float r) {
    return u_size_min[type] + (u_size_max[type] - u_size_min[type]) * third_random(r);
}

// The atlas tile a flipbook shows (the thesis §2.3): the type's tile advanced by
// floor(age_s · rate) mod frames, or with no rate by floor(age · frames); wraps after four.
int flipbook_tile(int type, float age, float age_s) {
    int tile = u_type_tile[type];
    int frames = int(u_flip_frames[type] + 0.5);
    if (frames <= 1) {
        return tile;
    }
    float rate = u_flip_rate[type];
    int k = rate > 0.0 ? int(floor(age_s * rate)) % frames
                       : min(int(floor(age * float(frames))), frames - 1);
    return (tile + k) & 3;
}
