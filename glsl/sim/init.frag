// The initial state, one full-screen pass per target (see sim/integrate.frag for the layout).
//   INITIAL    every particle spawned now from its emitter (type = index mod emitter count);
//              with LIFE it lives once, else it is permanent (life 1, total life 0)
//   TIMESTAMP  every particle unborn, its phase spread uniformly over its type's first cycle,
//              its life drawn once (UberFlow §4.1); with ROW_PHASES (collision scenes) the
//              phases follow the texel order instead of a random draw: texel i of N takes
//              the middle of step floor((i + 0.5) / N * S) of the S = cycle / dt steps of a
//              cycle, so one step's release is a run of consecutive texels, in one row (or two,
//              where the run crosses a row's end), and rows-only sorting can find its collisions
//              (UberFlow §5)
//              A burst (count particles at one time) takes the type's next texels in texel
//              order and stamps them all with its time. A phase at time 0 is born here.
//   ALLOCATOR  every texel dead and free; the CPU allocator emits into it
//   CHILDREN   texels from u_child_start on belong to child emitters: dead until born
// OUT_STATE writes position (and velocity), OUT_PREVIOUS the Verlet previous position
// x0 - v0 dt + a0 dt^2 / 2 (the second-order start), OUT_STATIC the static texture.

#include "common/state.glsl"
#include "common/precision.glsl"
#include "sim/spawn.glsl"

uniform int u_width;
uniform uint u_seed;
uniform int u_emitters;
uniform float u_dt;
#ifdef TIMESTAMP
uniform vec4 u_cycle;
// Bursts per type: up to four times, and the particle counts at the end of each (cumulative);
// zero counts: no burst.
uniform vec4 u_burst_time[4];
uniform vec4 u_burst_end[4];
#endif
#ifdef ROW_PHASES
uniform ivec2 u_size;
#endif
#ifdef TIMESTAMP
#include "sim/stamp_birth.glsl"
#endif

#include "sim/forces.glsl"
#ifdef CHILDREN
#include "sim/children.glsl"
#endif

layout(location = 0) out vec4 o_0;
#if defined(OUT_STATE) && !defined(VERLET)
layout(location = 1) out vec4 o_1;
#endif
#if defined(OUT_STATE) && defined(SPIN)
layout(location = 2) out vec4 o_2;   // spin: at rest, angle 0 (sim/integrate.frag)
#endif

const float INF = uintBitsToFloat(0x7f800000u);

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    uint index = particle_index(t, u_width);
    int type = int(index % uint(u_emitters));
    // Stream 0xffffffff is the initial one; generations of time stamps use 0, 1, 2, ...
    uint rng = rng_seed(index, 0xffffffffu, u_seed);
    vec4 pos = vec4(INF, INF, INF, 0.0);
    vec3 vel = vec3(0.0);
    vec4 st = vec4(0.0, float(type), 0.0, 0.0);
#if defined(INITIAL)
    pos.xyz = spawn_position(type, rng);
    vel = spawn_velocity(type, rng);
#ifdef LIFE
    st.z = spawn_life(type, rng);
    pos.w = st.z;
#else
    pos.w = 1.0;
#endif
#elif defined(TIMESTAMP)
    st.x = rng_uniform(rng) * u_cycle[type];
#ifdef ROW_PHASES
    float steps = max(1.0, floor(u_cycle[type] / u_dt + 0.5));
    float f = (float(index) + 0.5) / (float(u_size.x) * float(u_size.y));
    st.x = (floor(f * steps) + 0.5) * u_dt;
#endif
    // Bursts: the type's first particles (in texel order) share the bursts' time stamps, in
    // the order of the bursts.
    float rank = float(index / uint(u_emitters));
    vec4 ends = u_burst_end[type];
    if (rank < ends.w) {
        int b = rank < ends.x ? 0 : (rank < ends.y ? 1 : (rank < ends.z ? 2 : 3));
        st.x = u_burst_time[type][b];
    }
    st.z = spawn_life(type, rng);
    pos.w = -1.0;
    if (st.x <= 0.0) {
        // A cycle that begins at time 0 begins before the first step, which births the phases
        // in (start, end] of its interval: it is born here, as the step that begins a cycle
        // would (sim/stamp_birth.glsl, the stream of generation 0), at age 0.
        uint born = rng_seed(index, 0u, u_seed);
        stamp_birth(type, index, st.x, born, pos.xyz, vel);
        pos.w = st.z;
    }
#endif
    st.w = rng_uniform(rng);
#ifdef CHILDREN
    // A child texel (sim/children.glsl) starts dead, with its type and a life drawn once, as
    // time stamps' are; past the last range a texel stays dead.
    if (int(index) >= u_child_start) {
        int parent, slot;
        int c = child_of(int(index), parent, slot);
        int kind = c < 0 ? 0 : int(u_child_more[c].z);
        pos = vec4(INF, INF, INF, 0.0);
        vel = vec3(0.0);
        st = vec4(0.0, float(kind), c < 0 ? 0.0 : spawn_life(kind, rng), rng_uniform(rng));
    }
#endif

#if defined(OUT_STATIC)
    o_0 = st;
#elif defined(OUT_PREVIOUS)
    if (pos.w > 0.0) {
        vec3 a = acceleration(pos.xyz, vel, type);
        o_0 = fp_store(vec4(pos.xyz - vel * u_dt + 0.5 * a * u_dt * u_dt, pos.w));
    } else {
        o_0 = pos;
    }
#else
    o_0 = fp_store(pos);
#ifndef VERLET
    o_1 = fp_store(vec4(vel, 0.0));
#endif
#ifdef SPIN
    o_2 = vec4(0.0);
#endif
#endif
}
