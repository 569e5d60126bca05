// Initial fire state (thesis §4.1: the thesis filled it on the CPU; here a pass draws it).
// Every particle starts dead, waiting a uniformly random part of the maximum age, so births are
// spread evenly over the first cycle instead of one generation being born and dying at once.
//   position = (0, 0, 0, life = 0)      velocity = (0, 0, 0, wait in [0, u_max_age))

#include "common/rng.glsl"
#include "common/state.glsl"

uniform uint u_seed;
uniform int u_width;
uniform float u_max_age;

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    // Step 0xffffffff never occurs in the simulation, so this stream is distinct from all steps.
    uint rng = rng_seed(particle_index(t, u_width), 0xffffffffu, u_seed);
    o_position = vec4(0.0);
    o_velocity = vec4(0.0, 0.0, 0.0, u_max_age * rng_uniform(rng));
}
