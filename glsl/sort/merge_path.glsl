// The merge path of the blocked sort's merge passes (src/sort/blocked.rs, merge_schedule),
// shared by the merge (sort/merge.frag) and its partition pass (sort/merge_partition.frag).
// The entries lie row-major in the blocked layout (SIZE = 2^BITS a pixel, LANES a texel, one
// texel per layer of a 3D texture written through multiple render targets), sorted in runs.

#include "common/compare.glsl"

#ifdef COMPACT
#define LESS(B, A) ((B) < (A))
#else
#define LESS(B, A) entry_less(B, A)
#endif

#include "sort/blocked_entry.glsl"

#include "sort/merge_search.glsl"
