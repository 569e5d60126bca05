// Initial data of a new particle drawn from its emitter (Latta §3.4.1: point, box, sphere, disc;
// velocity in a cone). Used where the GPU spawns: the initial fill and UberFlow's time-stamp
// emission. Allocator emitters draw the same distributions on the CPU (src/sim/emit.rs is the
// twin, with the same random stream layout).
//
// Emitter k (= particle type k) is described by five vec4 uniforms:
//   u_em_center[k] = (centre, shape: 0 point, 1 box, 2 sphere, 3 disc)
//   u_em_size[k]   = (box size, radius)
//   u_em_normal[k] = (disc normal, unit length; cone half-angle in radians)
//   u_em_dir[k]    = (velocity direction, unit length; unused)
//   u_em_range[k]  = (speed min, speed max, life min, life max)

#include "common/rng.glsl"

uniform vec4 u_em_center[4];
uniform vec4 u_em_size[4];
uniform vec4 u_em_normal[4];
uniform vec4 u_em_dir[4];
uniform vec4 u_em_range[4];

const float SPAWN_TAU = 6.28318530718;

// Two unit vectors perpendicular to unit n and to each other.
void spawn_basis(vec3 n, out vec3 t, out vec3 b) {
    vec3 a = abs(n.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    t = normalize(cross(n, a));
    b = cross(n, t);
}

vec3 spawn_position(int k, inout uint rng) {
    vec4 c = u_em_center[k];
    int shape = int(c.w);
    if (shape == 1) {
        vec3 u = vec3(rng_uniform(rng), rng_uniform(rng), rng_uniform(rng));
        return c.xyz + (u - 0.5) * u_em_size[k].xyz;
    }
    if (shape == 2) {
        // Uniform in the ball: direction uniform on the sphere, radius from the cube root.
        float z = 2.0 * rng_uniform(rng) - 1.0;
        float phi = SPAWN_TAU * rng_uniform(rng);
        float r = u_em_size[k].w * pow(rng_uniform(rng), 1.0 / 3.0);
        float s = sqrt(max(0.0, 1.0 - z * z));
        return c.xyz + r * vec3(s * cos(phi), s * sin(phi), z);
    }
    if (shape == 3) {
        vec3 t, b;
        spawn_basis(u_em_normal[k].xyz, t, b);
        float r = u_em_size[k].w * sqrt(rng_uniform(rng));
        float phi = SPAWN_TAU * rng_uniform(rng);
        return c.xyz + r * (cos(phi) * t + sin(phi) * b);
    }
    return c.xyz;
}

// Direction uniform on the spherical cap of half-angle u_em_normal[k].w around u_em_dir[k],
// speed uniform in [min, max].
vec3 spawn_velocity(int k, inout uint rng) {
    vec3 d = u_em_dir[k].xyz;
    float cos_cone = cos(u_em_normal[k].w);
    float z = mix(cos_cone, 1.0, rng_uniform(rng));
    float phi = SPAWN_TAU * rng_uniform(rng);
    float s = sqrt(max(0.0, 1.0 - z * z));
    vec3 t, b;
    spawn_basis(d, t, b);
    vec3 dir = z * d + s * (cos(phi) * t + sin(phi) * b);
    vec4 range = u_em_range[k];
    return mix(range.x, range.y, rng_uniform(rng)) * dir;
}

float spawn_life(int k, inout uint rng) {
    vec4 range = u_em_range[k];
    return mix(range.z, range.w, rng_uniform(rng));
}
