// The fluid's initial state (src/sim/fluid/mod.rs): texel i is particle rank i / E of type
// i mod E (E initial box emitters, as sim/init.frag assigns types), placed on the cubic lattice
// of spacing dx that fills its emitter's box: n = floor(size / dx) points per axis, point
// (ix, iy, iz) at min + (i + 1/2) dx, x fastest, then z, then y, so that a partial fill is a
// lower, level layer. Ranks past n.x n.y n.z stay dead (at +inf, life 0). Velocity: the
// emitter's direction times its lowest speed, the same for all. Life 1: permanent.

#include "common/state.glsl"
#include "common/precision.glsl"

uniform int u_width;
uniform int u_emitters;
uniform vec4 u_lattice_min[4];   // box corner, spacing
uniform ivec4 u_lattice_n[4];    // points per axis
uniform vec4 u_lattice_v[4];     // start velocity

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

const float INF = uintBitsToFloat(0x7f800000u);

void main() {
    int index = int(particle_index(ivec2(gl_FragCoord.xy), u_width));
    int type = index % u_emitters;
    int rank = index / u_emitters;
    ivec3 n = u_lattice_n[type].xyz;
    vec4 lo = u_lattice_min[type];
    if (rank < n.x * n.y * n.z) {
        ivec3 c = ivec3(rank % n.x, rank / (n.x * n.z), (rank / n.x) % n.z);
        o_position = fp_store(vec4(lo.xyz + (vec3(c) + 0.5) * lo.w, 1.0));
        o_velocity = fp_store(vec4(u_lattice_v[type].xyz, 0.0));
    } else {
        o_position = vec4(INF, INF, INF, 0.0);
        o_velocity = vec4(0.0);
    }
}
