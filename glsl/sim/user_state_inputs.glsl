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
