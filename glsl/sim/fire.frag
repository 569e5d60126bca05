// Fire physics pass: thesis §4.5.1, Listing 2, with the flaws the thesis names fixed.
//
// State (both read from the front, both written to the back through MRT):
//   position = (x, y, z, remaining life L_r in s)
//   velocity = (vx, vy, vz, remaining wait W in s)
// A particle is born with life L in [u_life_min, u_life_max] and wait W = u_max_age - L, so each
// particle's cycle (life, then wait) lasts u_max_age whatever L is: the emission rate stays
// N / u_max_age per second (the thesis's reason for its second counter). While alive, W holds the
// wait still to come, so the total life is L = u_max_age - W and the age can be derived.
//
// Improvements over the thesis: a fixed time step u_dt in seconds (the thesis counted frames),
// PCG random numbers per particle and step (the thesis had none), buoyancy as a real acceleration
// integrated with semi-implicit Euler (velocity first, then position: Latta eq. 3 and 8).

#include "common/rng.glsl"
#include "common/state.glsl"

uniform sampler2D u_position;
uniform sampler2D u_velocity;
uniform int u_width;
uniform float u_dt;
uniform uint u_step;
uniform uint u_seed;
// Emitter disc in the xz plane.
uniform vec3 u_emitter_center;
uniform float u_emitter_radius;
// Initial velocity: upward speed, random sideways spread, pull towards the axis.
uniform float u_speed;
uniform float u_spread;
uniform float u_converge;
// Forces: buoyancy (negative gravity, thesis §4.5.1), noise (turbulence), damping.
uniform vec3 u_buoyancy;
uniform float u_turbulence;
uniform float u_damping;
// Life cycle.
uniform float u_life_min;
uniform float u_life_max;
uniform float u_max_age;

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 v = texelFetch(u_velocity, t, 0);
    uint rng = rng_seed(particle_index(t, u_width), u_step, u_seed);

    if (p.w > 0.0) {
        // Alive: accelerate, move, age.
        vec3 a = u_buoyancy + u_turbulence * rng_signed3(rng) - u_damping * v.xyz;
        v.xyz += a * u_dt;
        p.xyz += v.xyz * u_dt;
        p.w = max(p.w - u_dt, 0.0);
    } else if (v.w > 0.0) {
        // Dead: wait out the rest of the cycle, out of view.
        v.w = max(v.w - u_dt, 0.0);
    } else {
        // Respawn on the emitter disc with a fresh random life.
        vec2 d = rng_disc(rng);
        vec3 offset = vec3(d.x, 0.0, d.y) * u_emitter_radius;
        vec2 side = rng_disc(rng) * u_spread;
        float up = u_speed * (0.75 + 0.5 * rng_uniform(rng));
        float life = mix(u_life_min, u_life_max, rng_uniform(rng));
        p = vec4(u_emitter_center + offset, life);
        v = vec4(vec3(side.x, up, side.y) - u_converge * offset, u_max_age - life);
    }
    o_position = p;
    o_velocity = v;
}
