// What the expressions of a user state (`[[state]]`) read besides the states themselves, set by
// sim/user_state.frag before it calls them: position and velocity after this step's
// integration, remaining life, age in seconds, type, the particle's random number in [0, 1),
// its index, the time at the end of the step and the step.
#include "common/state.glsl"

vec3 x;
vec3 v;
float life;
float age;
int type;
float random;
int index;
float time;
float dt;

// The age of the particle of position texel p and static texel st at time t, in seconds.
float user_age(vec4 p, vec4 st, float t) {
#if defined(LIFE) || defined(TIMESTAMP) || defined(CHILDREN)
    return st.z - p.w;
#else
    return t - st.x;
#endif
}
