// Sphere collision response for one pair (UberFlow §4.5), as seen from particle i, and the
// separation of what still overlaps. With dx = x_i - x_j and dv = v_i - v_j:
//   back-up to first contact: tau in [0, dt] with |dx - dv tau| = 2r (dt if they overlapped
//   already at the start of the step), normal n = (dx - dv tau) / |dx - dv tau|;
//   if approaching there ((dv . n) < 0), the momentum exchange with restitution e
//     dv_i = -(1 + e) m_j / (m_i + m_j) (dv . n) n,   dv_j = +(1 + e) m_i / (m_i + m_j) (dv . n) n,
//   and both advance by tau again with the new velocity: x_i += dv_i tau;
//   then what still overlaps, depth = 2r - |x_i' - x_j'|, is removed along the line of centres,
//   mass-weighted, x_i += m_j / (m_i + m_j) depth n' (positions only: no velocity, no energy).
// Both particles of a pair compute the same numbers with opposite signs (the formulas are odd in
// dx and dv), so momentum is conserved and the centre of mass stays where it was. Kinetic energy
// never grows: with e <= 1 the exchange removes (1 - e^2) of the normal relative energy. Each
// result is scaled by the caller's weights (1 with one partner; see collide/exact_response.frag).
// Coincident centres take a fixed normal, +y or -y by the particles' random numbers hi, hj.
// With SPIN (UberFlow §4.5's spherical rigid bodies), an approaching pair also exchanges a
// tangential impulse at the contact point, Coulomb-limited by u_friction times the normal
// impulse (collide/spin.glsl): it changes both velocities and both spins (pair_wi, pair_wj in,
// pair_dw out), and is advanced over tau and weighted like the normal exchange.

uniform float u_radius;
uniform float u_restitution;
uniform float u_dt;

#ifdef SPIN
#include "collide/spin.glsl"
uniform float u_friction;
// The spins of the pair pair_response is called for (set by the caller), and particle i's
// change of spin, accumulated with the exchange's weight.
vec3 pair_wi;
vec3 pair_wj;
vec3 pair_dw = vec3(0.0);
#endif

// The separation of a pair whose centres are `sep` apart (after any exchange): what still
// overlaps, depth = 2r - |sep|, removed along sep (n where sep is 0), mu_i of it on this side.
vec3 pair_push(vec3 sep, vec3 n, float mu_i) {
    float l = length(sep);
    float depth = 2.0 * u_radius - l;
    vec3 push = vec3(0.0);
    if (depth > 0.0) {
        push = mu_i * depth * (l > 0.0 ? sep / l : n);
    }
    return push;
}

// Adds particle i's velocity change to dv and position change to dx: the exchange (and the
// move it makes over tau) times `weight`, the separation times `push_weight`.
void pair_response(vec3 x, vec3 v, float mi, float hi, vec3 xq, vec3 w, float mj, float hj,
                   float weight, float push_weight, inout vec3 dv_out, inout vec3 dx_out) {
    float reach = 2.0 * u_radius;
    vec3 dx = x - xq;
    vec3 dv = v - w;
    float c = dot(dx, dx) - reach * reach;
    if (!(c < 0.0)) return;   // not in contact
    float vv = dot(dv, dv);
    float xv = dot(dx, dv);
    float tau = 0.0;
    if (vv > 0.0) {
        tau = clamp((xv + sqrt(max(xv * xv - vv * c, 0.0))) / vv, 0.0, u_dt);
    }
    vec3 xc = dx - dv * tau;
    float len = length(xc);
    vec3 n = len > 0.0 ? xc / len : vec3(0.0, hi < hj ? 1.0 : -1.0, 0.0);
    float vn = dot(dv, n);
    float mu_i = mj / (mi + mj);
    float mu_j = mi / (mi + mj);
    vec3 di = vec3(0.0);
    vec3 dj = vec3(0.0);
    if (vn < 0.0) {
        di = -(1.0 + u_restitution) * mu_i * vn * n;
        dj = (1.0 + u_restitution) * mu_j * vn * n;
#ifdef SPIN
        // Relative surface velocity at the contact: dv + ω_i × (-r n) - ω_j × (r n).
        vec3 u = dv - u_spin_radius * cross(pair_wi + pair_wj, n);
        vec3 u_t = u - dot(u, n) * n;
        float jn = -(1.0 + u_restitution) * mi * mj / (mi + mj) * vn;
        vec3 jt = spin_friction_impulse(u_t, 3.5 * (1.0 / mi + 1.0 / mj), jn, u_friction);
        di += jt / mi;
        dj -= jt / mj;
        pair_dw += weight * spin_from_impulse(n, jt, mi);
#endif
    }
    vec3 sep = dx + weight * (di - dj) * tau;
    vec3 push = pair_push(sep, n, mu_i);
    dv_out += weight * di;
    dx_out += weight * di * tau + push_weight * push;
}

// What pair_response adds to dx_out for a pair it weighs 0 with push weight 1 (no exchange:
// the separation along the line of centres, from positions and masses alone), the same numbers
// for fewer instructions and no velocity; false, adding nothing, where the centres coincide
// (the normal then comes from the velocities: call pair_response).
bool pair_separation(vec3 x, float mi, vec3 xq, float mj, inout vec3 dx_out) {
    float reach = 2.0 * u_radius;
    vec3 dx = x - xq;
    if (!(dot(dx, dx) - reach * reach < 0.0)) return true;   // not in contact
    if (!(length(dx) > 0.0)) return false;
    dx_out += pair_push(dx, vec3(0.0), mj / (mi + mj));
    return true;
}
