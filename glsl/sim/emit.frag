// Writes a new particle's initial data (see emit.vert). OUT_STATE: position and velocity (MRT;
// position only with VERLET); OUT_PREVIOUS: the Verlet previous position for a second-order
// start; OUT_STATIC: the static texture.

#include "common/precision.glsl"

uniform float u_dt;

#include "sim/forces.glsl"

flat in vec4 v_position;
flat in vec4 v_velocity;
flat in vec4 v_static;

layout(location = 0) out vec4 o_0;
#if defined(OUT_STATE) && !defined(VERLET)
layout(location = 1) out vec4 o_1;
#endif
#if defined(OUT_STATE) && defined(SPIN)
layout(location = 2) out vec4 o_2;   // spin: at rest, angle 0 (sim/integrate.frag)
#endif

void main() {
#if defined(OUT_STATIC)
    o_0 = v_static;
#elif defined(OUT_PREVIOUS)
    vec3 x = v_position.xyz;
    vec3 v = v_velocity.xyz;
    force_type = int(v_static.y);
    vec3 a = acceleration(x, v, particle_inv_mass(force_type, v_static.w));
    o_0 = fp_store(vec4(x - v * u_dt + 0.5 * a * u_dt * u_dt, v_position.w));
#else
    o_0 = fp_store(v_position);
#ifndef VERLET
    o_1 = fp_store(v_velocity);
#endif
#ifdef SPIN
    o_2 = vec4(0.0);
#endif
#endif
}
