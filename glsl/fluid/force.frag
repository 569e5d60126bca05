// SPH force pass (Becker & Teschner 2007 eq. 6, 11): over the cell-sorted layout, each
// particle's acceleration from every particle j within 2h that the exact search visits
// (collide/cells.glsl), and with WALLS from their ghosts and its own in the plane colliders
// closer than 2h (fluid/kernel.glsl), with x_ij = x_i - x_j, r = |x_ij|, grad W_ij = W'(r) x_ij / r:
//   pressure   a -= m (p_i / rho_i^2 + p_j / rho_j^2) grad W_ij       (symmetric: momentum kept)
//   viscosity  a -= m Pi_ij grad W_ij, Pi_ij = -nu (v_ij . x_ij) / (r^2 + 0.01 h^2) where
//              v_ij . x_ij < 0, nu = 2 alpha h c / (rho_i + rho_j)    (Monaghan's artificial)
// A ghost carries its original's pressure plus the hydrostatic difference between the two
// places, 2 rho_j d_j (-g . n) for an original at distance d_j in front of a plane of normal n
// (Adami et al. 2012's wall pressure, for a mirror): the floor then holds a resting column up
// with the weight above it, instead of letting the bottom layer sink into it.
// The velocity gains a dt; positions are copied (they move in the next step's integration,
// which also applies gravity and the colliders), as the neighbour kick of
// collide/neighbour_apply.frag does.

#include "common/state.glsl"
#include "common/precision.glsl"
#include "collide/cells.glsl"
#include "fluid/kernel.glsl"

uniform sampler2D u_velocity;
uniform sampler2D u_density;    // (rho, p, neighbours, truncated), fluid/density.frag
uniform float u_mass;
uniform float u_alpha;          // artificial viscosity
uniform float u_sound;          // c (m/s)
uniform float u_dt;
uniform vec3 u_gravity;         // the scene's gravity (m/s^2), for the ghosts' pressure

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

vec3 g_x;
vec3 g_v;
float g_rho;
float g_p_term;   // p_i / rho_i^2
vec3 g_a = vec3(0.0);
bool g_walls = false;   // a plane closer than 2h: every visited neighbour's ghosts count

// Adds the force of a particle or ghost at y with velocity w, density and pressure dp.
void add(vec3 y, vec3 w, vec2 dp) {
    vec3 x_ij = g_x - y;
    float r = length(x_ij);
    if (!(r < 2.0 * u_h) || r == 0.0) return;
    vec3 grad = kernel_dw(r) / r * x_ij;
    float term = g_p_term + dp.y / (dp.x * dp.x);
    float vx = dot(g_v - w, x_ij);
    if (vx < 0.0) {
        float nu = 2.0 * u_alpha * u_h * u_sound / (g_rho + dp.x);
        term += -nu * vx / (r * r + 0.01 * u_h * u_h);
    }
    g_a -= u_mass * term * grad;
}

#ifdef FLUID_GHOSTS
// (density, pressure) of the ghost in plane k of a particle at y with (density, pressure) dp.
vec2 ghost_pressure(vec3 y, vec2 dp, int k) {
    float d = dot(u_plane[k].xyz, y) - u_plane[k].w;
    return vec2(dp.x, dp.y - 2.0 * dp.x * d * dot(u_gravity, u_plane[k].xyz));
}
#endif

// A neighbour at 2h or farther adds nothing (add() computes the same r), and away from the
// walls it has no ghost: its velocity and density are not fetched. The search visits three
// (cells of h) to six (2h) such neighbours for each one within 2h.
bool is_partner(vec4 q) {
    if (!(q.w > 0.0)) return false;
    return g_walls || length(g_x - q.xyz) < 2.0 * u_h;
}

// The force of the partner at texel tj and position q, and of its ghosts.
void partner_work(int j, ivec2 tj, vec4 q) {
    vec2 dp = texelFetch(u_density, tj, 0).xy;
    vec3 w = texelFetch(u_velocity, tj, 0).xyz;
    add(q.xyz, w, dp);
#ifdef FLUID_GHOSTS
    for (int k = 0; k < N_PLANES; k++) {
        if (g_near[k]) add(ghost_position(q.xyz, k), ghost_velocity(w, k), ghost_pressure(q.xyz, dp, k));
    }
#endif
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 v = texelFetch(u_velocity, t, 0);
    if (p.w > 0.0) {
        vec2 dp = texelFetch(u_density, t, 0).xy;
        g_x = p.xyz;
        g_v = v.xyz;
        g_rho = dp.x;
        g_p_term = dp.y / (dp.x * dp.x);
#ifdef FLUID_GHOSTS
        find_walls(g_x);
        for (int k = 0; k < N_PLANES; k++) {
            g_walls = g_walls || g_near[k];
            if (g_near[k]) add(ghost_position(g_x, k), ghost_velocity(g_v, k), ghost_pressure(g_x, dp, k));
        }
#endif
        search_around(t.y * u_key_width + t.x, g_x);
        v.xyz += g_a * u_dt;
    }
    o_position = fp_store(p);
    o_velocity = fp_store(v);
}
