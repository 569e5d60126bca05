// The particle step (Latta §3.4.2-3.4.3, UberFlow §4.2): one full-screen pass per time step.
// State, particle i in texel (i mod width, i div width):
//   position (RGBA32F) = (x, y, z, remaining life in s); w <= 0: dead or not yet born, xyz = +inf
//   velocity (RGBA32F or RGBA16F) = (vx, vy, vz, 0)        — not with VERLET
//   previous position (VERLET only; three position textures in a ring)
//   static  (RGBA32F, written at birth only) = (birth time or phase, type, total life, random)
// Integrators (fixed dt):
//   EULER     Latta eq. 3 and 8: v' = v + a dt, x' = x + v' dt (velocity first)
//   UBERFLOW  UberFlow eq. 1-2: v' = v + a dt, x' = x + (v + v') dt / 2
//   VERLET    Latta eq. 9: x' = 2x - x_prev + a dt^2, velocity implied: (x - x_prev) / dt
//   HEUN, RK4, LEAPFROG  the thesis's other schemes (§2.1): Heun's predictor-corrector, the
//             classical fourth-order Runge-Kutta, leapfrog kick-drift-kick (sim/stages.glsl)
// With the wind in UberFlow's form (eq. 1) the velocity also gains v_ext = w(x) in each step
// (wind_kick; Verlet: x' gains w(x) dt).
// Explicit integrators write position and velocity through MRT; Verlet writes positions only.
// Without MRT (`passes = "separate"`, Latta §3.1) the pass is drawn twice: OUT_VELOCITY writes
// the velocity alone, then OUT_POSITION the position alone; with POSITION_FROM_VELOCITY (Euler
// and UberFlow without colliders, fp32 writes) the position pass reads the velocity the first
// pass wrote, as Latta's does, else it recomputes the step: either way the bits are the MRT's.
// Life: LIFE counts the remaining life down and moves the dead to infinity (Latta §3.4.1; the CPU
// frees the index on its own clock). TIMESTAMP is UberFlow's emission (§4.1, §4.7): the static
// texture holds each particle's phase; before it the particle is unborn and out of view; at the
// start of every cycle it respawns from its emitter, and it is dead for the rest of the cycle
// after its life. Without either the particles are permanent and no life code is compiled.
// SPIN (UberFlow §4.5, spinning spheres): a third target, spin (RGBA32F) = (ω, angle about z);
// no torque acts between contacts, so ω changes only by the colliders' friction
// (collide/spin.glsl) and the angle advances by ω_z dt; births and deaths start from rest.
// USER_STATE_OUTPUTS (`[[state]]` with pass = "integrate"): the states' updates as further
// targets after these, evaluated in write_state (the root: src/sim/particles/user_state_mrt.rs).
// CHILDREN (the thesis §2, emitters that emit): texels from u_child_start on belong to child
// emitters; a dead one is born here from its parent texel's state (sim/child_birth.glsl), a live
// one counts its life down as LIFE does; velocity.w keeps its count of dropped births.

#include "common/state.glsl"
#include "common/precision.glsl"
#include "sim/spawn.glsl"

uniform sampler2D u_position;
uniform sampler2D u_static;
#ifdef VERLET
uniform sampler2D u_previous;
#else
uniform sampler2D u_velocity;
#endif
uniform int u_width;
uniform float u_dt;
uniform float u_time;   // simulation time at the start of this step
uniform uint u_seed;
#ifdef TIMESTAMP
uniform vec4 u_cycle;   // cycle length per type
#endif
#if defined(TIMESTAMP) || defined(CHILDREN)
uniform float u_time_next;  // the simulation time at the end of this step (the next u_time)
#endif
#if defined(TIMESTAMP) && defined(VERLET)
uniform float u_time_prev;  // the last step's u_time, bit for bit (-dt before the first step)
#endif

vec3 advance(vec3 x, vec3 v, vec3 vb) {
#if defined(UBERFLOW) || defined(MULTISTAGE)
    return x + 0.5 * (v + vb) * u_dt;
#else
    return x + vb * u_dt;
#endif
}

#ifdef TIMESTAMP
// A time stamp's step (UberFlow §4.1) on one clock: the cycle number at the start of the step
// (u_time) and at its end (u_time_next, the next step's u_time bit for bit), so the end of a
// step is the start of the next and every cycle begins in exactly one step. A test of the age
// at the end against dt (age < dt) does not tile: u_time + dt differs from the next u_time by
// rounding, and a phase on a step boundary was born in two consecutive steps, or in none.
struct Stamp {
    float age;          // the age in the cycle at the end of the step
    float start_age;    // the age in the cycle at the start of the step
    float generation;   // the cycle's number at the end of the step; < 0: not born yet
    bool begins;        // a cycle begins in this step: the particle is born (again)
};

Stamp timestamp_step(vec4 st, int type) {
    float cycle = u_cycle[type];
    float rel0 = u_time - st.x;
    float rel1 = u_time_next - st.x;
    float g0 = floor(rel0 / cycle);
    float g1 = floor(rel1 / cycle);
    return Stamp(rel1 - g1 * cycle, rel0 - g0 * cycle, g1, rel1 >= 0.0 && g1 > g0);
}
#include "sim/stamp_birth.glsl"
#endif
#ifdef CHILDREN
#include "sim/children.glsl"
#include "sim/child_birth.glsl"
#endif

#include "sim/forces.glsl"
#ifdef MULTISTAGE
#include "sim/stages.glsl"
#endif
#ifdef SPIN
#include "collide/spin.glsl"
uniform sampler2D u_spin;
vec4 spin = vec4(0.0);
#endif
#if HAS_COLLIDERS
#include "sim/colliders.glsl"
#endif

#if defined(OUT_VELOCITY)
layout(location = 0) out vec4 o_velocity;
#elif defined(OUT_POSITION) || defined(VERLET)
layout(location = 0) out vec4 o_position;
#else
layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;
#ifdef SPIN
layout(location = 2) out vec4 o_spin;
#endif
#endif
#ifdef POSITION_FROM_VELOCITY
uniform sampler2D u_new_velocity;
#endif

const float INF = uintBitsToFloat(0x7f800000u);

// velocity.w: 0, or a child texel's count of dropped births (sim/child_birth.glsl), or 1 on
// another texel whose path in this step still entered a collider after the colliders' bound on
// bounces (sim/colliders.glsl, MAX_BOUNCES; counted by src/sim/particles/bounces.rs).
float state_w = 0.0;

#ifdef USER_STATE_OUTPUTS
// `[[state]]` with pass = "integrate" (src/sim/particles/user_state_mrt.rs): the states'
// updates, further render targets of this pass, from the position and velocity it stores.
void user_states_write(vec4 position, vec3 velocity);
#endif

void write_state(vec3 x, float life, vec3 v) {
#ifndef OUT_VELOCITY
    o_position = fp_store(vec4(x, life));
#endif
#if !defined(VERLET) && !defined(OUT_POSITION)
    o_velocity = fp_store(vec4(v, state_w));
#endif
#ifdef SPIN
    o_spin = spin;
#endif
#ifdef USER_STATE_OUTPUTS
    user_states_write(fp_store(vec4(x, life)), fp_store(vec4(v, state_w)).xyz);
#endif
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    uint index = particle_index(t, u_width);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 st = texelFetch(u_static, t, 0);
    int type = int(st.y);
    float im = particle_inv_mass(type, st.w);
    force_type = type;
    force_age = u_time - st.x;  // birth time (allocator) or 0 (initial emitters)
    vec3 x = p.xyz;
#ifdef VERLET
    vec3 xp = texelFetch(u_previous, t, 0).xyz;
    vec3 v = (x - xp) / u_dt;
#else
    vec3 v = texelFetch(u_velocity, t, 0).xyz;
#endif
    float life = p.w;

#ifdef CHILDREN
    if (int(index) >= u_child_start) {
        // A child texel: born from its parent in this step, or living out its own life.
        ChildStep c = child_step(int(index), p, texelFetch(u_velocity, t, 0));
        state_w = c.drops;
        if (c.born) {
            write_state(c.x, st.z, c.v);
            return;
        }
        life = p.w - u_dt;
        if (!(p.w > 0.0) || life <= 0.0) {
            write_state(vec3(INF), 0.0, vec3(0.0));
            return;
        }
        force_age = st.z - p.w;
    } else {
#endif
#if defined(TIMESTAMP)
    Stamp stamp = timestamp_step(st, type);
    if (stamp.generation < 0.0) {
        write_state(vec3(INF), -1.0, vec3(0.0));  // not born yet: out of view
        return;
    }
    float generation = stamp.generation;
    // Born within this step: its age at the end is below dt (rounding may leave it a hair
    // outside [0, dt)).
    float age = stamp.begins ? clamp(stamp.age, 0.0, u_dt) : stamp.age;
    if (age >= st.z) {
        write_state(vec3(INF), 0.0, vec3(0.0));   // dead until its next cycle begins
        return;
    }
    uint rng = rng_seed(index, uint(generation), u_seed);
    if (stamp.begins) {
        vec3 x0, v0;
        stamp_birth(type, index, st.x, rng, x0, v0);
        write_state(x0, st.z - age, v0);          // born during this step
        return;
    }
    life = st.z - age;
    force_age = age;
#ifdef VERLET
    // Born in the previous step: a cycle began between its start and this step's, on the
    // clock of timestamp_step (a test of the end age against 2 dt made the start twice, or
    // not at all, for a phase on a step boundary).
    float cycle = u_cycle[type];
    float rel0 = u_time - st.x;
    if (rel0 >= 0.0 && floor(rel0 / cycle) > floor((u_time_prev - st.x) / cycle)) {
        // x_prev belongs to the last life. Second-order start:
        // x_prev = x0 - v0 dt + a0 dt^2 / 2, which makes this step x0 + v0 dt + a0 dt^2 / 2.
        spawn_position(type, rng);
        v = spawn_velocity(type, rng);
        xp = x - v * u_dt + 0.5 * acceleration(x, v, im) * u_dt * u_dt;
    }
#endif
#elif defined(LIFE)
    if (!(p.w > 0.0)) {
        write_state(vec3(INF), p.w, vec3(0.0));
        return;
    }
    life = p.w - u_dt;
    if (life <= 0.0) {
        write_state(vec3(INF), 0.0, vec3(0.0));   // death by age: moved to infinity
        return;
    }
#endif
#ifdef CHILDREN
    }
#endif

#ifdef SPIN
    spin = texelFetch(u_spin, t, 0);
    spin_w = spin.xyz;
#endif
#ifdef POSITION_FROM_VELOCITY
    // Latta's position pass: the new velocity is the one the velocity pass just wrote.
    vec3 vn = texelFetch(u_new_velocity, t, 0).xyz;
    write_state(advance(x, v, vn), life, vn);
    return;
#endif
#ifdef VERLET
    vec3 a = acceleration(x, v, im);
    vec3 xn = 2.0 * x - xp + a * (u_dt * u_dt) + wind_kick(x) * u_dt;
#if HAS_COLLIDERS
    collide(x, xn);
    vec3 vn = (xn - x) / u_dt;
    keep_outside(xn, vn);
#endif
    write_state(xn, life, vec3(0.0));
#else
#ifdef MULTISTAGE
    vec3 xb, vb;
    stages(x, v + wind_kick(x), im, force_age, xb, vb);
#else
    vec3 a = acceleration(x, v, im);
    vec3 vb = v + wind_kick(x) + a * u_dt;
    vec3 xb = advance(x, v, vb);
#endif
#if HAS_COLLIDERS
    collide(x, v, vb, xb);
    keep_outside(xb, vb);
#ifdef CHILDREN
    if (bounces_truncated && int(index) < u_child_start) state_w = 1.0;
#else
    if (bounces_truncated) state_w = 1.0;
#endif
#endif
#ifdef SPIN
    // The angle kept in (-pi, pi], so that its float spacing stays fine however long it turns.
    spin = vec4(spin_w, mod(spin.w + spin_w.z * u_dt + 3.14159265, 6.28318531) - 3.14159265);
#endif
    write_state(xb, life, vb);
#endif
}
