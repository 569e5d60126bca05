//! Sorting networks as pass schedules, and their CPU twin.
//!
//! Elements are (key, id) pairs stored row-major in a `width`×`height` texture: element `i` is
//! texel `(i mod width, i div width)`. A schedule is a list of [`Step`]s; in each step every
//! element is compared with at most one partner and keeps the smaller or the larger of the two.
//! The GPU passes and [`apply_step`] derive partner and decision from the same rules, so the GPU's
//! output can be checked against the twin bit for bit.
//!
//! Order: (key, id) lexicographically, keys by [`key_order_bits`] (NaN after +inf, -0.0 equal to
//! +0.0), ids (non-negative floats) by their bits. Both elements of a pair reach the same decision,
//! ties included, so no element is duplicated or lost.

/// A (key, id) pair, as stored in the R and G channels of a sort texture.
pub type Entry = [f32; 2];

/// Maps a key to an unsigned integer whose order is the sort order: -0.0 is +0.0, every NaN is
/// the positive quiet NaN, which lands after +inf. The GLSL twin is `key_order_bits` in
/// `glsl/common/compare.glsl`.
pub fn key_order_bits(key: f32) -> u32 {
    let mut u = key.to_bits();
    if u == 0x8000_0000 {
        u = 0;
    }
    if key.is_nan() {
        u = 0x7fc0_0000;
    }
    if u & 0x8000_0000 != 0 {
        !u
    } else {
        u | 0x8000_0000
    }
}

/// Whether `a` sorts before `b`.
pub fn entry_less(a: Entry, b: Entry) -> bool {
    entry_order(&a, &b) == std::cmp::Ordering::Less
}

/// The same order as [`entry_less`], for the standard library's sorts.
pub fn entry_order(a: &Entry, b: &Entry) -> std::cmp::Ordering {
    (key_order_bits(a[0]), a[1].to_bits()).cmp(&(key_order_bits(b[0]), b[1].to_bits()))
}

/// One pass of a sorting network.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum Step {
    /// Bitonic compare-exchange in a stage of block size `block`. With `mirror` (the first pass
    /// of a merge stage, UberFlow §4.3.3's implicit reversal) the partner is `i ^ (block - 1)`
    /// and every block ascends; otherwise the partner is `i ^ dist`, and in the row stages
    /// (`block <= width`) blocks ascend where `x & block == 0`, descend elsewhere.
    Bitonic {
        /// Size of the blocks this stage sorts.
        block: u32,
        /// Distance to the partner (a power of two) for non-mirror steps.
        dist: u32,
        /// Whether this is the reversing first pass of a merge stage.
        mirror: bool,
    },
    /// Latta's "recursion" program (Fig. 4): inside merge blocks of `count * step` elements,
    /// position `m = (i / step) mod count` with `1 <= m <= count - 2` compares with its odd-even
    /// neighbour (odd `m` with `m + 1`).
    OddEvenRecursion {
        /// Stride of the sub-sequence.
        step: u32,
        /// Elements of the sub-sequence.
        count: u32,
    },
    /// Latta's "end" program: `m = (i / step) mod 2` compares with `m`'s other half.
    OddEvenEnd {
        /// Stride of the pair.
        step: u32,
    },
}

impl Step {
    /// The XOR mask of a bitonic step (`None` for odd-even steps).
    pub fn mask(&self) -> Option<u32> {
        match *self {
            Step::Bitonic {
                block,
                dist,
                mirror,
            } => Some(if mirror { block - 1 } else { dist }),
            Step::OddEvenRecursion { .. } | Step::OddEvenEnd { .. } => None,
        }
    }
}

/// Partner of element `i` and whether `i` keeps the smaller entry; `None`: `i` stays.
pub fn partner(step: &Step, i: u32, width: u32) -> Option<(u32, bool)> {
    match *step {
        Step::Bitonic {
            block,
            dist,
            mirror,
        } => {
            let j = if mirror { i ^ (block - 1) } else { i ^ dist };
            Some((j, (i < j) == ascending(step, i, width)))
        }
        Step::OddEvenRecursion { step, count } => {
            let m = (i / step) % count;
            if m >= 1 && m + 2 <= count {
                if m % 2 == 1 {
                    Some((i + step, true))
                } else {
                    Some((i - step, false))
                }
            } else {
                None
            }
        }
        Step::OddEvenEnd { step } => {
            if (i / step).is_multiple_of(2) {
                Some((i + step, true))
            } else {
                Some((i - step, false))
            }
        }
    }
}

/// Whether the bitonic block of element `i` ascends in this step (always true for odd-even).
pub fn ascending(step: &Step, i: u32, width: u32) -> bool {
    match *step {
        Step::Bitonic { block, mirror, .. } => mirror || block > width || (i % width) & block == 0,
        Step::OddEvenRecursion { .. } | Step::OddEvenEnd { .. } => true,
    }
}

fn log2_exact(n: u32) -> Option<u32> {
    n.is_power_of_two().then(|| n.trailing_zeros())
}

/// UberFlow's row-wise bitonic sort of blocks of `block` elements of a `width`-wide texture:
/// rows first (stages of block ≤ width), then merges of 2, 4, ... rows, each merge stage opening
/// with the reversing pass. `block` = width × height sorts everything; width × k sorts within k
/// consecutive rows (the rows-only mode of §4.4 and §5). Both must be powers of two.
pub fn bitonic_schedule(width: u32, block: u32) -> Vec<Step> {
    let (Some(_), Some(k)) = (log2_exact(width), log2_exact(block)) else {
        return Vec::new();
    };
    let mut steps = Vec::new();
    for p in 1..=k {
        let b = 1u32 << p;
        if b <= width {
            for q in (0..p).rev() {
                steps.push(Step::Bitonic {
                    block: b,
                    dist: 1 << q,
                    mirror: false,
                });
            }
        } else {
            steps.push(Step::Bitonic {
                block: b,
                dist: b / 2,
                mirror: true,
            });
            for q in (0..p - 1).rev() {
                steps.push(Step::Bitonic {
                    block: b,
                    dist: 1 << q,
                    mirror: false,
                });
            }
        }
    }
    steps
}

/// Latta's odd-even merge sort of blocks of `block` elements (Fig. 5: `MergeSort` and `Merge`).
pub fn odd_even_schedule(block: u32) -> Vec<Step> {
    fn merge(count: u32, step: u32, out: &mut Vec<Step>) {
        if count > 2 {
            merge(count / 2, step * 2, out);
            out.push(Step::OddEvenRecursion { step, count });
        } else {
            out.push(Step::OddEvenEnd { step });
        }
    }
    fn merge_sort(count: u32, out: &mut Vec<Step>) {
        if count > 1 {
            merge_sort(count / 2, out);
            merge(count, 1, out);
        }
    }
    let mut steps = Vec::new();
    if block.is_power_of_two() {
        merge_sort(block, &mut steps);
    }
    steps
}

/// Splits a bitonic schedule into the passes of the multistep variant: consecutive steps of one
/// stage with up to `per_pass` steps whose mask is 2 or more (each doubles the texels a fragment
/// fetches); distance-1 steps join for free, since both of their entries share a packed texel.
pub fn group_steps(steps: &[Step], per_pass: usize) -> Vec<Vec<Step>> {
    let stage = |x: &Step| match x {
        Step::Bitonic { block, .. } => *block,
        Step::OddEvenRecursion { .. } | Step::OddEvenEnd { .. } => 0,
    };
    let wide = |x: &Step| x.mask().is_none_or(|m| m >= 2);
    let mut groups: Vec<Vec<Step>> = Vec::new();
    for s in steps {
        match groups.last_mut() {
            Some(g)
                if stage(&g[0]) == stage(s)
                    && stage(s) != 0
                    && (!wide(s) || g.iter().filter(|x| wide(x)).count() < per_pass.max(1)) =>
            {
                g.push(*s)
            }
            _ => groups.push(vec![*s]),
        }
    }
    groups
}

/// Applies one step to `data` (the CPU twin of a GPU pass).
pub fn apply_step(data: &mut [Entry], step: &Step, width: u32) {
    let n = data.len() as u32;
    let old = data.to_vec();
    for i in 0..n {
        if let Some((j, keep_min)) = partner(step, i, width) {
            if j >= n {
                continue;
            }
            let (a, b) = (old[i as usize], old[j as usize]);
            data[i as usize] = if entry_less(a, b) == keep_min { a } else { b };
        }
    }
}

/// Applies a group of steps as the multistep pass does: each element gathers the 2^s elements
/// its sub-network spans and runs the steps on them locally. Equal to applying them one by one.
pub fn apply_group(data: &mut [Entry], group: &[Step], width: u32) {
    if let [single] = group {
        return apply_step(data, single, width);
    }
    let n = data.len();
    let old = data.to_vec();
    let masks: Vec<u32> = group.iter().filter_map(Step::mask).collect();
    let size = 1usize << masks.len();
    for i in 0..n as u32 {
        let index = |c: usize| {
            (0..masks.len()).fold(
                i,
                |acc, t| if c >> t & 1 == 1 { acc ^ masks[t] } else { acc },
            )
        };
        let mut local: Vec<Entry> = (0..size).map(|c| old[index(c) as usize]).collect();
        for (t, step) in group.iter().enumerate() {
            let next = local.clone();
            for c in 0..size {
                let other = c ^ (1 << t);
                let (gi, gj) = (index(c), index(other));
                let keep_min = (gi < gj) == ascending(step, gi, width);
                let (a, b) = (next[c], next[other]);
                local[c] = if entry_less(a, b) == keep_min { a } else { b };
            }
        }
        data[i as usize] = local[0];
    }
}

/// Counts pairs out of order (a measure of sortedness; 0 when sorted).
pub fn inversions(data: &[Entry]) -> u64 {
    // Merge sort count, O(n log n).
    fn count(v: &mut [Entry], buf: &mut Vec<Entry>) -> u64 {
        let n = v.len();
        if n < 2 {
            return 0;
        }
        let mid = n / 2;
        let mut c = count(&mut v[..mid], buf) + count(&mut v[mid..], buf);
        buf.clear();
        let (mut i, mut j) = (0, mid);
        while i < mid && j < n {
            if entry_less(v[j], v[i]) {
                c += (mid - i) as u64;
                buf.push(v[j]);
                j += 1;
            } else {
                buf.push(v[i]);
                i += 1;
            }
        }
        buf.extend_from_slice(&v[i..mid]);
        buf.extend_from_slice(&v[j..n]);
        v.copy_from_slice(buf);
        c
    }
    count(&mut data.to_vec(), &mut Vec::with_capacity(data.len()))
}

/// Whether every block of `block` consecutive entries is in order.
pub fn blocks_sorted(data: &[Entry], block: usize) -> bool {
    data.chunks(block.max(1))
        .all(|c| c.windows(2).all(|w| !entry_less(w[1], w[0])))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(seed: &mut u64) -> u32 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 33) as u32
    }

    fn random_entries(n: usize, seed: u64, distinct: u32) -> Vec<Entry> {
        let mut s = seed;
        (0..n)
            .map(|i| {
                [
                    (lcg(&mut s) % distinct) as f32 - (distinct / 2) as f32,
                    i as f32,
                ]
            })
            .collect()
    }

    fn reference(v: &[Entry]) -> Vec<Entry> {
        let mut r = v.to_vec();
        r.sort_by(entry_order);
        r
    }

    #[test]
    fn key_order_puts_nan_last_and_merges_signed_zeros() {
        let order = [
            f32::NEG_INFINITY,
            -1.0,
            -1e-40,
            0.0,
            1e-40,
            1.0,
            f32::INFINITY,
            f32::NAN,
        ];
        for w in order.windows(2) {
            assert!(
                key_order_bits(w[0]) < key_order_bits(w[1]),
                "{} < {}",
                w[0],
                w[1]
            );
        }
        assert_eq!(key_order_bits(-0.0), key_order_bits(0.0));
        assert_eq!(key_order_bits(-f32::NAN), key_order_bits(f32::NAN));
    }

    #[test]
    fn pass_counts_match_the_papers() {
        // UberFlow §5: log(n²)(log(n²)+1)/2 passes for n×n; Latta: 210 for 1024².
        for (w, h) in [(4u32, 4u32), (128, 128), (1024, 1024), (16, 2)] {
            let k = (w * h).trailing_zeros() as usize;
            assert_eq!(bitonic_schedule(w, w * h).len(), k * (k + 1) / 2);
            assert_eq!(odd_even_schedule(w * h).len(), k * (k + 1) / 2);
        }
        assert_eq!(odd_even_schedule(1024 * 1024).len(), 210);
    }

    #[test]
    fn twins_sort_like_slice_sort() {
        for &(w, h) in &[
            (1u32, 1u32),
            (2, 1),
            (1, 2),
            (4, 4),
            (8, 2),
            (2, 8),
            (32, 16),
            (64, 64),
        ] {
            let n = (w * h) as usize;
            for seed in 0..3 {
                let input = random_entries(n, seed, 7 + seed as u32 * 50);
                let want = reference(&input);
                let mut a = input.clone();
                for s in bitonic_schedule(w, w * h) {
                    apply_step(&mut a, &s, w);
                }
                assert_eq!(a, want, "bitonic {w}x{h}");
                let mut b = input.clone();
                for s in odd_even_schedule(w * h) {
                    apply_step(&mut b, &s, w);
                }
                assert_eq!(b, want, "odd-even {w}x{h}");
                for per in [2, 3] {
                    let mut c = input.clone();
                    for g in group_steps(&bitonic_schedule(w, w * h), per) {
                        apply_group(&mut c, &g, w);
                    }
                    assert_eq!(c, want, "multistep {per} {w}x{h}");
                }
            }
        }
    }

    #[test]
    fn rows_only_sorts_each_row_and_row_group() {
        let (w, h) = (16u32, 8u32);
        let input = random_entries((w * h) as usize, 9, 1000);
        for rows in [1u32, 2, 4] {
            let mut a = input.clone();
            for s in bitonic_schedule(w, w * rows) {
                apply_step(&mut a, &s, w);
            }
            assert!(blocks_sorted(&a, (w * rows) as usize));
            for (got, inp) in a
                .chunks((w * rows) as usize)
                .zip(input.chunks((w * rows) as usize))
            {
                assert_eq!(got, reference(inp).as_slice());
            }
        }
    }

    /// The 0-1 principle: a network that sorts every 0/1 input of 16 elements sorts everything.
    #[test]
    fn zero_one_principle_for_16_elements() {
        let networks: Vec<(&str, u32, Vec<Vec<Step>>)> = vec![
            (
                "bitonic 16x1",
                16,
                bitonic_schedule(16, 16)
                    .into_iter()
                    .map(|s| vec![s])
                    .collect(),
            ),
            (
                "bitonic 4x4",
                4,
                bitonic_schedule(4, 16)
                    .into_iter()
                    .map(|s| vec![s])
                    .collect(),
            ),
            (
                "odd-even",
                16,
                odd_even_schedule(16).into_iter().map(|s| vec![s]).collect(),
            ),
            (
                "multistep 3, 4x4",
                4,
                group_steps(&bitonic_schedule(4, 16), 3),
            ),
        ];
        for (name, width, passes) in networks {
            for bits in 0u32..1 << 16 {
                let mut v: Vec<Entry> = (0..16)
                    .map(|i| [((bits >> i) & 1) as f32, i as f32])
                    .collect();
                for g in &passes {
                    apply_group(&mut v, g, width);
                }
                assert!(
                    v.windows(2).all(|w| w[0][0] <= w[1][0]),
                    "{name} fails on {bits:016b}"
                );
            }
        }
    }

    #[test]
    fn odd_even_never_increases_inversions() {
        let input = random_entries(256, 4, 100);
        let mut v = input;
        let mut last = inversions(&v);
        for s in odd_even_schedule(256) {
            apply_step(&mut v, &s, 16);
            let now = inversions(&v);
            assert!(now <= last, "{s:?}: {last} -> {now}");
            last = now;
        }
        assert_eq!(last, 0);
    }

    #[test]
    fn inversion_count_is_right() {
        let v: Vec<Entry> = [3.0, 1.0, 2.0, 0.0]
            .iter()
            .enumerate()
            .map(|(i, &k)| [k, i as f32])
            .collect();
        assert_eq!(inversions(&v), 5);
    }
}
