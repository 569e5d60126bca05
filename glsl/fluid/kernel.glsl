// SPH kernel and wall terms (src/sim/fluid/mod.rs). The cubic spline of Monaghan (1992) in 3-D,
// smoothing length h, support 2h (the neighbour lattice's cell), q = r / h:
//   W(r) = 1 / (pi h^3) * (1 - 3/2 q^2 + 3/4 q^3)   for q < 1
//        = 1 / (pi h^3) * (2 - q)^3 / 4             for 1 <= q < 2, else 0.
// Wall treatment at plane colliders, for a particle at distance d in front of the plane (unit
// normal n into the fluid), as if the half-space behind it were fluid at rest density rho0 and
// the particle's own pressure (a mirror):
//   F(d) = 2 pi Int_d^2h W(r) r (r - d) dr     the kernel's volume behind the plane
//   G(d) = 2 pi Int_d^2h W(r) r dr             = -dF/dd
// With several planes, the kernel's volume in front of all of them is taken as the product
// P = prod_k (1 - F_k) (exact for a separable kernel, such as a Gaussian, at orthogonal planes;
// the sum of the F_k would count a corner's volume two or three times): the density gains
// rho0 (1 - P), and the acceleration (p/rho^2 + p/rho0^2) rho0 sum_i G_i n_i P / (1 - F_i)
// (minus the gradient of the gain, times the mirror's pressure term).
// Both in closed form (tests/fluid.rs's twin integrates them numerically).

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

// Antiderivatives of w(q) q and w(q) q^2 for the two pieces of the spline (w = W pi h^3).
vec2 wall_piece1(float q) {
    float q2 = q * q;
    return vec2(q2 * (0.5 + q2 * (-0.375 + 0.15 * q)),
                q2 * q * (1.0 / 3.0 + q2 * (-0.3 + 0.125 * q)));
}
vec2 wall_piece2(float q) {
    float q2 = q * q;
    return vec2(q2 * (1.0 + q * (-1.0 + q * (0.375 - 0.05 * q))),
                q2 * q * (2.0 / 3.0 + q * (-0.75 + q * (0.3 - q / 24.0))));
}

// (F(d), G(d)) for 0 <= d, in closed form: with delta = d / h and the integrals
// I1 = Int_delta^2 w q dq, I2 = Int_delta^2 w q^2 dq, F = 2 (I2 - delta I1), G = 2 I1 / h.
vec2 wall_integrals(float d) {
    float delta = d / u_h;
    if (delta >= 2.0) return vec2(0.0);
    vec2 i = wall_piece2(2.0) - wall_piece2(max(delta, 1.0));
    if (delta < 1.0) i += wall_piece1(1.0) - wall_piece1(delta);
    return vec2(2.0 * (i.y - delta * i.x), 2.0 * i.x / u_h);
}

#if defined(WALLS) && N_PLANES > 0
uniform vec4 u_plane[N_PLANES];   // unit normal, offset (as sim/colliders.glsl)

// The walls' share at x: (rho0 (1 - P) / rho0, and sum_i G_i n_i P / (1 - F_i)).
vec4 wall_share(vec3 x) {
    vec2 fg[N_PLANES];
    float product = 1.0;
    for (int i = 0; i < N_PLANES; i++) {
        fg[i] = wall_integrals(max(dot(u_plane[i].xyz, x) - u_plane[i].w, 0.0));
        product *= 1.0 - fg[i].x;
    }
    vec3 push = vec3(0.0);
    for (int i = 0; i < N_PLANES; i++) {
        push += fg[i].y * product / (1.0 - fg[i].x) * u_plane[i].xyz;
    }
    return vec4(1.0 - product, push);
}
#endif
