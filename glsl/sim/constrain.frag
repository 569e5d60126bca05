// One relaxation pass of the distance constraints (Latta §3.4.3: after the Verlet step,
// "other constraints can be used to limit the distance between a pair or group of particles,
// which is useful for particle simulation of cloth or hair"; the relaxation follows
// Jakobsen 2001, which Latta cites). Jacobi-style: every texel reads its neighbours' positions
// of the last pass by texelFetch and moves itself by the mean of its corrections, so one pass
// needs no order between particles.
//   CLOTH  neighbours ±x, ±y (structural) and the four diagonals (shear)
//   HAIR   neighbours ±x: every row is a strand, texel 0 its root
// Rest lengths are distances in the rest texture (the initial layout; w = 1 pinned). For each
// neighbour q at distance L with rest length r the correction is share (L - r) / L (x_q - x):
// half of what closes the gap (the neighbour moves the other half in its own texel), all of it
// against a pinned neighbour. The texel moves by stiffness × the mean of its corrections; a pinned
// texel goes to its rest position plus u_pin_offset (hair roots follow their sphere). Last, the
// colliders' projection (sim/colliders.glsl, the Verlet step's keep_outside) puts a particle that
// the correction pushed into a collider back on its surface.
// src/sim/reference/constraints.rs is the CPU twin: keep the two in step.

#include "common/state.glsl"
#include "common/precision.glsl"

uniform sampler2D u_position;   // positions after the Verlet step or the last pass
uniform sampler2D u_rest;       // rest position, pinned (1) or free (0)
uniform ivec2 u_size;
uniform float u_stiffness;
uniform vec3 u_pin_offset;
uniform float u_dt;

#if HAS_COLLIDERS
#include "sim/colliders.glsl"
#endif

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
        vec4 rq = texelFetch(u_rest, q, 0);
        float rest = length(rq.xyz - r.xyz);
        vec3 d = xq - x;
        float len = length(d);
        float share = rq.w > 0.5 ? 1.0 : 0.5;
        if (len > 0.0) sum += (share * (len - rest) / len) * d;
        n++;
    }
    vec3 xn = x + (u_stiffness / float(max(n, 1))) * sum;
#if HAS_COLLIDERS
    vec3 v = vec3(0.0);
    keep_outside(xn, v);
#endif
    o_position = fp_store(vec4(xn, p.w));
}
