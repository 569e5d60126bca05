// The stateless particle system (Latta §2.1: "a closed form function which is defined by a set of
// start values and the current time"; thesis §2.2.5, "zustandslos"): every step computes each
// particle's position and velocity from its start values and its age alone, never from the last
// step's state. Defined for the motions with a closed form: gravity, linear damping and a
// constant wind through drag (a wind field without turbulence, drag or latta form), that is
//   a = A - lambda v,  A = g + k w,  lambda = c + k  (latta form: k / m in both)
// with the solution, tau the time since the start values,
//   v(tau) = v0 e^(-lambda tau) + A e1,  x(tau) = x0 + v0 e1 + A e2,
//   e1 = (1 - e^(-lambda tau)) / lambda,  e2 = (tau - e1) / lambda
// (series in lambda tau where it is small, so that lambda = 0 gives x0 + v0 tau + A tau^2 / 2).
// Start values: INITIAL scenes read them from the start textures drawn once at reset (bound as
// u_position, u_velocity); TIMESTAMP scenes draw them from the emitter with the same random
// stream as sim/integrate.frag's respawn, at the particle's age in its cycle.

#include "common/state.glsl"
#include "common/precision.glsl"
#include "sim/spawn.glsl"

uniform sampler2D u_position;   // start positions (xyz, life at the start)
uniform sampler2D u_velocity;   // start velocities
uniform sampler2D u_static;
uniform int u_width;
uniform float u_dt;
uniform float u_time;           // simulation time at the start of this step
uniform uint u_seed;
#ifdef TIMESTAMP
uniform vec4 u_cycle;
uniform float u_time_next;      // the next step's u_time, bit for bit (as sim/integrate.frag)
#endif
uniform vec4 u_inv_mass;
#ifdef MASS_RANGE
uniform vec4 u_mass_lo;
uniform vec4 u_mass_hi;
#endif
uniform vec3 u_closed_accel;    // g + k w (drag form) or g (latta form)
uniform vec3 u_closed_wind;     // 0 (drag form) or k w, to be divided by the mass (latta form)
uniform vec2 u_closed_rate;     // c + k (drag form) or c, and 0 or k (latta form, / mass)

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

const float INF = uintBitsToFloat(0x7f800000u);

float inv_mass_of(int type, float r) {
#ifdef MASS_RANGE
    return 1.0 / mix(u_mass_lo[type], u_mass_hi[type], fract(4096.0 * r));
#else
    return u_inv_mass[type];
#endif
}

void closed_form(vec3 x0, vec3 v0, float tau, float im, out vec3 x, out vec3 v) {
    vec3 A = u_closed_accel + u_closed_wind * im;
    float lambda = u_closed_rate.x + u_closed_rate.y * im;
    float z = lambda * tau;
    float e1, e2, decay;
    if (abs(z) < 0.1) {
        // Taylor series to z^5 (remainder below 3e-10): the closed form's differences would
        // cancel to a few significant digits here.
        e1 = tau * (1.0 - z * (1.0 / 2.0 - z * (1.0 / 6.0 - z * (1.0 / 24.0
                  - z * (1.0 / 120.0 - z / 720.0)))));
        e2 = tau * tau * (1.0 / 2.0 - z * (1.0 / 6.0 - z * (1.0 / 24.0 - z * (1.0 / 120.0
                  - z * (1.0 / 720.0 - z / 5040.0)))));
        decay = 1.0 - lambda * e1;
    } else {
        decay = exp(-z);
        e1 = (1.0 - decay) / lambda;
        e2 = (tau - e1) / lambda;
    }
    v = v0 * decay + A * e1;
    x = x0 + v0 * e1 + A * e2;
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    uint index = particle_index(t, u_width);
    vec4 st = texelFetch(u_static, t, 0);
    int type = int(st.y);
    float im = inv_mass_of(type, st.w);
    float now = u_time + u_dt;
    vec3 x, v;
#if defined(TIMESTAMP)
    // The age at the end of the step on the clock the stateful pass uses (timestamp_step), so
    // that both give a particle the same life cycle.
    float rel = u_time_next - st.x;
    if (rel < 0.0) {
        o_position = vec4(INF, INF, INF, -1.0);
        o_velocity = vec4(0.0);
        return;
    }
    float cycle = u_cycle[type];
    float generation = floor(rel / cycle);
    float age = rel - generation * cycle;
    if (age >= st.z) {
        o_position = vec4(INF, INF, INF, 0.0);
        o_velocity = vec4(0.0);
        return;
    }
    uint rng = rng_seed(index, uint(generation), u_seed);
    vec3 x0 = spawn_position(type, rng);
    vec3 v0 = spawn_velocity(type, rng);
    closed_form(x0, v0, age, im, x, v);
    o_position = fp_store(vec4(x, st.z - age));
#else
    vec4 p0 = texelFetch(u_position, t, 0);
    vec3 v0 = texelFetch(u_velocity, t, 0).xyz;
    float life = p0.w;
#ifdef LIFE
    if (!(p0.w > 0.0)) {
        o_position = vec4(INF, INF, INF, p0.w);
        o_velocity = vec4(0.0);
        return;
    }
    life = p0.w - now;
    if (life <= 0.0) {
        o_position = vec4(INF, INF, INF, 0.0);
        o_velocity = vec4(0.0);
        return;
    }
#endif
    closed_form(p0.xyz, v0, now, im, x, v);
    o_position = fp_store(vec4(x, life));
#endif
    o_velocity = fp_store(vec4(v, 0.0));
}
