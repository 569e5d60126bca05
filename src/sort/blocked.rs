//! Our own sort for today's GPUs: a bitonic network run in registers, 2^b entries per fragment.
//!
//! Why: on an NVIDIA H200 a fragment pass costs about what it writes (≈55 GB/s into colour
//! attachments) plus what it fetches, plus a fixed cost. UberFlow's variants do one network step
//! per pass, so every step writes every entry once (8 bytes) and fetches two texels. Here a
//! fragment owns `2^b` entries (b = 2..4, two entries per RGBA32F texel, one texel per layer of a
//! 3D texture written through multiple render targets), fetches them once, runs every
//! consecutive step of the network whose bit lies among its `b` group bits in registers, and
//! writes them back: a pass does about `b` steps for the bytes of one.
//!
//! The trick that makes any group of `b` bits local is a layout that changes from pass to pass:
//! the storage index of an entry is a permutation of the bits of its logical index, with the
//! pass's group bits as the low `b` bits (the slot: layer and lane) and the other bits, in
//! ascending order, as the pixel. A pass reads each entry where the previous layout put it
//! (texel fetches can gather from anywhere) and writes it where its own layout puts it. The
//! first pass reads the key pass's row-major texture, a last pass writes the sorted entries
//! row-major again, so everything after the sort (the gather, the collision search) is unchanged.
//!
//! With `pinned`, logical bit 0 stays in the lane of every layout: both entries of a fetched
//! texel are used (half the fetches), at the price of one group bit.
//!
//! [`schedule`] builds the passes, [`apply`] is the CPU twin that runs the same network on the
//! logical order; the GPU's output is checked against it bit for bit.

use super::network::{entry_less, Entry};

/// One compare-exchange step of the network: partner `i ^ (1 << bit)`; the pair ascends where bit
/// `dir` of `i` is 0 (`None`: every pair ascends, the last stage of a block).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct BitStep {
    /// The logical bit the step flips.
    pub bit: u32,
    /// The logical bit that sets the direction, if any.
    pub dir: Option<u32>,
}

/// One pass: the group of logical bits it holds in registers (in slot order: group bit `t` is
/// slot bit `t`) and the steps it runs, each as the slot bit it flips; or a merge pass.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BlockPass {
    /// Logical bits of the slot, low to high.
    pub group: Vec<u32>,
    /// The steps, in order.
    pub steps: Vec<BitStep>,
    /// `Some(r)`: no network steps; the pass merges sorted runs of 2^r entries in pairs into
    /// runs of 2^(r+1), each fragment finding where its 2^b outputs start by a binary search
    /// (merge path) and merging them from the two runs. Its layout is row-major (group
    /// `0..b`).
    pub merge: Option<u32>,
    /// `Some(r)`: no steps, the entries unchanged: the partition pass before the merge of runs
    /// of 2^r, which finds the merge path's split every 2^[`partition_bits`] outputs so that
    /// the merge searches only between two splits.
    pub partition: Option<u32>,
}

impl BlockPass {
    /// The slot bit of each step (what the pass's program is compiled for).
    pub fn local_bits(&self) -> Vec<u32> {
        self.steps
            .iter()
            .map(|s| self.group.iter().position(|&g| g == s.bit).unwrap() as u32)
            .collect()
    }

    /// Storage bit of every logical bit (`n` of them) in this pass's output layout.
    pub fn layout(&self, n: u32) -> Vec<u32> {
        let mut perm = vec![0u32; n as usize];
        for (t, &g) in self.group.iter().enumerate() {
            perm[g as usize] = t as u32;
        }
        let mut next = self.group.len() as u32;
        for l in 0..n {
            if !self.group.contains(&l) {
                perm[l as usize] = next;
                next += 1;
            }
        }
        perm
    }

    /// The logical bits of the pixel index, low to high.
    pub fn pixel_bits(&self, n: u32) -> Vec<u32> {
        (0..n).filter(|l| !self.group.contains(l)).collect()
    }
}

/// The bitonic network over blocks of `2^block_bits` entries, as single steps.
pub fn network(block_bits: u32) -> Vec<BitStep> {
    let mut steps = Vec::new();
    for k in 1..=block_bits {
        for j in (0..k).rev() {
            steps.push(BitStep {
                bit: j,
                dir: (k < block_bits).then_some(k),
            });
        }
    }
    steps
}

/// The passes of a sort of `2^n` entries in blocks of `2^block_bits` (`block_bits = n`: one
/// sort of everything), `b` group bits per pass (clamped to `n`), optionally with bit 0 pinned.
pub fn schedule(n: u32, block_bits: u32, b: u32, pinned: bool) -> Vec<BlockPass> {
    let b = b.min(n).max(1);
    let pinned = pinned && b >= 2;
    let mut passes: Vec<BlockPass> = Vec::new();
    let fresh = || BlockPass {
        group: if pinned { vec![0] } else { Vec::new() },
        steps: Vec::new(),
        merge: None,
        partition: None,
    };
    let mut cur = fresh();
    for step in network(block_bits) {
        let fits = cur.group.contains(&step.bit) || (cur.group.len() as u32) < b;
        if !fits {
            passes.push(std::mem::replace(&mut cur, fresh()));
        }
        if !cur.group.contains(&step.bit) {
            cur.group.push(step.bit);
        }
        cur.steps.push(step);
    }
    if !cur.steps.is_empty() {
        passes.push(cur);
    }
    // Pad every group to exactly b bits: a fragment always owns 2^b entries.
    for p in &mut passes {
        let mut l = 0;
        while (p.group.len() as u32) < b {
            if !p.group.contains(&l) {
                p.group.push(l);
            }
            l += 1;
        }
    }
    passes
}

/// The passes of a merge sort of `2^n` entries in blocks of `2^block_bits`, `b` bits a fragment:
/// the network sorts runs of `2^b` entries in one pass (its group `0..b`, so its layout is
/// row-major), then `block_bits - b` merge passes double the runs until they fill the blocks.
/// Where the blocks are no longer than a fragment's entries, the network alone.
///
/// Why: every pass writes every entry, and the bytes written bound a pass. The network needs
/// about `block_bits² / 2b` passes; merging needs `block_bits - b + 1` (21 instead of 74 for
/// 2^24 entries, 16 a fragment), at the price of a binary search of `r` fetches a fragment and
/// its entries fetched one by one. Runs of at least 2^([`partition_bits`] + 2) are merged after
/// a partition pass, which bounds that search to [`partition_bits`] steps.
pub fn merge_schedule(n: u32, block_bits: u32, b: u32) -> Vec<BlockPass> {
    let b = b.min(n).max(1);
    if block_bits <= b {
        return schedule(n, block_bits, b, false);
    }
    let mut passes = schedule(n, b, b, false);
    debug_assert!(passes.len() == 1 && passes[0].group == (0..b).collect::<Vec<_>>());
    let pass = |merge, partition| BlockPass {
        group: (0..b).collect(),
        steps: Vec::new(),
        merge,
        partition,
    };
    for r in b..block_bits {
        if r >= partition_bits(b) + 2 {
            passes.push(pass(None, Some(r)));
        }
        passes.push(pass(Some(r), None));
    }
    passes
}

/// log2 of the outputs between two splits of a partition pass, for `b` bits (2^b entries) a
/// fragment: a split every 16 fragments' outputs. Merges of shorter runs search the whole run.
pub const fn partition_bits(b: u32) -> u32 {
    b + 4
}

/// Merges the sorted runs of `2^r` entries of `entries` in pairs (stable, by [`entry_less`]):
/// the CPU twin of a merge pass.
pub fn merge_runs(entries: &mut [Entry], r: u32) {
    let run = 1usize << r;
    for pair in entries.chunks_mut(2 * run) {
        if pair.len() <= run {
            continue;
        }
        let (a, b) = pair.split_at(run);
        let (mut i, mut j) = (0, 0);
        let mut out = Vec::with_capacity(pair.len());
        while i < a.len() || j < b.len() {
            let take_a = j >= b.len() || (i < a.len() && !entry_less(b[j], a[i]));
            if take_a {
                out.push(a[i]);
                i += 1;
            } else {
                out.push(b[j]);
                j += 1;
            }
        }
        pair.copy_from_slice(&out);
    }
}

/// Runs `steps` on `entries` in logical order: the CPU twin of the GPU passes.
pub fn apply(entries: &mut [Entry], steps: &[BitStep]) {
    for s in steps {
        let m = 1usize << s.bit;
        for i in 0..entries.len() {
            let j = i | m;
            if i & m != 0 || j >= entries.len() {
                continue;
            }
            let ascending = s.dir.is_none_or(|d| (i >> d) & 1 == 0);
            if entry_less(entries[j], entries[i]) == ascending {
                entries.swap(i, j);
            }
        }
    }
}

/// Runs every pass of a schedule with [`apply`].
pub fn apply_schedule(entries: &mut [Entry], passes: &[BlockPass]) {
    for p in passes {
        match p.merge {
            Some(r) => merge_runs(entries, r),
            // A partition pass leaves the entries as they are (no steps).
            None => apply(entries, &p.steps),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random(n: usize, seed: u64) -> Vec<Entry> {
        let mut s = seed;
        (0..n)
            .map(|i| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                [((s >> 40) % 97) as f32 - 40.0, i as f32]
            })
            .collect()
    }

    #[test]
    fn the_network_sorts_every_block() {
        for n in 1..=10u32 {
            for block_bits in 1..=n {
                let mut e = random(1 << n, n as u64 * 31 + block_bits as u64);
                let mut want = e.clone();
                for chunk in want.chunks_mut(1 << block_bits) {
                    chunk.sort_by(|a, b| {
                        if entry_less(*a, *b) {
                            std::cmp::Ordering::Less
                        } else {
                            std::cmp::Ordering::Greater
                        }
                    });
                }
                apply(&mut e, &network(block_bits));
                assert_eq!(e, want, "n {n}, block bits {block_bits}");
            }
        }
    }

    #[test]
    fn passes_keep_the_steps_and_hold_b_distinct_bits() {
        for n in 1..=20u32 {
            for b in 1..=4u32 {
                for pinned in [false, true] {
                    let passes = schedule(n, n, b, pinned);
                    let flat: Vec<BitStep> = passes.iter().flat_map(|p| p.steps.clone()).collect();
                    assert_eq!(flat, network(n), "n {n} b {b}");
                    for p in &passes {
                        let mut g = p.group.clone();
                        g.sort();
                        g.dedup();
                        assert_eq!(g.len() as u32, b.min(n), "n {n} b {b} {p:?}");
                        assert!(p.steps.iter().all(|s| p.group.contains(&s.bit)));
                        if pinned && b.min(n) >= 2 {
                            assert_eq!(p.group[0], 0);
                        }
                        let layout = p.layout(n);
                        let mut seen = layout.clone();
                        seen.sort();
                        assert_eq!(seen, (0..n).collect::<Vec<_>>());
                    }
                }
            }
        }
    }

    #[test]
    fn merge_passes_sort_every_block_as_the_network_does() {
        for n in 1..=12u32 {
            for block_bits in 1..=n {
                for b in 2..=5u32 {
                    let mut e = random(1 << n, n as u64 * 7 + block_bits as u64 + b as u64);
                    let mut want = e.clone();
                    apply(&mut want, &network(block_bits));
                    let passes = merge_schedule(n, block_bits, b);
                    apply_schedule(&mut e, &passes);
                    assert_eq!(e, want, "n {n}, block bits {block_bits}, b {b}");
                    if block_bits > b.min(n) {
                        let merges = passes.iter().filter(|p| p.merge.is_some()).count();
                        assert_eq!(merges as u32, block_bits - b.min(n));
                        // A partition pass right before each merge of runs of 2^(P + 2) or
                        // more, for the same runs.
                        for (k, p) in passes.iter().enumerate() {
                            let r = p.merge.or(p.partition);
                            let long = r.is_some_and(|r| r >= partition_bits(b.min(n)) + 2);
                            match (p.merge, p.partition) {
                                (Some(_), None) => {
                                    assert_eq!(passes[k - 1].partition.is_some(), long);
                                }
                                (None, Some(r)) => {
                                    assert!(long);
                                    assert_eq!(passes[k + 1].merge, Some(r));
                                }
                                (None, None) => assert_eq!(k, 0),
                                (Some(_), Some(_)) => panic!("a merge and a partition: {p:?}"),
                            }
                        }
                        // Row-major throughout: the unpack reads the identity layout.
                        let last = passes.last().unwrap().layout(n);
                        assert_eq!(last, (0..n).collect::<Vec<_>>());
                    }
                }
            }
        }
        // 2^24 entries, 16 a fragment: 21 passes that write every entry where the network
        // takes 74, and 14 partition passes (runs of 2^10 to 2^23) writing one split in 256.
        let m = merge_schedule(24, 24, 4);
        assert_eq!(m.iter().filter(|p| p.partition.is_none()).count(), 21);
        assert_eq!(m.len(), 35);
        assert_eq!(schedule(24, 24, 4, false).len(), 74);
    }

    #[test]
    fn fewer_passes_than_steps() {
        // 2^20 entries: 210 network steps; four group bits cut them to about a quarter.
        let steps = network(20).len();
        assert_eq!(steps, 210);
        let p4 = schedule(20, 20, 4, false).len();
        let p3 = schedule(20, 20, 3, false).len();
        assert!(p4 * 3 < steps, "{p4} passes");
        assert!(p3 < steps / 2 && p4 < p3, "{p3} {p4}");
    }
}
