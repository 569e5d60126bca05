// UberFlow's bitonic sort, GP/FP packed variant (§4.3.3, last paragraphs): two consecutive
// entries (k0, id0, k1, id1) per RGBA texel, half the fragments; the compare-exchange runs twice.
// SAME_TEXEL: the distance-1 pass compares the two entries of one texel and fetches no second
// operand. MIRROR: the reversing pass; the partner texel's entries meet ours crosswise.

#include "common/compare.glsl"
#include "common/precision.glsl"

uniform sampler2D u_keys;
uniform ivec2 u_offset;

in vec4 v_attr;
layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 own = texelFetch(u_keys, t, 0);
    bool keep_min = v_attr.y > 0.0;
#if defined(SAME_TEXEL)
    // Slot 0 is the lower index: it keeps the smaller entry in an ascending block.
    vec2 lo = compare_exchange(own.xy, own.zw, keep_min);
    vec2 hi = compare_exchange(own.zw, own.xy, !keep_min);
    o_entry = fp_store(vec4(lo, hi));
#elif defined(MIRROR)
    vec4 other = texelFetch(u_keys, ivec2(floor(v_attr.zw)), 0);
    o_entry = fp_store(vec4(compare_exchange(own.xy, other.zw, keep_min),
                            compare_exchange(own.zw, other.xy, keep_min)));
#else
    int sign = v_attr.x < 0.0 ? -1 : 1;
    vec4 other = texelFetch(u_keys, t + sign * u_offset, 0);
    o_entry = fp_store(vec4(compare_exchange(own.xy, other.xy, keep_min),
                            compare_exchange(own.zw, other.zw, keep_min)));
#endif
}
