// Ours, beyond the papers: one merge pass of the blocked sort (src/sort/blocked.rs,
// merge_schedule). The entries lie row-major in the blocked layout (SIZE = 2^BITS a pixel, LANES
// a texel, one texel per layer of a 3D texture written through multiple render targets), sorted
// in runs of 2^u_run_log. A fragment owns SIZE consecutive outputs of the merge of two runs A
// and B: a binary search finds how many of the outputs before its first come from A (the merge
// path), then it merges SIZE entries from where that leaves A and B.
//
// Why: a pass costs about the bytes it writes. The network needs about n² / 2 BITS passes for
// 2^n entries, merging n - BITS + 1; the search's fetches are shared by neighbouring fragments
// (the texture cache), and the merge reads two windows of SIZE entries.
//
// The merge is stable (A first among equal entries); entries are distinct (their identifiers
// differ), so it gives what the network gives, bit for bit.

#include "common/compare.glsl"

#ifndef BITS
#define BITS 4
#endif
#define SIZE (1 << BITS)
#ifdef COMPACT
#define LANES 4
#define ENTRY uint
uniform usampler3D u_blocks;
layout(location = 0) out uvec4 o_blocks[SIZE / LANES];
#define LESS(B, A) ((B) < (A))
// Above every entry but the largest possible one, which it equals: taking either gives the same.
#define SENTINEL 0xffffffffu
#else
#define LANES 2
#define ENTRY vec2
uniform sampler3D u_blocks;
layout(location = 0) out vec4 o_blocks[SIZE / LANES];
#define LESS(B, A) entry_less(B, A)
// Key NaN (after every key), identifier +inf (after every identifier).
#define SENTINEL vec2(uintBitsToFloat(0x7fc00000u), uintBitsToFloat(0x7f800000u))
#endif

// Entry t of each run's window, or the sentinel past the run's end.
#define LD(T) e[T] = i + T < run ? entry_at(a0 + i + T) : SENTINEL; bv[T] = j + T < run ? entry_at(b0 + j + T) : SENTINEL;
// The smaller of A[t] and B[SIZE - 1 - t].
#define MN(T, U) if (LESS(bv[U], e[T])) e[T] = bv[U];
// A compare-exchange of the bitonic merge, ascending.
#define MX(C, O) { ENTRY a = e[C]; ENTRY b = e[O]; bool sw = LESS(b, a); e[C] = sw ? b : a; e[O] = sw ? a : b; }

// log2 of the width of the blocks texture (read and written at the same size).
uniform int u_log_w;
// log2 of the sorted runs read.
uniform int u_run_log;

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
    while (lo < hi) {
        int mid = (lo + hi) >> 1;
        if (LESS(entry_at(b0 + k - mid - 1), entry_at(a0 + mid))) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    int i = lo;
    int j = k - lo;
    // The outputs [k, k + SIZE) are the SIZE smallest of A[i, i + SIZE) and B[j, j + SIZE):
    // fetched all at once (independent fetches, no chain of one fetch an output), past a run's
    // end as a sentinel above every entry. Then a bitonic merge in registers: e[t] = min(A[t],
    // B[SIZE - 1 - t]) is a bitonic sequence holding the SIZE smallest; log2(SIZE) steps sort it.
    // LOADS, HALF and MERGE are written out by the sorter (src/sort/gpu/blocked.rs) so that every
    // array index is a constant and the entries stay in registers.
    ENTRY e[SIZE];
    ENTRY bv[SIZE];
    LOADS
    HALF
    MERGE
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
