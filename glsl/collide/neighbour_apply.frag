// Neighbour forces, second pass: each particle's summed neighbour force (collide/neighbour_force
// .frag) added to its velocity, v' = v + F / m dt, in the cell-sorted layout the state is now
// kept in. Positions are copied: they move with the new velocity in the next step's
// integration, as in NVIDIA's `particles` sample, whose collide kernel writes velocities only.
// Together with the integration pass this is one symplectic Euler step whose force includes the
// neighbours' at the positions integration produced.

#include "common/state.glsl"
#include "common/precision.glsl"

uniform sampler2D u_position;   // the cell-sorted layout
uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform sampler2D u_force;      // (summed force, contacts)
uniform float u_dt;

#include "common/mass.glsl"

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 v = texelFetch(u_velocity, t, 0);
    if (p.w > 0.0) {
        vec4 st = texelFetch(u_static, t, 0);
        vec3 f = texelFetch(u_force, t, 0).xyz;
        v.xyz += f * (particle_inv_mass(int(st.y), st.w) * u_dt);
    }
    o_position = fp_store(p);
    o_velocity = fp_store(v);
}
