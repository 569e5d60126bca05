// The coherent re-sort's merge (src/sim/fluid/resort.rs): after the aligned blocks of u_block
// entries are sorted, every block of u_block at offset u_offset (half a block) holds two sorted
// halves, A and B; one pass merges them. The fragment of the block's k-th output finds by a
// binary search how many of the outputs before it come from A (the merge path), x, and writes the
// smaller of A[x] and B[k - x]. Entries before the first offset block and from u_end on are
// copied.
//
// Why one pass: the bitonic merge of the halves takes log2(u_block) passes, each writing every
// entry; the search's fetches (log2(u_block) - 1 pairs) are shared by neighbouring fragments.

#include "common/compare.glsl"

uniform sampler2D u_keys;
// log2 of the texture's width (a power of two: the fluid's state is).
uniform int u_log_w;
uniform int u_offset;
uniform int u_end;
uniform int u_block;

layout(location = 0) out vec4 o_entry;

vec2 entry_at(int s) {
    return texelFetch(u_keys, ivec2(s & ((1 << u_log_w) - 1), s >> u_log_w), 0).xy;
}

#define ENTRY vec2
#define LESS(B, A) entry_less(B, A)
#include "sort/merge_search.glsl"

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int i = (t.y << u_log_w) | t.x;
    if (i < u_offset || i >= u_end) {
        o_entry = vec4(texelFetch(u_keys, t, 0).xy, 0.0, 0.0);
        return;
    }
    int r = i - u_offset;
    int half_block = u_block >> 1;
    int a0 = u_offset + (r & ~(u_block - 1));
    int b0 = a0 + half_block;
    int k = r & (u_block - 1);
    // The smallest x with B[k - x - 1] < A[x]: the outputs before k take A[0, x) and B[0, k - x).
    int lo = merge_split(a0, b0, k, max(0, k - half_block), min(k, half_block));
    int j = k - lo;
    vec2 out_entry;
    if (j >= half_block) {
        out_entry = entry_at(a0 + lo);
    } else if (lo >= half_block) {
        out_entry = entry_at(b0 + j);
    } else {
        vec2 a = entry_at(a0 + lo);
        vec2 b = entry_at(b0 + j);
        out_entry = entry_less(b, a) ? b : a;
    }
    o_entry = vec4(out_entry, 0.0, 0.0);
}
