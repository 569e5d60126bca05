// The merge path of the blocked sort's merge passes (src/sort/blocked.rs, merge_schedule),
// shared by the merge (sort/merge.frag) and its partition pass (sort/merge_partition.frag).
// The entries lie row-major in the blocked layout (SIZE = 2^BITS a pixel, LANES a texel, one
// texel per layer of a 3D texture written through multiple render targets), sorted in runs.

#include "common/compare.glsl"

#ifndef BITS
#define BITS 4
#endif
#define SIZE (1 << BITS)
#ifdef COMPACT
#define LANES 4
#define ENTRY uint
uniform usampler3D u_blocks;
#define LESS(B, A) ((B) < (A))
#else
#define LANES 2
#define ENTRY vec2
uniform sampler3D u_blocks;
#define LESS(B, A) entry_less(B, A)
#endif

// log2 of the width of the blocks texture (read and written at the same size).
uniform int u_log_w;

// The entry at row-major index s.
ENTRY entry_at(int s) {
    int p = s >> BITS;
    int mask = (1 << u_log_w) - 1;
    ivec3 t = ivec3(p & mask, p >> u_log_w, (s & (SIZE - 1)) / LANES);
#ifdef COMPACT
    return texelFetch(u_blocks, t, 0)[s & 3];
#else
    vec4 v = texelFetch(u_blocks, t, 0);
    return (s & 1) == 0 ? v.xy : v.zw;
#endif
}

#include "sort/merge_search.glsl"
