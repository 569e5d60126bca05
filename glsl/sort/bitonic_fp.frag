// UberFlow's bitonic sort, FP variant (§4.3.3, §5 Table 1 "FP"): the fragment program derives
// its partner, the direction and the comparison from its texel coordinates and the pass
// uniforms. Network: src/sort/network.rs (Step::Bitonic).

#include "common/compare.glsl"
#include "common/precision.glsl"

uniform sampler2D u_keys;
uniform int u_width;
uniform int u_block;
uniform int u_dist;
uniform bool u_mirror;

layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * u_width + t.x;
    int j = u_mirror ? i ^ (u_block - 1) : i ^ u_dist;
    bool ascending = u_mirror || u_block > u_width || (t.x & u_block) == 0;
    vec2 own = texelFetch(u_keys, t, 0).xy;
    vec2 other = texelFetch(u_keys, ivec2(j % u_width, j / u_width), 0).xy;
    o_entry = fp_store(vec4(compare_exchange(own, other, (i < j) == ascending), 0.0, 0.0));
}
