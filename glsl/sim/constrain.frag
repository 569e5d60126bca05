// One relaxation pass of the distance constraints (Latta §3.4.3: after the Verlet step,
// "other constraints can be used to limit the distance between a pair or group of particles,
// which is useful for particle simulation of cloth or hair"; the relaxation follows
// Jakobsen 2001, which Latta cites). The Jacobi scheme (scheme = "jacobi"; sim/constrain_set.frag
// is the Gauss-Seidel one): every texel reads its neighbours' positions of the last pass by
// texelFetch and moves itself by the mean of its corrections, so one pass needs no order between
// particles.
//   CLOTH  neighbours ±x, ±y (structural) and the four diagonals (shear)
//   HAIR   neighbours ±x: every row is a strand, texel 0 its root
// Rest lengths are distances in the rest texture (the initial layout; w = 1 pinned). For each
// neighbour the correction is sim/constraint.glsl's edge_correction. The texel moves by
// stiffness × the mean of its corrections; a pinned texel goes to its rest position plus u_pin_offset (hair roots follow their sphere). Last, the
// colliders' projection (sim/colliders.glsl, the Verlet step's keep_outside) puts a particle that
// the correction pushed into a collider back on its surface.
// src/sim/reference/constraints.rs is the CPU twin: keep the two in step.

#include "common/state.glsl"
#include "common/precision.glsl"

#include "sim/constraint.glsl"

#ifdef HAIR
const int N_NEIGHBOURS = 2;
const ivec2 NEIGHBOURS[2] = ivec2[2](ivec2(1, 0), ivec2(-1, 0));
#else
const int N_NEIGHBOURS = 8;
const ivec2 NEIGHBOURS[8] = ivec2[8](ivec2(1, 0), ivec2(-1, 0), ivec2(0, 1), ivec2(0, -1),
                                     ivec2(1, 1), ivec2(-1, -1), ivec2(1, -1), ivec2(-1, 1));
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
    vec3 x = p.xyz;
    vec3 sum = vec3(0.0);
    int n = 0;
    for (int k = 0; k < N_NEIGHBOURS; k++) {
        ivec2 q = t + NEIGHBOURS[k];
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, u_size))) continue;
        vec3 xq = texelFetch(u_position, q, 0).xyz;
        sum += edge_correction(x, r.xyz, xq, texelFetch(u_rest, q, 0));
        n++;
    }
    vec3 xn = x + (u_stiffness / float(max(n, 1))) * sum;
    o_position = fp_store(vec4(outside(xn), p.w));
}
