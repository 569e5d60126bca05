// A user state's pass (`[[state]]`; Latta §3.4.2: "other operations can be applied in separate
// passes, as all operations are completely independent"): one full-screen pass per state and
// step, after the integration, writing the state's back texture; every state is swapped after
// all have been drawn, so each update reads the previous step's values of every state.
// The root (src/sim/particles/user_state.rs) defines, before including this file:
//   user_init(), user_update()   the scene's `init` and `update` expressions as vec4 functions;
//   USER_SELF                    this state's previous value (a texel fetch);
//   a sampler per state, and around the user's texts alone a macro per state reading its
//   previous value by its name (undefined before this file: no name here is replaced).
// Inputs of the expressions (globals set by sim/user_state_step.glsl): x, v (after this step's
// integration), life, age, type, random, index, time (the end of the step), dt.
// Birth (sim/user_state_step.glsl, shared with the integration pass of `pass = "integrate"`):
// a texel alive now that was dead or unborn before the step, or whose life grew, or a newborn of
// the allocator. u_start = 1 gives every texel its value at birth (the start).
// Dead and unborn texels keep their value.

uniform sampler2D u_position;       // after this step's integration
uniform sampler2D u_old_position;   // before it (Verlet: the previous positions)
#ifndef VERLET
uniform sampler2D u_velocity;
#endif
uniform sampler2D u_static;
uniform int u_width;
uniform float u_dt;
uniform float u_time;
uniform int u_start;
#ifdef CHILDREN
uniform int u_child_start;
#endif

layout(location = 0) out vec4 o_state;

#include "sim/user_state_step.glsl"

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 q = texelFetch(u_old_position, t, 0);
#ifdef VERLET
    vec3 vel = (p.xyz - q.xyz) / u_dt;
#else
    vec3 vel = texelFetch(u_velocity, t, 0).xyz;
#endif
    int s = user_state_step(t, p, q, texelFetch(u_static, t, 0), vel, u_time);
    if (u_start != 0 || s == USER_INIT) {
        o_state = user_init();
    } else if (s == USER_UPDATE) {
        o_state = user_update();
    } else {
        o_state = USER_SELF;
    }
}
