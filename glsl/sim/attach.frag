// The long-range attachments' pass (Kim, Chentanez and Müller-Fischer 2012): a free particle may
// be no farther from a pin than its rest distance to it (along a flat sheet or a straight strand
// the rest distance is the geodesic one, so an unstretched cloth or strand always meets it).
// Where it is farther, it goes back onto that sphere around the pin, one pin after the other.
// The bound is one-sided: it never pulls a particle towards a pin, so folds and slack stay. It
// stops the stretch that relaxation spreads too slowly along a hanging sheet.
//   CLOTH  every pinned texel, listed in u_pins (rest positions, u_pin_count of them)
//   HAIR   the strand's root, texel (0, y) of its row
// Then the colliders' projection. src/sim/reference/constraints.rs is the CPU twin.

#include "common/state.glsl"
#include "common/precision.glsl"

#include "sim/constraint.glsl"

uniform sampler2D u_pins;       // cloth: pinned texels' rest positions, k at (k % width, k / width)
uniform int u_pin_count;

layout(location = 0) out vec4 o_position;

// x pulled back within the rest distance of r to the pin at rest position rp.
vec3 attach(vec3 x, vec3 r, vec3 rp) {
    float reach = length(r - rp);
    vec3 pin = rp + u_pin_offset;
    vec3 d = x - pin;
    float len = length(d);
    return len > reach ? pin + (reach / len) * d : x;
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 p = texelFetch(u_position, t, 0);
    vec4 r = texelFetch(u_rest, t, 0);
    if (r.w > 0.5) {
        o_position = fp_store(vec4(r.xyz + u_pin_offset, p.w));
        return;
    }
    vec3 x = p.xyz;
#ifdef HAIR
    x = attach(x, r.xyz, texelFetch(u_rest, ivec2(0, t.y), 0).xyz);
#else
    for (int k = 0; k < u_pin_count; k++) {
        x = attach(x, r.xyz, texelFetch(u_pins, ivec2(k % u_size.x, k / u_size.x), 0).xyz);
    }
#endif
    o_position = fp_store(vec4(outside(x), p.w));
}
