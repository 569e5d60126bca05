// What every relaxation pass shares (sim/constrain.frag, sim/constrain_set.frag,
// sim/attach.frag): the uniforms, the correction of one distance constraint and the colliders'
// projection that ends each pass. src/sim/reference/constraints.rs is the CPU twin.

uniform sampler2D u_position;   // positions after the Verlet step or the last pass
uniform sampler2D u_rest;       // rest position, pinned (1) or free (0)
uniform ivec2 u_size;
uniform float u_stiffness;
uniform vec3 u_pin_offset;
uniform float u_dt;

#if HAS_COLLIDERS
#include "sim/colliders.glsl"
#endif

// The move of a particle at x (rest position r) that closes its share of the constraint to the
// particle at xq (rest position and pin flag rq): the gap (L - rest) along the edge, half of it
// (the neighbour moves the other half in its own texel), all of it against a pinned neighbour.
vec3 edge_correction(vec3 x, vec3 r, vec3 xq, vec4 rq) {
    float rest = length(rq.xyz - r);
    vec3 d = xq - x;
    float len = length(d);
    float share = rq.w > 0.5 ? 1.0 : 0.5;
    return len > 0.0 ? (share * (len - rest) / len) * d : vec3(0.0);
}

// A correction can push a particle into a collider: put it back on the surface.
vec3 outside(vec3 x) {
#if HAS_COLLIDERS
    vec3 v = vec3(0.0);
    keep_outside(x, v);
#endif
    return x;
}
