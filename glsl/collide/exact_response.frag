// Exact detection, second pass: the response with every partner at once (beyond UberFlow §4.5).
// Each particle visits the particles of the 27 cells around it again (collide/cells.glsl) and
// sums the pair responses of collide/pair.glsl over all partners closer than 2r, pair (i, j)
// weighted by w_ij = 1 / max(n_i, n_j), with n the partner counts of the first pass. Both sides
// use the same weight, so momentum is conserved; and since every particle's weights sum to at
// most 1, the new velocities are (per particle) a convex combination of single-pair outcomes,
// each of which loses kinetic energy or keeps it (e <= 1): by Jensen's inequality the sum
// cannot gain any. Then the boundary conditions (§4.6).

#include "common/state.glsl"
#include "common/precision.glsl"
#include "collide/cells.glsl"

uniform sampler2D u_position;   // the cell-sorted layout
uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform sampler2D u_counts;     // first pass: (partners, truncated, 0, 0)
uniform vec4 u_inv_mass;

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

vec3 g_x;
vec3 g_v;
vec4 g_st;
float g_n;
vec3 g_dv = vec3(0.0);
vec3 g_dx = vec3(0.0);

void visit(int j) {
    ivec2 tj = ivec2(j % u_key_width, j / u_key_width);
    vec4 q = texelFetch(u_position, tj, 0);
    if (!(q.w > 0.0)) return;
    vec3 d = g_x - q.xyz;
    if (!(dot(d, d) < 4.0 * u_radius * u_radius)) return;
    vec4 st_q = texelFetch(u_static, tj, 0);
    float n_j = texelFetch(u_counts, tj, 0).x;
    pair_response(g_x, g_v, 1.0 / u_inv_mass[int(g_st.y)], g_st.w, q.xyz,
                  texelFetch(u_velocity, tj, 0).xyz, 1.0 / u_inv_mass[int(st_q.y)], st_q.w,
                  1.0 / max(max(g_n, n_j), 1.0), EXACT_PUSH, g_dv, g_dx);
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 v4 = texelFetch(u_velocity, t, 0);
    g_st = texelFetch(u_static, t, 0);
    vec3 x = p.xyz;
    vec3 v = v4.xyz;
    if (p.w > 0.0) {
        g_n = texelFetch(u_counts, t, 0).x;
        if (g_n > 0.0) {
            g_x = x;
            g_v = v;
            search_neighbours(t.y * u_key_width + t.x);
            x += g_dx;
            v += g_dv;
        }
#if HAS_COLLIDERS
        keep_outside(x, v);
#endif
    }
    o_position = fp_store(vec4(x, p.w));
    o_velocity = fp_store(vec4(v, v4.w));
}
