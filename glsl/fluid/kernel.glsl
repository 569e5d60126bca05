// SPH kernel and wall ghosts (src/sim/fluid/mod.rs). The cubic spline of Monaghan (1992) in 3-D,
// smoothing length h, support 2h (the neighbour lattice's cell), q = r / h:
//   W(r) = 1 / (pi h^3) * (1 - 3/2 q^2 + 3/4 q^3)   for q < 1
//        = 1 / (pi h^3) * (2 - q)^3 / 4             for 1 <= q < 2, else 0.
// Wall treatment at plane colliders (with WALLS): ghost particles (Colagrossi & Landrini 2003).
// A plane closer than 2h to particle i reflects i and every neighbour j the search visits:
// the ghost of j sits at x_j - 2 (n . x_j - offset) n, with j's density and pressure and its
// velocity mirrored (free slip; reversed at a no-slip plane), and counts in i's density and
// forces as a particle would.
// Every ghost within 2h of i is the reflection of a particle within 2h of i (reflection only
// moves a particle in front of the plane further away from another in front of it), so the
// search that finds the neighbours finds the ghosts too. A corner's second reflections are not
// made: there the fluid misses the kernel's volume behind both planes.

uniform float u_h;        // smoothing length (m)

const float FLUID_PI = 3.14159265358979;

float kernel_w(float r) {
    float q = r / u_h;
    float s = 1.0 / (FLUID_PI * u_h * u_h * u_h);
    if (q < 1.0) return s * (1.0 - 1.5 * q * q + 0.75 * q * q * q);
    if (q < 2.0) {
        float t = 2.0 - q;
        return s * 0.25 * t * t * t;
    }
    return 0.0;
}

// dW/dr (negative: the kernel falls with distance).
float kernel_dw(float r) {
    float q = r / u_h;
    float s = 1.0 / (FLUID_PI * u_h * u_h * u_h * u_h);
    if (q < 1.0) return s * (-3.0 * q + 2.25 * q * q);
    if (q < 2.0) {
        float t = 2.0 - q;
        return -s * 0.75 * t * t;
    }
    return 0.0;
}

#if defined(WALLS) && N_PLANES > 0
#define FLUID_GHOSTS 1
uniform vec4 u_plane[N_PLANES];   // unit normal, offset (as sim/colliders.glsl)
bool g_near[N_PLANES];            // planes closer than 2h to this fragment's particle

// Marks the planes closer than 2h to x.
void find_walls(vec3 x) {
    for (int k = 0; k < N_PLANES; k++) {
        g_near[k] = dot(u_plane[k].xyz, x) - u_plane[k].w < 2.0 * u_h;
    }
}

// The reflection of the point x in plane k.
vec3 ghost_position(vec3 x, int k) {
    return x - 2.0 * (dot(u_plane[k].xyz, x) - u_plane[k].w) * u_plane[k].xyz;
}

// The ghost's velocity of a particle with velocity v in plane k: mirrored (free slip), or
// reversed where bit k of NO_SLIP is set (colliders.plane.wall = "no_slip": the wall at rest
// halfway between the particle and its ghost).
vec3 ghost_velocity(vec3 v, int k) {
    if (((NO_SLIP >> k) & 1) != 0) return -v;
    return v - 2.0 * dot(u_plane[k].xyz, v) * u_plane[k].xyz;
}
#endif
