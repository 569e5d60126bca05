// The fluid's initial state (src/sim/fluid/mod.rs): texel i is particle rank i / E of type
// i mod E (E initial box emitters, as sim/init.frag assigns types), placed on the cubic lattice
// of spacing dx that fills its emitter's box: n = floor(size / dx) points per axis, point
// (ix, iy, iz) at min + (i + 1/2) dx, x fastest, then z, then y, so that a partial fill is a
// lower, level layer. Ranks past n.x n.y n.z stay dead (at +inf, life 0). Velocity: the
// emitter's direction times its lowest speed, the same for all. Life 1: permanent.
// With fluid.initial = "hydrostatic" (u_compress > 0) the layers close up with depth so that the
// density sum gives each layer Tait's pressure of the weight above it: the column starts at rest
// in equilibrium instead of falling until its own compression holds it up.

#include "common/state.glsl"
#include "common/precision.glsl"

uniform int u_width;
uniform int u_emitters;
uniform vec4 u_lattice_min[4];   // box corner, spacing
uniform ivec4 u_lattice_n[4];    // points per axis; w: the layers its particles fill
uniform vec4 u_lattice_v[4];     // start velocity

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_velocity;

uniform float u_compress;         // fluid.initial = "hydrostatic": rho0 |g| / B, else 0
uniform float u_gamma;            // Tait's exponent

const float INF = uintBitsToFloat(0x7f800000u);

// 1 - rho0 / rho at a depth of fluid s (m of the uncompressed lattice) under Tait's equation:
// the weight above is rho0 |g| s per unit area whatever the compression, so
// rho / rho0 = (1 + rho0 |g| s / B)^(1 / gamma).
float squeeze(float s) {
    return 1.0 - pow(1.0 + u_compress * s, -1.0 / u_gamma);
}

// Height above the box's floor of a layer whose centre has `below` layers of spacing dx under
// it in a column of `layers`: the integral of rho0 / rho over the fluid below it, by
// Simpson's rule (the squeeze is nearly linear in depth).
float hydrostatic_height(float below, float layers, float dx) {
    float s0 = layers * dx;
    float s1 = (layers - below) * dx;
    float sm = 0.5 * (s0 + s1);
    return below * dx * (1.0 - (squeeze(s0) + 4.0 * squeeze(sm) + squeeze(s1)) / 6.0);
}

void main() {
    int index = int(particle_index(ivec2(gl_FragCoord.xy), u_width));
    int type = index % u_emitters;
    int rank = index / u_emitters;
    ivec3 n = u_lattice_n[type].xyz;
    vec4 lo = u_lattice_min[type];
    if (rank < n.x * n.y * n.z) {
        ivec3 c = ivec3(rank % n.x, rank / (n.x * n.z), (rank / n.x) % n.z);
        vec3 x = lo.xyz + (vec3(c) + 0.5) * lo.w;
        // The column is as high as the layers filled (a partial fill: fewer than n.y).
        float layers = float(u_lattice_n[type].w);
        if (u_compress > 0.0) x.y = lo.y + hydrostatic_height(float(c.y) + 0.5, layers, lo.w);
        o_position = fp_store(vec4(x, 1.0));
        o_velocity = fp_store(vec4(u_lattice_v[type].xyz, 0.0));
    } else {
        o_position = vec4(INF, INF, INF, 0.0);
        o_velocity = vec4(0.0);
    }
}
