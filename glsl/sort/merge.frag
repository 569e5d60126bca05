// Ours, beyond the papers: one merge pass of the blocked sort (src/sort/blocked.rs,
// merge_schedule). The entries lie row-major in the blocked layout (SIZE = 2^BITS a pixel, LANES
// a texel, one texel per layer of a 3D texture written through multiple render targets), sorted
// in runs of 2^u_run_log. A fragment owns SIZE consecutive outputs of the merge of two runs A
// and B: a binary search finds how many of the outputs before its first come from A (the merge
// path; with PARTITIONED only between the two splits of the partition pass around it,
// sort/merge_partition.frag), then it merges SIZE entries from where that leaves A and B.
//
// Why: a pass costs about the bytes it writes. The network needs about n² / 2 BITS passes for
// 2^n entries, merging n - BITS + 1; the search's fetches are shared by neighbouring fragments
// (the texture cache), and the merge fetches each entry it takes once.
//
// The merge is stable (A first among equal entries); entries are distinct (their identifiers
// differ), so it gives what the network gives, bit for bit.

#include "sort/merge_path.glsl"

#ifdef COMPACT
layout(location = 0) out uvec4 o_blocks[SIZE / LANES];
#else
layout(location = 0) out vec4 o_blocks[SIZE / LANES];
#endif

// log2 of the sorted runs read.
uniform int u_run_log;
#ifdef PARTITIONED
// log2 of the outputs between the splits of the partition pass (u_splits) that ran before this
// pass: the search then runs between the two splits around the fragment.
uniform int u_part_bits;
uniform sampler2D u_splits;
uniform int u_split_log_w;

float split_at(int q) {
    return texelFetch(u_splits, ivec2(q & ((1 << u_split_log_w) - 1), q >> u_split_log_w), 0).r;
}
#endif

void main() {
    ivec2 f = ivec2(gl_FragCoord.xy);
    int first = ((f.y << u_log_w) | f.x) << BITS;
    int run = 1 << u_run_log;
    int a0 = first & ~(2 * run - 1);
    int b0 = a0 + run;
    int k = first - a0;
    // The smallest i with B[k - i - 1] < A[i]: the outputs before `first` take A[0, i) and
    // B[0, k - i).
    int lo = max(0, k - run);
    int hi = min(k, run);
#ifdef PARTITIONED
    {
        // The split is monotone along the path, and so is its complement k - i: between the
        // splits at kq <= k and kq + 2^u_part_bits (or the pair's end) it moves at most as far
        // as k moves.
        int q = first >> u_part_bits;
        int kq = (q << u_part_bits) - a0;
        int i_lo = int(split_at(q));
        int kq1 = kq + (1 << u_part_bits);
        int i_hi = kq1 < 2 * run ? int(split_at(q + 1)) : run;
        kq1 = min(kq1, 2 * run);
        lo = max(lo, max(i_lo, i_hi - (kq1 - k)));
        hi = min(hi, min(i_lo + (k - kq), i_hi));
    }
#endif
    int i = merge_split(a0, b0, k, lo, hi);
    int j = k - i;
    ENTRY a = entry_at(a0 + min(i, run - 1));
    ENTRY b = entry_at(b0 + min(j, run - 1));
    ENTRY e[SIZE];
    // One fetch an output, from whichever run gave it: no divergent branch. (Fetching both
    // windows of SIZE entries at once and merging them by a bitonic network in registers was
    // measured slower on an NVIDIA H100: 7.4 against 5.0 ms for 1024² entries.)
    for (int t = 0; t < SIZE; t++) {
        bool take_a = j >= run || (i < run && !LESS(b, a));
        e[t] = take_a ? a : b;
        i += take_a ? 1 : 0;
        j += take_a ? 0 : 1;
        if (t + 1 < SIZE) {
            ENTRY next = entry_at(take_a ? a0 + min(i, run - 1) : b0 + min(j, run - 1));
            a = take_a ? next : a;
            b = take_a ? b : next;
        }
    }
#ifdef COMPACT
    for (int l = 0; l < SIZE / LANES; l++) {
        o_blocks[l] = uvec4(e[4 * l], e[4 * l + 1], e[4 * l + 2], e[4 * l + 3]);
    }
#else
    for (int l = 0; l < SIZE / LANES; l++) {
        o_blocks[l] = vec4(e[2 * l], e[2 * l + 1]);
    }
#endif
}
