// Ours, beyond the papers: the partition pass before a merge pass of long runs (src/sort/
// blocked.rs, merge_schedule). One fragment for every 2^u_part_bits outputs finds, by the full
// binary search of the merge path, how many of the outputs before its first come from the first
// run of its pair; the merge pass then searches only between two neighbouring splits (at most
// 2^u_part_bits entries) instead of the whole run.
//
// Why: a merge pass's search of r steps runs before any of its fragment's outputs, fetch after
// dependent fetch; with runs up to 2^23 entries it held the merges at 1.6 times their write
// floor (NVIDIA H100, 4096²; 1.24 times with the splits). A split every 2^(BITS + 4) outputs
// costs one fragment in 16 a full search and writes 4 bytes.

#include "sort/merge_path.glsl"

// log2 of the sorted runs read.
uniform int u_run_log;
// log2 of the outputs between splits.
uniform int u_part_bits;
// log2 of the width of the split texture.
uniform int u_split_log_w;

layout(location = 0) out float o_split;

void main() {
    ivec2 f = ivec2(gl_FragCoord.xy);
    int first = ((f.y << u_split_log_w) | f.x) << u_part_bits;
    int run = 1 << u_run_log;
    int a0 = first & ~(2 * run - 1);
    int k = first - a0;
    // Below 2^24: exact in a float.
    o_split = float(merge_split(a0, a0 + run, k, max(0, k - run), min(k, run)));
}
