// Spinning spheres (UberFlow §4.5: "Spherical rigid bodies can be modeled as well by using
// additional containers for angular momentum and rotation, and by updating these quantities
// according to external forces and collision impulses"). Compiled with SPIN only.
// The spin texture holds (angular velocity ω in rad/s, angle about z in rad); every particle is
// a solid sphere of radius u_spin_radius (collisions.radius), I = 2/5 m r².
// A contact with normal n (pointing to this particle) touches it at r_c = -r n. Its surface
// velocity there is v + ω × r_c; the tangential part u_t of the relative surface velocity is
// what friction removes. With K = the inverse effective mass of the tangential impulse J_t
//   K = Σ_k (1/m_k + r²/I_k) = 7/2 Σ_k 1/m_k   (a collider has infinite mass: one term),
// sticking asks J_t = -u_t / K; Coulomb's law caps |J_t| at μ J_n, J_n the normal impulse.
// Then v += J_t / m and ω += (r_c × J_t) / I = -5 / (2 m r) n × J_t on this side; the other
// side of a pair takes -J_t at its r_c = +r n, which changes its ω by the same -5/(2 m r) n × J_t
// per mass. Both impulses act at the one contact point, so Σ x × m v + I ω is conserved.

uniform float u_spin_radius;

// The angular velocity of the particle being updated (set by the pass before the colliders'
// response, read back after it).
vec3 spin_w;

// Tangential impulse J_t of a contact: u_t the slip velocity (tangential relative surface
// velocity), k = K the inverse effective mass, jn >= 0 the normal impulse, mu the friction.
vec3 spin_friction_impulse(vec3 u_t, float k, float jn, float mu) {
    vec3 j = -u_t / k;
    float cap = mu * jn;
    float len = length(j);
    return len > cap ? j * (cap / len) : j;
}

// The change of ω of a sphere of mass m touched at -r n by the impulse j.
vec3 spin_from_impulse(vec3 n, vec3 j, float m) {
    return -5.0 / (2.0 * m * u_spin_radius) * cross(n, j);
}

// Latta eq. 4-5 for a spinning sphere against a collider (per unit mass): the normal velocity
// v_n becomes -eps v_n (J_n / m = (1 + eps) |v_n|); friction mu is Coulomb's, on the slip
// v_t - r ω × n of the contact point, and it turns ω (spin_w) as it slows v.
vec3 spin_collider_response(vec3 v, vec3 n, float vn, float mu, float eps) {
    vec3 u = v - u_spin_radius * cross(spin_w, n);
    vec3 u_t = u - dot(u, n) * n;
    vec3 j = spin_friction_impulse(u_t, 3.5, (1.0 + eps) * -vn, mu);
    spin_w += spin_from_impulse(n, j, 1.0);
    return v - (1.0 + eps) * vn * n + j;
}
