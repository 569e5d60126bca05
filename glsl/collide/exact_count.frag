// Exact detection, first pass: for every particle (in the cell-sorted layout) the number of live
// particles closer than 2r in the cells around it (collide/cells.glsl: the 27 cells, or on a cell
// below 2r those within u_search_radius = 2r), and the closest of
// them that it approaches ((x_i - x_j) . (v_i - v_j) < 0): the response matches mutual closest
// pairs, so a pair that the last iteration's exchange set apart leaves its particles to match
// their other contacts in this one.
// It also sums, over the partners in the order it visits them, what the response
// (collide/exact_response.frag) adds to the position in either outcome of the matching, which
// only the closest partner's count decides: the separations alone (collide/pair.glsl, weight 0:
// not matched), and the same sum with the closest partner's exchange in its place (weight 1:
// matched). Whenever a closer approached partner is found, the second sum restarts from the
// first as it stood before that partner, so both are the response's own sum, term for term in
// the same order; the response reads one of them instead of walking the cells again.
// Outputs, at the fragment's pixel (in the walk's order: walk_texel(i) holds sorted index i's):
// (partners, 1 if a run of cells held more than EXACT_SCAN particles, sorted index of
// the closest approaching partner or -1, its distance); (Σ separations, 0); (Σ with the closest
// partner's exchange, 0).

#include "common/state.glsl"
#include "collide/cells.glsl"

uniform sampler2D u_velocity;
uniform sampler2D u_static;
#ifdef SPIN
uniform sampler2D u_spin;       // angular velocity, angle (collide/spin.glsl)
#endif

#include "common/mass.glsl"
#include "collide/pair.glsl"

layout(location = 0) out vec4 o_count;
layout(location = 1) out vec4 o_separation;
layout(location = 2) out vec4 o_exchanged;

vec3 g_x;
vec3 g_v;
float g_m;
float g_h;
int g_found = 0;
int g_closest = -1;
float g_d2 = 1e30;
vec3 g_separation = vec3(0.0);
vec3 g_exchanged = vec3(0.0);

// A partner: live, closer than 2r. A position that is not finite gives a d2 that is infinite or
// NaN, which fails the distance test as particle_live would (fewer instructions a visit).
bool is_partner(vec4 q) {
    vec3 d = g_x - q.xyz;
    return q.w > 0.0 && dot(d, d) < 4.0 * u_radius * u_radius;
}

// The work of partner j, at texel tj and position q.
void partner_work(int j, ivec2 tj, vec4 q) {
    vec3 d = g_x - q.xyz;
    float d2 = dot(d, d);
    g_found++;
    vec4 st_q = texelFetch(u_static, tj, 0);
    float m_q = 1.0 / particle_inv_mass(int(st_q.y), st_q.w);
    // What this partner adds unmatched: its separation at full weight (docs/collisions.md); the
    // exchange weighted 0 adds exact zeros.
    vec3 alone = vec3(0.0);
    vec3 dv = vec3(0.0);
    vec3 w = vec3(0.0);
    bool fetched = false;
    if (!pair_separation(g_x, g_m, q.xyz, m_q, alone)) {
        w = texelFetch(u_velocity, tj, 0).xyz;
        fetched = true;
        pair_response(g_x, g_v, g_m, g_h, q.xyz, w, m_q, st_q.w, 0.0, 1.0, dv, alone);
    }
    // Only a partner closer than the closest so far can take its place: its velocity (for the
    // approach test) is fetched only then. A tie keeps the first visited: it can cost a match,
    // never the symmetry of one (the approach test is symmetric too: both sides compute the
    // same product).
    bool closest = false;
    if (d2 < g_d2) {
        if (!fetched) w = texelFetch(u_velocity, tj, 0).xyz;
        closest = dot(d, g_v - w) < 0.0;
    }
    if (closest) {
        g_d2 = d2;
        g_closest = j;
        g_exchanged = g_separation;
#ifdef SPIN
        pair_wi = spin_w;
        pair_wj = texelFetch(u_spin, tj, 0).xyz;
#endif
        pair_response(g_x, g_v, g_m, g_h, q.xyz, w, m_q, st_q.w, 1.0, 1.0, dv,
                      g_exchanged);
    } else {
        g_exchanged += alone;
    }
    g_separation += alone;
}

void main() {
    // This fragment's particle (in the walk's order: collide/sorted_keys.glsl).
    int self = walk_index(ivec2(gl_FragCoord.xy));
    ivec2 t = key_texel(self);
    vec4 p = texelFetch(u_position, t, 0);
    if (particle_live(p)) {
        g_x = p.xyz;
        g_v = texelFetch(u_velocity, t, 0).xyz;
        vec4 st = texelFetch(u_static, t, 0);
        g_m = 1.0 / particle_inv_mass(int(st.y), st.w);
        g_h = st.w;
#ifdef SPIN
        spin_w = texelFetch(u_spin, t, 0).xyz;
#endif
        search_around(self, g_x);
    }
    o_count = vec4(float(g_found), exact_truncated ? 1.0 : 0.0, float(g_closest),
                   g_closest >= 0 ? sqrt(g_d2) : 0.0);
    o_separation = vec4(g_separation, 0.0);
    o_exchanged = vec4(g_exchanged, 0.0);
}
