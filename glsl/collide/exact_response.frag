// Exact detection, second pass: the response (beyond UberFlow §4.5), without a walk: the count
// pass (collide/exact_count.frag) summed over every partner (closer than 2r) the separation of
// what overlaps, in two versions. Of its partners the momentum exchange of collide/pair.glsl is
// applied with one only: the closest it approaches, and only if that partner's is this particle
// too (a mutual pair, weight 1). Such pairs are disjoint, so every exchange is a two-body
// collision on its own: momentum is conserved, and kinetic energy is kept exactly at e = 1 and
// lost only by (1 - e^2) of the normal relative energy below it. (Splitting one impulse over
// every partner with weights 1/max(n_i, n_j) made even e = 1 inelastic: a weight 1/2 leaves the
// normal approach at 0.) Contacts left unmatched are matched by the next iteration, which sorts
// again. The separation of what overlaps acts on every partner at full weight, positions only:
// the same on both sides, so the centre of mass stays put. (Weighted 1/max(n_i, n_j), it moved a
// particle by no more than its deepest overlap but left the collide pile 11.6 % of a diameter
// deep with 4 iterations; at full weight 2.6 %: docs/collisions.md.) So a matched particle takes
// the count's sum with the exchange and the exchange's change of velocity (computed again here
// from the pair alone, as the count computed it), an unmatched one the separations alone. Then
// the boundary conditions (§4.6).

#include "common/state.glsl"
#include "common/precision.glsl"
#include "collide/sorted_keys.glsl"

uniform sampler2D u_position;   // the cell-sorted layout
uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform sampler2D u_counts;     // count pass: (partners, truncated, closest, its distance)
uniform sampler2D u_separation; // count pass: Σ separations (not matched)
uniform sampler2D u_exchanged;  // count pass: Σ with the closest partner's exchange (matched)
#ifdef SPIN
uniform sampler2D u_spin;       // angular velocity, angle (collide/spin.glsl)
#endif

#include "common/mass.glsl"

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

// Adds the exchange with the matched partner at sorted index j to v (and the spin's to spin_w),
// as the count pass computed it for its sum: the same call, alone.
void exchange(int j, vec3 x, inout vec3 v, vec4 st) {
    ivec2 tj = key_texel(j);
    vec4 st_q = texelFetch(u_static, tj, 0);
#ifdef SPIN
    pair_wi = spin_w;
    pair_wj = texelFetch(u_spin, tj, 0).xyz;
#endif
    vec3 dv = vec3(0.0);
    vec3 dx = vec3(0.0);
    pair_response(x, v, 1.0 / particle_inv_mass(int(st.y), st.w), st.w,
                  texelFetch(u_position, tj, 0).xyz, texelFetch(u_velocity, tj, 0).xyz,
                  1.0 / particle_inv_mass(int(st_q.y), st_q.w), st_q.w, 1.0, 1.0, dv, dx);
    v += dv;
#ifdef SPIN
    spin_w += pair_dw;
#endif
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 v4 = texelFetch(u_velocity, t, 0);
    vec3 x = p.xyz;
    vec3 v = v4.xyz;
#ifdef SPIN
    vec4 spin = texelFetch(u_spin, t, 0);
    spin_w = spin.xyz;
#endif
    if (p.w > 0.0) {
        // The count's outputs lie in the walk's order (collide/sorted_keys.glsl).
        int self = t.y * u_key_width + t.x;
        ivec2 w = walk_texel(self);
        vec4 c = texelFetch(u_counts, w, 0);
        if (c.x > 0.0) {
            int closest = int(c.z);
            bool matched = closest >= 0
                && int(texelFetch(u_counts, walk_texel(closest), 0).z) == self;
            if (matched) {
                exchange(closest, x, v, texelFetch(u_static, t, 0));
                x += texelFetch(u_exchanged, w, 0).xyz;
            } else {
                x += texelFetch(u_separation, w, 0).xyz;
            }
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
