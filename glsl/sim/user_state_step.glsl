// One texel of a user state's step (`[[state]]`): the expressions' inputs set, and what the
// state takes: its value at birth, its update, or (dead or unborn) its previous value. Shared by
// the state's own pass (sim/user_state.frag) and the integration pass that evaluates the update
// itself (`pass = "integrate"`, src/sim/particles/user_state_mrt.rs), so both read the same
// inputs: p the position texel after this step's integration, q before it, st the static
// texel, vel the velocity after it, now the time at the end of the step.
// Birth: a texel alive now that was dead or unborn before the step, or whose life grew (a time
// stamp's respawn), or (ALLOCATOR, parent texels) whose life before the integration was its
// whole life: the allocator draws a newborn into the state before the integration
// (src/sim/particles/births.rs).
// The includer declares u_width, u_dt and, with CHILDREN, u_child_start.
#include "sim/user_state_inputs.glsl"

const int USER_KEEP = 0;
const int USER_INIT = 1;
const int USER_UPDATE = 2;

int user_state_step(ivec2 t, vec4 p, vec4 q, vec4 st, vec3 vel, float now) {
    index = int(particle_index(t, u_width));
    x = p.xyz;
    life = p.w;
    type = int(st.y);
    random = st.w;
    time = now;
    dt = u_dt;
    age = user_age(p, st, now);
    v = vel;
    bool alive = particle_live(p);
    bool born = alive && (!(q.w > 0.0) || p.w > q.w);
#ifdef ALLOCATOR
    bool parent = true;
#ifdef CHILDREN
    parent = index < u_child_start;
#endif
    born = born || (alive && parent && q.w == st.z);
#endif
    return born ? USER_INIT : (alive ? USER_UPDATE : USER_KEEP);
}
