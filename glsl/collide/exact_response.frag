// Exact detection, second pass: the response (beyond UberFlow §4.5). Each particle visits the
// particles the count pass visited again (collide/cells.glsl). Of its partners (closer than
// 2r), the momentum exchange of collide/pair.glsl is applied with one only: the closest it
// approaches, and only if that partner's is this particle too (a mutual pair, weight 1). Such
// pairs are disjoint, so every exchange is a two-body collision on its own: momentum is
// conserved, and kinetic energy is kept exactly at e = 1 and lost only by (1 - e^2) of the
// normal relative energy below it. (Splitting one impulse over every partner with weights
// 1/max(n_i, n_j) made even e = 1 inelastic: a weight 1/2 leaves the normal approach at 0.)
// Contacts left unmatched are matched by the next iteration, which sorts again. The separation
// of what overlaps acts on every partner at full weight, positions only: the same on both
// sides, so the centre of mass stays put. (Weighted 1/max(n_i, n_j), it moved a particle by no
// more than its deepest overlap but left the collide pile 11.6 % of a diameter deep with 4
// iterations; at full weight 2.6 %: docs/collisions.md.) Then the boundary conditions (§4.6).

// It walks only the particles the count found partners for: the walking floor of `bench scene`
// (bench/fetch_floor.frag), which walks every live particle, does not bound it.
#define WALKS_SOME 1

#include "common/state.glsl"
#include "common/precision.glsl"
#include "collide/cells.glsl"

uniform sampler2D u_position;   // the cell-sorted layout
uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform sampler2D u_counts;     // first pass: (partners, truncated, closest, its distance)
#ifdef SPIN
uniform sampler2D u_spin;       // angular velocity, angle (collide/spin.glsl)
#endif

#include "common/mass.glsl"

#ifndef EXACT_PUSH
#define EXACT_PUSH 1.0
#endif

#include "collide/pair.glsl"

vec3 advance(vec3 x, vec3 v, vec3 vb) {
    return x + vb * u_dt;
}

#if HAS_COLLIDERS
#include "sim/colliders.glsl"
#endif

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;
#ifdef SPIN
layout(location = 2) out vec4 o_spin;
#endif

vec3 g_x;
vec3 g_v;
vec4 g_st;
float g_n;
int g_closest;
int g_self;
vec3 g_dv = vec3(0.0);
vec3 g_dx = vec3(0.0);

void visit(int j) {
    ivec2 tj = key_texel(j);
    vec4 q = texelFetch(u_position, tj, 0);
    if (!(q.w > 0.0)) return;
    vec3 d = g_x - q.xyz;
    if (!(dot(d, d) < 4.0 * u_radius * u_radius)) return;
    vec4 st_q = texelFetch(u_static, tj, 0);
    vec4 c_j = texelFetch(u_counts, tj, 0);
    bool matched = j == g_closest && int(c_j.z) == g_self;
#ifdef SPIN
    pair_wi = spin_w;
    pair_wj = texelFetch(u_spin, tj, 0).xyz;
#endif
    pair_response(g_x, g_v, 1.0 / particle_inv_mass(int(g_st.y), g_st.w), g_st.w, q.xyz,
                  texelFetch(u_velocity, tj, 0).xyz, 1.0 / particle_inv_mass(int(st_q.y), st_q.w),
                  st_q.w, matched ? 1.0 : 0.0, EXACT_PUSH, g_dv, g_dx);
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 v4 = texelFetch(u_velocity, t, 0);
    g_st = texelFetch(u_static, t, 0);
    vec3 x = p.xyz;
    vec3 v = v4.xyz;
#ifdef SPIN
    vec4 spin = texelFetch(u_spin, t, 0);
    spin_w = spin.xyz;
#endif
    if (p.w > 0.0) {
        vec4 c = texelFetch(u_counts, t, 0);
        g_n = c.x;
        g_closest = int(c.z);
        g_self = t.y * u_key_width + t.x;
        if (g_n > 0.0) {
            g_x = x;
            g_v = v;
            search_around(g_self, x);
            x += g_dx;
            v += g_dv;
#ifdef SPIN
            spin_w += pair_dw;
#endif
        }
#if HAS_COLLIDERS
        keep_outside_bouncing(x, v);
#endif
    }
    o_position = fp_store(vec4(x, p.w));
    o_velocity = fp_store(vec4(v, v4.w));
#ifdef SPIN
    o_spin = vec4(spin_w, spin.w);
#endif
}
