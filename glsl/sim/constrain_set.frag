// One Gauss-Seidel pass of the distance constraints: the constraints of one set, which share no
// particle, each closing its gap (Jakobsen 2001's sequential relaxation, made parallel by graph
// colouring). The edges along each direction split into two sets by the parity of the texel they
// start at, along x (along y for vertical edges), so every texel belongs to at most one
// constraint of a set:
//   CLOTH  8 sets: (1, 0), (0, 1), (1, 1), (1, -1), each from even and from odd texels
//   HAIR   2 sets: (1, 0) from even and from odd texels
// Both ends of a constraint read the same two positions and move by opposite halves
// (sim/constraint.glsl's edge_correction), so the pass is the sequential update of that set;
// the next set's pass reads its result. A texel in no constraint of the set keeps its position;
// a pinned texel goes to its rest position plus u_pin_offset; last, the colliders' projection.
// src/sim/constraints.rs set_partner and src/sim/reference/constraints.rs are the CPU twin.

#include "common/state.glsl"
#include "common/precision.glsl"

#include "sim/constraint.glsl"

uniform int u_set;              // 0 .. sets - 1

#ifdef HAIR
const ivec2 DIRECTIONS[1] = ivec2[1](ivec2(1, 0));
#else
const ivec2 DIRECTIONS[4] = ivec2[4](ivec2(1, 0), ivec2(0, 1), ivec2(1, 1), ivec2(1, -1));
#endif

layout(location = 0) out vec4 o_position;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 r = texelFetch(u_rest, t, 0);
    if (r.w > 0.5) {
        o_position = fp_store(vec4(r.xyz + u_pin_offset, p.w));
        return;
    }
    ivec2 d = DIRECTIONS[u_set / 2];
    int along = d.x == 0 ? t.y : t.x;
    // The texel starts its edge of this set, or ends the one from t - d.
    ivec2 q = (along & 1) == (u_set & 1) ? t + d : t - d;
    vec3 xn = p.xyz;
    if (all(greaterThanEqual(q, ivec2(0))) && all(lessThan(q, u_size))) {
        vec3 xq = texelFetch(u_position, q, 0).xyz;
        xn += u_stiffness * edge_correction(p.xyz, r.xyz, xq, texelFetch(u_rest, q, 0));
    }
    o_position = fp_store(vec4(outside(xn), p.w));
}
