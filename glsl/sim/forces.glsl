// Accelerations (Latta §3.4.2, UberFlow §4.2). Only the forces a scene has are compiled in:
// GRAVITY, N_ATTRACTORS, N_SPRINGS, N_VORTICES, DAMPING and WIND come from the scene (src/sim/particles.rs).
//   gravity     a += g                                   (an acceleration)
//   damping     a -= c v; c < 0 un-damps (Latta: eq. 1 with zero flow)
//   wind        a += k (w(x) - v), Stokes drag towards the flow field's velocity (Latta eq. 1,
//               all constants folded into k, in 1/s)
//   attractor   F = s d / (r^2 + soft^2)^(3/2) (inverse square, Plummer-softened: smooth and
//               zero at the centre) or s d/r (constant), within max_distance, d = c - x;
//               s < 0 repels
//   spring      F = -k (x - anchor)                      (harmonic oscillator)
//   vortex      F = s (a x r_perp) / max(|r_perp|, 0.1)^2: tangential around the axis,
//               magnitude s / r outside a core of radius 0.1, rising linearly from 0 inside it
//               (a Rankine vortex: smooth on the axis)
// Forces are divided by the particle's mass (Latta eq. 2): u_inv_mass[type].

// Included unconditionally: the resolver splices each file once, whatever #if surrounds it.
#include "sim/fields.glsl"

uniform vec4 u_inv_mass;
#ifdef GRAVITY
uniform vec3 u_gravity;
#endif
#ifdef DAMPING
uniform float u_damping;
#endif
#ifdef WIND
uniform sampler3D u_flow;
uniform vec3 u_flow_min;
uniform vec3 u_flow_max;
uniform ivec3 u_flow_res;
uniform float u_drag;
#endif
#if N_ATTRACTORS > 0
uniform vec4 u_attractor[N_ATTRACTORS];       // centre, strength
uniform vec4 u_attractor_shape[N_ATTRACTORS]; // constant falloff (0/1), max distance (<0: none), softening
#endif
#if N_SPRINGS > 0
uniform vec4 u_spring[N_SPRINGS];       // anchor, stiffness
#endif
#if N_VORTICES > 0
uniform vec4 u_vortex[N_VORTICES];      // point on the axis, strength
uniform vec3 u_vortex_axis[N_VORTICES]; // unit axis
#endif

vec3 acceleration(vec3 x, vec3 v, int type) {
    vec3 a = vec3(0.0);
    vec3 f = vec3(0.0);
#ifdef GRAVITY
    a += u_gravity;
#endif
#ifdef DAMPING
    a -= u_damping * v;
#endif
#ifdef WIND
    a += u_drag * (flow_sample(u_flow, u_flow_min, u_flow_max, u_flow_res, x) - v);
#endif
#if N_ATTRACTORS > 0
    for (int i = 0; i < N_ATTRACTORS; i++) {
        vec3 d = u_attractor[i].xyz - x;
        float r = length(d);
        vec4 s = u_attractor_shape[i];
        if (r > 0.0 && (s.y < 0.0 || r <= s.y)) {
            if (s.x > 0.5) {
                f += u_attractor[i].w * (d / r);
            } else {
                float q = r * r + s.z * s.z;
                f += u_attractor[i].w * d / (q * sqrt(q));
            }
        }
    }
#endif
#if N_SPRINGS > 0
    for (int i = 0; i < N_SPRINGS; i++) {
        f -= u_spring[i].w * (x - u_spring[i].xyz);
    }
#endif
#if N_VORTICES > 0
    for (int i = 0; i < N_VORTICES; i++) {
        vec3 rel = x - u_vortex[i].xyz;
        vec3 ax = u_vortex_axis[i];
        vec3 perp = rel - dot(rel, ax) * ax;
        float core = max(length(perp), 0.1);
        f += u_vortex[i].w * cross(ax, perp) / (core * core);
    }
#endif
    return a + f * u_inv_mass[type];
}
