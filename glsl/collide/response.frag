// Collision response (UberFlow §4.5) for spheres of radius u_radius, then the boundary
// conditions (§4.6). Each fragment updates its own particle from its mutual partner: the closer
// of the partner found in this layout (PARTNER 1) and, with STAGGERED, the one found on the
// staggered lattice (PARTNER 2, whose index refers to the other layout's textures).
// Both are backed up in time to first contact, |x_ij - v_ij tau| = 2r (tau at most dt), exchange
// momentum along the contact normal with restitution e (elastic: kinetic energy conserved too),
//   v_i' = v_i - (1 + e) m_j / (m_i + m_j) ((v_i - v_j) . n) n,
// and advance by tau again with the new velocity. Both particles of a pair compute the same
// impulse with opposite signs, so linear momentum is conserved to rounding. Coincident centres
// take a fixed normal, +y or -y by the particles' random numbers, so the pair still agrees.

#include "common/state.glsl"
#include "common/precision.glsl"

uniform sampler2D u_position;
uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform sampler2D u_partner;        // this layout's detection
#ifdef STAGGERED
uniform sampler2D u_partner2;       // the other lattice's detection, gathered into this layout
uniform sampler2D u_position2;      // the other layout's state
uniform sampler2D u_velocity2;
uniform sampler2D u_static2;
#endif
uniform int u_width;
uniform float u_radius;
uniform float u_restitution;
uniform float u_dt;
uniform vec4 u_inv_mass;

vec3 advance(vec3 x, vec3 v, vec3 vb) {
    return x + vb * u_dt;
}

#if HAS_COLLIDERS
#include "sim/colliders.glsl"
#endif

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

void respond(inout vec3 x, inout vec3 v, vec4 st, vec4 q, vec3 w, vec4 st_q) {
    float mi = 1.0 / u_inv_mass[int(st.y)];
    float mj = 1.0 / u_inv_mass[int(st_q.y)];
    vec3 dx = x - q.xyz;
    vec3 dv = v - w;
    float vv = dot(dv, dv);
    float xv = dot(dx, dv);
    float c = dot(dx, dx) - 4.0 * u_radius * u_radius;
    float tau = 0.0;
    if (vv > 0.0) {
        tau = clamp((xv + sqrt(max(xv * xv - vv * c, 0.0))) / vv, 0.0, u_dt);
    }
    vec3 xc = dx - dv * tau;
    float len = length(xc);
    vec3 n = len > 0.0 ? xc / len : vec3(0.0, st.w < st_q.w ? 1.0 : -1.0, 0.0);
    float vn = dot(dv, n);
    if (vn >= 0.0) return;   // separating at contact: nothing to do
    vec3 back = x - v * tau;
    v -= (1.0 + u_restitution) * mj / (mi + mj) * vn * n;
    x = back + v * tau;
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 v4 = texelFetch(u_velocity, t, 0);
    vec4 st = texelFetch(u_static, t, 0);
    vec3 x = p.xyz;
    vec3 v = v4.xyz;
    if (p.w > 0.0) {
        vec4 c1 = texelFetch(u_partner, t, 0);
        float d1 = c1.x >= 0.0 ? c1.y : 1e30;
#ifdef STAGGERED
        vec4 c2 = texelFetch(u_partner2, t, 0);
        float d2 = c2.x >= 0.0 ? c2.y : 1e30;
#else
        float d2 = 1e30;
#endif
        if (d1 <= d2 && c1.x >= 0.0) {
            ivec2 j = particle_texel(int(c1.x), u_width);
            respond(x, v, st, texelFetch(u_position, j, 0), texelFetch(u_velocity, j, 0).xyz,
                    texelFetch(u_static, j, 0));
        }
#ifdef STAGGERED
        else if (c2.x >= 0.0) {
            ivec2 j = particle_texel(int(c2.x), u_width);
            respond(x, v, st, texelFetch(u_position2, j, 0), texelFetch(u_velocity2, j, 0).xyz,
                    texelFetch(u_static2, j, 0));
        }
#endif
#if HAS_COLLIDERS
        keep_outside(x, v);
#endif
    }
    o_position = fp_store(vec4(x, p.w));
    o_velocity = fp_store(vec4(v, v4.w));
}
