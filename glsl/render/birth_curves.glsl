// A particle type's look as curves of the emitter's time (scene keys sprite_scale and tint; the
// thesis §5.2, Latta §3.4.6's type attributes): each particle keeps the value at its own birth
// time, so the vertex stage evaluates the curve there. The port of Curve::component_at in
// src/scene/curve.rs (keys linear or smooth, held before the first and after the last; plus
// amplitude · sin(2π (t / period + phase)); plus amplitude · the value noise of the seed at
// t · frequency); src/render/birth_curves.rs uploads the curves. Two slots per type: 2·type the
// sprite scale (x), 2·type + 1 the tint (RGBA).

#include "common/rng.glsl"

uniform vec4 u_curve_time[8];       // per slot: the key times (at most four)
uniform vec4 u_curve_value[32];     // per slot and key (4·slot + k): the key's value
uniform vec4 u_curve_form[8];       // per slot: keys, smooth (1) or linear (0), period (0: no sine), phase
uniform vec4 u_curve_periodic[8];   // per slot: the sine's amplitude per component
uniform vec4 u_curve_noise[8];      // per slot: the noise's amplitude per component
uniform vec4 u_curve_frequency[2];  // per slot (component slot % 4 of vector slot / 4): noise values per second (0: none)
uniform ivec4 u_curve_seed[8];      // per slot: the noise's seed per component (bits of a uint)

// value_noise in src/scene/curve.rs: a random value in [-1, 1] at every integer, smoothstep
// between.
float curve_noise(uint seed, float x) {
    float cell = floor(x);
    uint s = pcg_hash(seed);
    uint i = uint(int(cell));
    float a = float(pcg_hash(i ^ s) >> 8u) * (2.0 / 16777216.0) - 1.0;
    float b = float(pcg_hash((i + 1u) ^ s) >> 8u) * (2.0 / 16777216.0) - 1.0;
    float u = x - cell;
    return a + (b - a) * (u * u * (3.0 - 2.0 * u));
}

// The curve of `slot` at time t.
vec4 curve_at(int slot, float t) {
    vec4 form = u_curve_form[slot];
    vec4 times = u_curve_time[slot];
    int n = int(form.x + 0.5);
    // The first key after t (as Curve::keys_at): n if none.
    int next = n;
    for (int k = 3; k >= 0; --k) {
        if (k < n && times[k] > t) {
            next = k;
        }
    }
    vec4 v;
    if (next == n) {
        v = u_curve_value[4 * slot + n - 1];
    } else if (next == 0) {
        v = u_curve_value[4 * slot];
    } else {
        float t0 = times[next - 1];
        float u = (t - t0) / (times[next] - t0);
        if (form.y > 0.5) {
            u = u * u * (3.0 - 2.0 * u);
        }
        vec4 a = u_curve_value[4 * slot + next - 1];
        v = a + (u_curve_value[4 * slot + next] - a) * u;
    }
    // The terms, only where the curve has them (a constant stays its value, bit for bit).
    vec4 terms = vec4(0.0);
    bool any = false;
    if (form.z > 0.0) {
        // The turns reduced to [0, 1) first: sin stays accurate at any time.
        terms += u_curve_periodic[slot] * sin(6.28318530718 * fract(t / form.z + form.w));
        any = true;
    }
    float frequency = u_curve_frequency[slot / 4][slot % 4];
    if (frequency > 0.0) {
        uvec4 seed = uvec4(u_curve_seed[slot]);
        float x = t * frequency;
        vec4 n4 = vec4(curve_noise(seed.x, x), curve_noise(seed.y, x), curve_noise(seed.z, x),
                       curve_noise(seed.w, x));
        terms += u_curve_noise[slot] * n4;
        any = true;
    }
    return any ? v + terms : v;
}

// The sprite scale of type `type` for a particle born at `birth` seconds.
float type_scale(int type, float birth) {
    return curve_at(2 * type, birth).x;
}

// The tint of type `type` (a factor of its keyframe colour and opacity) for a particle born at
// `birth` seconds.
vec4 type_tint(int type, float birth) {
    return curve_at(2 * type + 1, birth);
}
