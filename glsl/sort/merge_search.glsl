// The merge path's binary search, shared by every merge of two sorted runs (the blocked sort's
// merge passes, sort/merge_path.glsl; the fluid's coherent re-sort, fluid/merge.frag). The
// includer defines ENTRY, LESS(b, a) and ENTRY entry_at(int) before it.

// How many of the first k outputs of the stable merge of the runs at a0 and b0 come from the
// first (A first among equal entries): the smallest i in [lo, hi] with B[k - i - 1] < A[i], or
// hi. The caller's [lo, hi] must hold the answer; the widest is [max(0, k - run), min(k, run)].
int merge_split(int a0, int b0, int k, int lo, int hi) {
    while (lo < hi) {
        int mid = (lo + hi) >> 1;
        if (LESS(entry_at(b0 + k - mid - 1), entry_at(a0 + mid))) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    return lo;
}
