// Accelerations (Latta §3.4.2, UberFlow §4.2). Only the forces a scene has are compiled in:
// GRAVITY, N_ATTRACTORS, N_SPRINGS, N_VORTICES, DAMPING and WIND come from the scene (src/sim/particles/uniforms.rs).
//   gravity     a += g                                   (an acceleration)
//   damping     a -= c v; c < 0 un-damps (Latta: eq. 1 with zero flow)
//   wind        WIND_FORM 0 (drag): a += k (w(x) - v), Stokes drag towards the flow field's
//               velocity as an acceleration (k in 1/s, the same for every mass);
//               WIND_FORM 1 (latta): F += c (w(x) - v), Latta eq. 1, divided by the mass (eq. 2);
//               WIND_FORM 2 (uberflow): v' = v + w(x) + (F/m) dt, UberFlow eq. 1, the wind
//               velocity added to the velocity (wind_kick, applied by the integrator)
//   attractor   F = s d / (r^2 + soft^2)^(3/2) (inverse square, Plummer-softened: smooth and
//               zero at the centre) or s d/r (constant), within max_distance, d = c - x;
//               s < 0 repels
//   spring      F = -k (x - anchor)                      (harmonic oscillator)
//   vortex      swirl: F = s (a x r_perp) / max(|r_perp|, 0.1)^2: tangential around the axis,
//               magnitude s / r outside a core of radius 0.1, rising linearly from 0 inside it
//               (a Rankine vortex: smooth on the axis);
//               latta (Latta §3.4.2): towards the closest point on the line, d = -r_perp, with
//               an attractor's falloff: s d / (r^2 + soft^2)^(3/2) or s d / r within max_distance
// Forces are divided by the particle's mass (Latta eq. 2): particle_inv_mass of
// common/mass.glsl, which the collision response uses too.
// EMITTER_FORCES: forces of one emitter act on its particles only (force_type, the particle's
// type, is its emitter's place): gravity and damping summed per type (u_type_gravity,
// u_type_damping), and every attractor, spring and vortex has an owner type (-1: every type;
// the scene's come first, then each emitter's).

// Included unconditionally: the resolver splices each file once, whatever #if surrounds it.
#include "sim/fields.glsl"

#include "common/mass.glsl"
#ifndef WIND_FORM
#define WIND_FORM 0
#endif
// User forces ([[forces.custom]]): the integration pass of such a scene is compiled from a root
// that splices the user's files first, each with `force` renamed custom_force_<i>, and defines
// N_CUSTOM (src/sim/particles/custom.rs). force_age and force_type are the particle's age and
// type, set by integrate.frag's main before it calls acceleration.
#ifndef N_CUSTOM
#define N_CUSTOM 0
#endif
float force_age = 0.0;
int force_type = 0;
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
#ifdef EMITTER_FORCES
uniform vec3 u_type_gravity[4];
uniform vec4 u_type_damping;
#if N_ATTRACTORS > 0
uniform int u_attractor_owner[N_ATTRACTORS];
#endif
#if N_SPRINGS > 0
uniform int u_spring_owner[N_SPRINGS];
#endif
#if N_VORTICES > 0
uniform int u_vortex_owner[N_VORTICES];
#endif
// Whether a force owned by type `owner` acts on this particle.
bool acts(int owner) {
    return owner < 0 || owner == force_type;
}
#define ACTS(owner) acts(owner)
#else
#define ACTS(owner) true
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
uniform vec4 u_vortex_shape[N_VORTICES]; // latta form (0/1), constant falloff (0/1), max distance (<0: none), softening
#endif

// UberFlow eq. 1's v_ext: the wind velocity added to the velocity in a step (0 unless
// WIND_FORM 2).
vec3 wind_kick(vec3 x) {
#if defined(WIND) && WIND_FORM == 2
    return flow_sample(u_flow, u_flow_min, u_flow_max, u_flow_res, x);
#else
    return vec3(0.0);
#endif
}

// A force of `strength` towards d (r = |d|) with an attractor's falloff; shape = (constant
// falloff 0/1, max distance < 0 for none, softening).
vec3 point_force(vec3 d, float strength, vec3 shape) {
    float r = length(d);
    if (r > 0.0 && (shape.y < 0.0 || r <= shape.y)) {
        if (shape.x > 0.5) {
            return strength * (d / r);
        }
        float q = r * r + shape.z * shape.z;
        return strength * d / (q * sqrt(q));
    }
    return vec3(0.0);
}

vec3 acceleration(vec3 x, vec3 v, float inv_mass) {
    vec3 a = vec3(0.0);
    vec3 f = vec3(0.0);
#ifdef GRAVITY
    a += u_gravity;
#endif
#ifdef DAMPING
    a -= u_damping * v;
#endif
#ifdef EMITTER_FORCES
    a += u_type_gravity[force_type];
    a -= u_type_damping[force_type] * v;
#endif
#if defined(WIND) && WIND_FORM == 0
    a += u_drag * (flow_sample(u_flow, u_flow_min, u_flow_max, u_flow_res, x) - v);
#elif defined(WIND) && WIND_FORM == 1
    f += u_drag * (flow_sample(u_flow, u_flow_min, u_flow_max, u_flow_res, x) - v);
#endif
#if N_ATTRACTORS > 0
    for (int i = 0; i < N_ATTRACTORS; i++) {
        if (!ACTS(u_attractor_owner[i])) continue;
        f += point_force(u_attractor[i].xyz - x, u_attractor[i].w, u_attractor_shape[i].xyz);
    }
#endif
#if N_SPRINGS > 0
    for (int i = 0; i < N_SPRINGS; i++) {
        if (!ACTS(u_spring_owner[i])) continue;
        f -= u_spring[i].w * (x - u_spring[i].xyz);
    }
#endif
#if N_VORTICES > 0
    for (int i = 0; i < N_VORTICES; i++) {
        if (!ACTS(u_vortex_owner[i])) continue;
        vec3 rel = x - u_vortex[i].xyz;
        vec3 ax = u_vortex_axis[i];
        vec3 perp = rel - dot(rel, ax) * ax;
        vec4 vs = u_vortex_shape[i];
        if (vs.x > 0.5) {
            f += point_force(-perp, u_vortex[i].w, vs.yzw);
        } else {
            float core = max(length(perp), 0.1);
            f += u_vortex[i].w * cross(ax, perp) / (core * core);
        }
    }
#endif
#if N_CUSTOM > 0
    f += custom_force_0(x, v, force_age, force_type);
#endif
#if N_CUSTOM > 1
    f += custom_force_1(x, v, force_age, force_type);
#endif
#if N_CUSTOM > 2
    f += custom_force_2(x, v, force_age, force_type);
#endif
#if N_CUSTOM > 3
    f += custom_force_3(x, v, force_age, force_type);
#endif
    return a + f * inv_mass;
}

// The same for a particle of `type` at its type's mass (init.frag's Verlet start; with a mass
// range, u_inv_mass holds the inverse of the range's middle).
vec3 acceleration(vec3 x, vec3 v, int type) {
    force_type = type;
    return acceleration(x, v, u_inv_mass[type]);
}
