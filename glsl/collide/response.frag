// Collision response (UberFlow §4.5) for spheres of radius u_radius, then the boundary
// conditions (§4.6). Each fragment updates its own particle from its mutual partner: the closer
// of the partner found in this layout (PARTNER 1) and, with STAGGERED, the one found on the
// staggered lattice (PARTNER 2, whose index is a texel of the textures bound as u_position2,
// u_velocity2, u_static2: the first layout, or where that holds positions alone the state the
// first sort read, src/sim/collide/lattices.rs).
// The pair is backed up to first contact, exchanges momentum if approaching, and what still
// overlaps is separated along the line of centres, mass-weighted (collide/pair.glsl). Both
// particles of a mutual pair compute the same change with opposite signs. With SPIN the spin
// texture (angular velocity, angle) is read and written alongside (collide/spin.glsl).

#include "common/state.glsl"
#include "common/precision.glsl"

uniform sampler2D u_position;
uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform sampler2D u_partner;        // this layout's detection
#ifdef STAGGERED
uniform sampler2D u_partner2;       // the other lattice's detection, gathered into this layout
uniform sampler2D u_position2;      // the state its partners' indices name
uniform sampler2D u_velocity2;
uniform sampler2D u_static2;
#endif
uniform int u_width;
#ifdef SPIN
uniform sampler2D u_spin;
#ifdef STAGGERED
uniform sampler2D u_spin2;
#endif
#endif

#include "common/mass.glsl"

#include "collide/pair.glsl"

vec3 advance(vec3 x, vec3 v, vec3 vb) {
    return x + vb * u_dt;
}

#if HAS_COLLIDERS
#include "sim/colliders.glsl"
#endif

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;
#ifdef SPIN
layout(location = 2) out vec4 o_spin;
#endif

void respond(inout vec3 x, inout vec3 v, vec4 st, vec4 q, vec3 w, vec4 st_q, vec3 wq) {
#ifdef SPIN
    pair_wi = spin_w;
    pair_wj = wq;
#endif
    vec3 dv = vec3(0.0);
    vec3 dx = vec3(0.0);
    pair_response(x, v, 1.0 / particle_inv_mass(int(st.y), st.w), st.w, q.xyz, w,
                  1.0 / particle_inv_mass(int(st_q.y), st_q.w), st_q.w, 1.0, 1.0, dv, dx);
    v += dv;
    x += dx;
#ifdef SPIN
    spin_w += pair_dw;
#endif
}

// The partner's spin, from this layout's spin texture (or, `other`, the other layout's).
vec3 partner_spin(ivec2 j, bool other) {
#ifdef SPIN
#ifdef STAGGERED
    if (other) return texelFetch(u_spin2, j, 0).xyz;
#endif
    return texelFetch(u_spin, j, 0).xyz;
#else
    return vec3(0.0);
#endif
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 v4 = texelFetch(u_velocity, t, 0);
    vec4 st = texelFetch(u_static, t, 0);
    vec3 x = p.xyz;
    vec3 v = v4.xyz;
#ifdef SPIN
    vec4 spin = texelFetch(u_spin, t, 0);
    spin_w = spin.xyz;
#endif
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
                    texelFetch(u_static, j, 0), partner_spin(j, false));
        }
#ifdef STAGGERED
        else if (c2.x >= 0.0) {
            ivec2 j = particle_texel(int(c2.x), u_width);
            respond(x, v, st, texelFetch(u_position2, j, 0), texelFetch(u_velocity2, j, 0).xyz,
                    texelFetch(u_static2, j, 0), partner_spin(j, true));
        }
#endif
#if HAS_COLLIDERS
        keep_outside_bouncing(x, v);
#endif
    }
    o_position = fp_store(vec4(x, p.w));
    o_velocity = fp_store(vec4(v, v4.w));
#ifdef SPIN
    o_spin = vec4(spin_w, spin.w);
#endif
}
