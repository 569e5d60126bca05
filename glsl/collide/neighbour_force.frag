// Neighbour forces over the sorted grid (UberFlow §6: "any physical model that requires access
// to adjacent particles"): for every particle of the cell-sorted layout, the sum of the forces
// of the particles the exact detection's search visits in the 27 cells around it, or on a cell
// below 2r those within u_search_radius = 2r (collide/cells.glsl): with DEM, the contact force
// of collide/dem.glsl from each one closer than 2r; with N_PAIR user hooks ([[forces.pair]],
// spliced in front of this file as pair_force_0..3 by src/sim/collide/neighbours.rs), each
// hook's force from each one closer than its radius. Output: (summed force in N, neighbours in
// contact (closer than 2r)). The search walks at most EXACT_SCAN particles per run of cells
// (its density limit).

#include "common/state.glsl"
#include "collide/cells.glsl"

uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform float u_radius;

#include "common/mass.glsl"

#ifdef DEM
#include "collide/dem.glsl"
#endif
#ifndef N_PAIR
#define N_PAIR 0
#endif
#if N_PAIR > 0
uniform vec4 u_pair_radius;     // each hook's reach (m), at most the cell
#endif

layout(location = 0) out vec4 o_force;

vec3 g_x;
vec3 g_v;
int g_type;
float g_mass;
vec3 g_force = vec3(0.0);
float g_contacts = 0.0;

// A neighbour that can add a force: live, and with PARTNER_MASK closer than the contact (2r) or
// a hook's reach; a farther one adds exact zeros (worked as visited, every live one is worked).
bool is_partner(vec4 q) {
    if (!(q.w > 0.0)) return false;
#ifdef PARTNER_MASK
    float reach = 2.0 * u_radius;
#if N_PAIR > 0
    // (A hook not in the scene has radius 0.)
    vec4 hooks = u_pair_radius;
    reach = max(reach, max(max(hooks.x, hooks.y), max(hooks.z, hooks.w)));
#endif
    return length(q.xyz - g_x) < reach;
#else
    return true;
#endif
}

// The forces of the partner at tj, at position q.
void partner_work(int j, ivec2 tj, vec4 q) {
    vec3 w = texelFetch(u_velocity, tj, 0).xyz;
    float dist = length(q.xyz - g_x);
    if (dist < 2.0 * u_radius) g_contacts += 1.0;
#ifdef DEM
    g_force += dem_force(g_x, g_v, q.xyz, w, u_radius);
#endif
#if N_PAIR > 0
    vec4 st = texelFetch(u_static, tj, 0);
    int type_j = int(st.y);
    float mass_j = 1.0 / particle_inv_mass(type_j, st.w);
    if (dist < u_pair_radius.x) {
        g_force += pair_force_0(g_x, g_v, g_type, g_mass, q.xyz, w, type_j, mass_j, dist);
    }
#endif
#if N_PAIR > 1
    if (dist < u_pair_radius.y) {
        g_force += pair_force_1(g_x, g_v, g_type, g_mass, q.xyz, w, type_j, mass_j, dist);
    }
#endif
#if N_PAIR > 2
    if (dist < u_pair_radius.z) {
        g_force += pair_force_2(g_x, g_v, g_type, g_mass, q.xyz, w, type_j, mass_j, dist);
    }
#endif
#if N_PAIR > 3
    if (dist < u_pair_radius.w) {
        g_force += pair_force_3(g_x, g_v, g_type, g_mass, q.xyz, w, type_j, mass_j, dist);
    }
#endif
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    if (p.w > 0.0) {
        vec4 st = texelFetch(u_static, t, 0);
        g_x = p.xyz;
        g_v = texelFetch(u_velocity, t, 0).xyz;
        g_type = int(st.y);
        g_mass = 1.0 / particle_inv_mass(g_type, st.w);
        search_around(t.y * u_key_width + t.x, g_x);
    }
    o_force = vec4(g_force, g_contacts);
}
