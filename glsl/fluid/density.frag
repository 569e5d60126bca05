// SPH density pass (Monaghan 1992; Becker & Teschner 2007 eq. 2, 4): over the cell-sorted
// layout, each particle's density rho_i = m sum_j W(|x_i - x_j|) over itself and every particle
// the exact search visits around it (collide/cells.glsl: on a lattice of cell h the cells within
// 2h, the trimmed walk; on cells of 2h the 27 cells), with WALLS
// also over the ghosts of both in the plane colliders closer than 2h (fluid/kernel.glsl); and
// its pressure from Tait's equation p = B ((rho / rho0)^gamma - 1), negative pressures clamped
// to 0 (no tension).
// Output: (rho, p, neighbours within 2h, 1 if a run of three cells held more than EXACT_SCAN).

#include "common/state.glsl"
#include "collide/cells.glsl"
#include "fluid/kernel.glsl"

uniform float u_mass;           // rho0 spacing^3
uniform float u_rest_density;   // rho0
uniform float u_stiffness;      // B = rho0 c^2 / gamma
uniform float u_gamma;

layout(location = 0) out vec4 o_density;

vec3 g_x;
float g_sum = 0.0;
float g_neighbours = 0.0;

// Adds the kernel of a particle or ghost at y.
void add(vec3 y) {
    float r = length(y - g_x);
    if (r < 2.0 * u_h) g_sum += kernel_w(r);
}

bool is_partner(vec4 q) {
    return q.w > 0.0;
}

void partner_work(int j, ivec2 tj, vec4 q) {
    if (length(q.xyz - g_x) < 2.0 * u_h) g_neighbours += 1.0;
    add(q.xyz);
#ifdef FLUID_GHOSTS
    for (int k = 0; k < N_PLANES; k++) {
        if (g_near[k]) add(ghost_position(q.xyz, k));
    }
#endif
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    if (!(p.w > 0.0)) {
        o_density = vec4(0.0);
        return;
    }
    g_x = p.xyz;
    g_sum = kernel_w(0.0);
#ifdef FLUID_GHOSTS
    find_walls(g_x);
    for (int k = 0; k < N_PLANES; k++) {
        if (g_near[k]) add(ghost_position(g_x, k));
    }
#endif
    search_around(t.y * u_key_width + t.x, g_x);
    float rho = u_mass * g_sum;
    float pressure = max(0.0, u_stiffness * (pow(rho / u_rest_density, u_gamma) - 1.0));
    o_density = vec4(rho, pressure, g_neighbours, exact_truncated ? 1.0 : 0.0);
}
