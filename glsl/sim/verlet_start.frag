// Verlet's second-order start for a state given with explicit velocities (src/sim/particles/,
// set_state): x_prev = x - v dt + a(x, v) dt^2 / 2, so that the first step gives
// x + v dt + a dt^2 / 2, the Taylor expansion to second order. Dead texels are copied.

#include "common/precision.glsl"

uniform sampler2D u_position;
uniform sampler2D u_velocity;
uniform sampler2D u_static;
uniform float u_dt;

#include "sim/forces.glsl"

layout(location = 0) out vec4 o_previous;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec3 v = texelFetch(u_velocity, t, 0).xyz;
    vec4 st = texelFetch(u_static, t, 0);
    int type = int(st.y);
    if (!(p.w > 0.0)) {
        o_previous = p;
        return;
    }
    force_type = type;
    vec3 a = acceleration(p.xyz, v, particle_inv_mass(type, st.w));
    o_previous = fp_store(vec4(p.xyz - v * u_dt + 0.5 * a * u_dt * u_dt, p.w));
}
