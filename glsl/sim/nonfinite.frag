// Non-finite particle state, counted on the GPU: a pass that counts non-finite values (a
// reduction) lets the engine report them instead of rendering garbage (docs/numerics.md).
// A reduction by fragment passes only, as 2004 hardware would do it (src/sim/nonfinite.rs):
//   MARK  each output texel covers a BLOCK x BLOCK tile of the state and counts, over the texels
//         of the tile that lie inside u_src_size (any size, odd ones included):
//           r  live particles with a non-finite component: position xyzw or velocity xyz
//           g  live particles
//           b  live particles with a non-finite position (xyzw)
//           a  texels whose life is NaN: neither alive nor dead, lost state
//   SUM   each output texel sums a BLOCK x BLOCK tile of the previous level.
// Live means position.w > 0 (the pipeline's convention, pipeline.md), dead particles sit at +inf
// by design and are not counted. Every test is on the bits (floatBitsToUint): comparisons with
// NaN cannot be trusted on every driver, and isnan() may be optimised away.
// Counts are floats, exact while one texel's count stays at most 2^24; the caller stops the
// reduction before a texel could cover more and sums the last level on the CPU.

uniform sampler2D u_src;       // MARK: positions (xyz, life); SUM: the previous level
#ifdef VELOCITY
uniform sampler2D u_velocity;  // MARK: velocities, or Verlet's previous positions (xyz read)
#endif
// MARK with N_EXTRA (1 to 4): the user's states (`[[state]]`, all four components read) count
// too: r counts a live particle once whichever of its textures is not finite. HALF_k: extra k
// is a half-float texture, whose overflow some drivers write as infinity and others (llvmpipe)
// clamp to the largest half, 65504: that value counts as overflowed too.
#if N_EXTRA > 0
uniform sampler2D u_extra0;
#endif
#if N_EXTRA > 1
uniform sampler2D u_extra1;
#endif
#if N_EXTRA > 2
uniform sampler2D u_extra2;
#endif
#if N_EXTRA > 3
uniform sampler2D u_extra3;
#endif
uniform ivec2 u_src_size;

layout(location = 0) out vec4 o_count;

bool non_finite(float x) {
    return (floatBitsToUint(x) & 0x7f800000u) == 0x7f800000u;
}

bool any_non_finite(vec3 v) {
    return non_finite(v.x) || non_finite(v.y) || non_finite(v.z);
}

bool half_overflow(vec4 v) {
    return any(greaterThanEqual(abs(v), vec4(65504.0)));
}

bool is_nan(float x) {
    return (floatBitsToUint(x) & 0x7fffffffu) > 0x7f800000u;
}

// w > 0 on the bits: sign clear, not +0, not NaN (+inf is a live, non-finite life).
bool alive(float w) {
    uint u = floatBitsToUint(w);
    return u != 0u && u <= 0x7f800000u;
}

void main() {
    ivec2 base = ivec2(gl_FragCoord.xy) * BLOCK;
    vec4 sum = vec4(0.0);
    for (int j = 0; j < BLOCK; j++) {
        for (int i = 0; i < BLOCK; i++) {
            ivec2 t = base + ivec2(i, j);
            if (t.x >= u_src_size.x || t.y >= u_src_size.y) {
                continue;
            }
#ifdef MARK
            vec4 p = texelFetch(u_src, t, 0);
            if (alive(p.w)) {
                bool bad_position = any_non_finite(p.xyz) || non_finite(p.w);
                bool bad = bad_position;
#ifdef VELOCITY
                bad = bad || any_non_finite(texelFetch(u_velocity, t, 0).xyz);
#endif
#if N_EXTRA > 0
                vec4 e0 = texelFetch(u_extra0, t, 0);
                bad = bad || any_non_finite(e0.xyz) || non_finite(e0.w);
#ifdef HALF_0
                bad = bad || half_overflow(e0);
#endif
#endif
#if N_EXTRA > 1
                vec4 e1 = texelFetch(u_extra1, t, 0);
                bad = bad || any_non_finite(e1.xyz) || non_finite(e1.w);
#ifdef HALF_1
                bad = bad || half_overflow(e1);
#endif
#endif
#if N_EXTRA > 2
                vec4 e2 = texelFetch(u_extra2, t, 0);
                bad = bad || any_non_finite(e2.xyz) || non_finite(e2.w);
#ifdef HALF_2
                bad = bad || half_overflow(e2);
#endif
#endif
#if N_EXTRA > 3
                vec4 e3 = texelFetch(u_extra3, t, 0);
                bad = bad || any_non_finite(e3.xyz) || non_finite(e3.w);
#ifdef HALF_3
                bad = bad || half_overflow(e3);
#endif
#endif
                sum += vec4(bad ? 1.0 : 0.0, 1.0, bad_position ? 1.0 : 0.0, 0.0);
            } else if (is_nan(p.w)) {
                sum.a += 1.0;
            }
#else
            sum += texelFetch(u_src, t, 0);
#endif
        }
    }
    o_count = sum;
}
