// UberFlow's bitonic sort, GP/FP variant (§4.3.3 "Row-Wise Bitonic Sort"): the geometry carries
// the sign of the offset and the comparison per vertex; the fragment program reconstructs ±1
// from the interpolated attributes, fetches two entries and compares once.
// MIRROR: the reversing first pass of a merge stage; the partner's texel coordinates are
// interpolated across the quad instead of an offset.

#include "common/compare.glsl"
#include "common/precision.glsl"

uniform sampler2D u_keys;
uniform ivec2 u_offset;

in vec4 v_attr;
layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec2 own = texelFetch(u_keys, t, 0).xy;
#ifdef MIRROR
    ivec2 p = ivec2(floor(v_attr.zw));
#else
    int sign = v_attr.x < 0.0 ? -1 : 1;
    ivec2 p = t + sign * u_offset;
#endif
    vec2 other = texelFetch(u_keys, p, 0).xy;
    o_entry = fp_store(vec4(compare_exchange(own, other, v_attr.y > 0.0), 0.0, 0.0));
}
