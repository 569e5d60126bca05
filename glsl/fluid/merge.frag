// The coherent re-sort's merge (src/sim/fluid/resort.rs): after the aligned blocks of u_block
// entries are sorted, every block of u_block at offset u_offset (half a block) holds two sorted
// halves; one pass of their bitonic merge. r is the index from the first offset block: with
// u_mirror the partner is r ^ (u_block - 1) (the halves compared as one bitonic sequence), else
// r ^ u_dist. Entries before the first offset block and from u_end on are copied.

#include "common/compare.glsl"

uniform sampler2D u_keys;
uniform int u_width;
uniform int u_offset;
uniform int u_end;
uniform int u_block;
uniform int u_dist;
uniform bool u_mirror;

layout(location = 0) out vec4 o_entry;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = t.y * u_width + t.x;
    vec2 own = texelFetch(u_keys, t, 0).xy;
    if (i < u_offset || i >= u_end) {
        o_entry = vec4(own, 0.0, 0.0);
        return;
    }
    int r = i - u_offset;
    int j = u_offset + (u_mirror ? r ^ (u_block - 1) : r ^ u_dist);
    vec2 other = texelFetch(u_keys, ivec2(j % u_width, j / u_width), 0).xy;
    o_entry = vec4(compare_exchange(own, other, i < j), 0.0, 0.0);
}
