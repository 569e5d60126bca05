// The identifier at sorted position j of the first lattice's sort, for the staggered lattice's
// passes that read the state through both sorts (src/sim/collide/lattices.rs,
// `reads_through_first`): the staggered sort's identifiers name places in the first lattice's
// layout, which holds the positions only, and this names the particle's texel in the state the
// first sort read. The first sort's entries are read where it left them: its blocked layout
// (FIRST_BLOCKED, with FIRST_BITS) or its row-major texture (with the pass's PACKED and ID_TABLE:
// both sorts are of one variant).

#include "sort/sorted_id.glsl"
#include "sort/blocked_entry.glsl"

#ifdef FIRST_BLOCKED
uniform sampler3D u_first_blocks;
uniform int u_first_log_w;
#else
uniform sampler2D u_first_sorted;
uniform int u_first_sort_width;
#endif

int first_id(int j) {
#ifdef FIRST_BLOCKED
    return decode_id(entry_in(u_first_blocks, u_first_log_w, FIRST_BITS, j).y);
#else
    return sorted_id(u_first_sorted, u_first_sort_width, j);
#endif
}
