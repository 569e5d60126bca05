// SPH force pass (Becker & Teschner 2007 eq. 6, 11): over the cell-sorted layout, each
// particle's acceleration from every particle j within 2h that the exact search visits
// (collide/cells.glsl), with grad W_ij = W'(r) (x_i - x_j) / r:
//   pressure   a -= m (p_i / rho_i^2 + p_j / rho_j^2) grad W_ij       (symmetric: momentum kept)
//   viscosity  a -= m Pi_ij grad W_ij, Pi_ij = -nu (v_ij . x_ij) / (r^2 + 0.01 h^2) where
//              v_ij . x_ij < 0, nu = 2 alpha h c / (rho_i + rho_j)    (Monaghan's artificial)
// and, with WALLS, the plane colliders' mirrored pressure push (fluid/kernel.glsl). The velocity gains a dt; positions are copied (they move in the next
// step's integration, which also applies gravity and the colliders), as the neighbour kick of
// collide/neighbour_apply.frag does.

#include "common/state.glsl"
#include "common/precision.glsl"
#include "collide/cells.glsl"
#include "fluid/kernel.glsl"

uniform sampler2D u_position;   // the cell-sorted layout
uniform sampler2D u_velocity;
uniform sampler2D u_density;    // (rho, p, neighbours, truncated), fluid/density.frag
uniform float u_mass;
uniform float u_rest_density;
uniform float u_alpha;          // artificial viscosity
uniform float u_sound;          // c (m/s)
uniform float u_dt;

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

vec3 g_x;
vec3 g_v;
float g_rho;
float g_p_term;   // p_i / rho_i^2
vec3 g_a = vec3(0.0);

void visit(int j) {
    ivec2 tj = ivec2(j % u_key_width, j / u_key_width);
    vec4 q = texelFetch(u_position, tj, 0);
    if (!(q.w > 0.0)) return;
    vec3 x_ij = g_x - q.xyz;
    float r = length(x_ij);
    if (!(r < 2.0 * u_h) || r == 0.0) return;
    vec2 dp = texelFetch(u_density, tj, 0).xy;
    vec3 grad = kernel_dw(r) / r * x_ij;
    float term = g_p_term + dp.y / (dp.x * dp.x);
    vec3 v_ij = g_v - texelFetch(u_velocity, tj, 0).xyz;
    float vx = dot(v_ij, x_ij);
    if (vx < 0.0) {
        float nu = 2.0 * u_alpha * u_h * u_sound / (g_rho + dp.x);
        term += -nu * vx / (r * r + 0.01 * u_h * u_h);
    }
    g_a -= u_mass * term * grad;
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
        search_neighbours(t.y * u_key_width + t.x);
#if defined(WALLS) && N_PLANES > 0
        float wall = (g_p_term + dp.y / (u_rest_density * u_rest_density)) * u_rest_density;
        g_a += wall * wall_share(g_x).yzw;
#endif
        v.xyz += g_a * u_dt;
    }
    o_position = fp_store(p);
    o_velocity = fp_store(v);
}
