//! The coherent re-sort (`fluid.resort = "coherent"`): Latta §3.4.4's frame coherence for the
//! fluid's cell sort. The fluid writes its state in cell order every step, so at the next step
//! the entries (cell, index) are sorted but for the particles that crossed a cell face. A
//! cheaper network sorts such a state: the aligned blocks of `m` entries sorted (our blocked
//! sort, `rows` rows at a time), then the blocks of `m` at offset `m / 2` merged (their two
//! sorted halves, in one pass: `glsl/fluid/merge.frag`).
//!
//! Why it is exact when no entry lies more than D = m / 2 from its sorted place: by the 0-1
//! principle it is enough that it sorts every threshold image of such an input. With z zeros,
//! the image is 0 below z − D and 1 from z + D on: its disorder lies in a window of 2D = m. A
//! window inside an aligned block is sorted by the first stage. Else it straddles one block
//! boundary c; after the first stage the block left of c ends in its ones, o of them, and the
//! block right of c starts with its zeros, q of them. Counting zeros, q = o + z − c, and o ≤
//! c − (z − D), q ≤ z + D − c, so o ≤ D and q ≤ D: the out-of-order ones and zeros lie in
//! [c − D, c + D), the offset block the merge sorts.
//!
//! A particle that crosses a face in y or z jumps a row or a slab of cells in the order, often
//! more than D: the check pass (`glsl/fluid/order.frag`) flags every entry greater than its
//! successor, a tally counts them, and the step falls back to the full sort when any is found,
//! so no neighbour is ever lost.

use crate::error::Result;
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, PingPong, Program, Texture, TextureDesc,
    TextureFormat, Uniform, FULLSCREEN_VERTEX,
};
use crate::scene;
use crate::sim::collide::tally::TruncationTally;
use crate::sort::blocked::{apply, merge_runs, network};
use crate::sort::{
    entry_less, entry_pass_count, passes_of, Entry, KeyMode, SortOptions, Sorter, Variant,
};

/// The block of the coherent re-sort of a `size` state, if `f` asks for it: `resort_block`,
/// default two rows (at most half the entries).
pub fn coherent_block(f: &scene::Fluid, size: [u32; 2]) -> Option<u32> {
    (f.resort == scene::Resort::Coherent).then(|| {
        f.resort_block
            .unwrap_or((2 * size[0]).min(size[0] * size[1] / 2).max(2))
    })
}

/// The CPU twin of the coherent network on `entries` in logical order: blocks of `m` sorted,
/// then the blocks at offset `m / 2` merged.
pub fn coherent_network(entries: &mut [Entry], m: usize) {
    apply(entries, &network(m.trailing_zeros()));
    let (n, off) = (entries.len(), m / 2);
    if n > m {
        merge_runs(&mut entries[off..n - off], (m / 2).trailing_zeros());
    }
}

/// Entries greater than their successor: what the check pass counts.
pub fn out_of_order(entries: &[Entry]) -> usize {
    entries
        .windows(2)
        .filter(|w| entry_less(w[1], w[0]))
        .count()
}

/// Passes that write every entry of one full sort of a `width`×`height` state, and of one
/// coherent re-sort in blocks of `m` (its blocked sort, the merge pass and the check; the key
/// pass not counted in either, nor the merges' small partition passes). A fallback runs both,
/// and a second key pass.
pub fn resort_passes(width: u32, height: u32, m: u32) -> (usize, usize) {
    let o = SortOptions::default();
    let passes = |block| entry_pass_count(&passes_of(Variant::Blocked, width, height, block, &o));
    let (full, blocks) = (passes(width * height), passes(m));
    (full, blocks + 2)
}

/// How the coherent re-sort went over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct ResortCounts {
    /// Steps whose cheap network sorted the state (the check found nothing).
    pub coherent: u64,
    /// Steps that fell back to the full sort.
    pub fallbacks: u64,
    /// Entries out of order after the cheap network, summed over the steps.
    pub out_of_order: u64,
}

/// The GPU side: the block sorter, the merge and check passes, the tally of the check.
#[derive(Debug)]
pub(super) struct CoherentSort {
    sorter: Sorter,
    merge: PingPong,
    order: Framebuffer,
    merge_pass: Program,
    order_pass: Program,
    pass: FullscreenPass,
    tally: TruncationTally,
    block: u32,
    width: u32,
    seen: u64,
    counts: ResortCounts,
}

impl CoherentSort {
    /// The coherent re-sort of a `size` state in blocks of `block` entries (validated: a power
    /// of two of whole rows, at most half the entries).
    pub(super) fn new(ctx: &Context, size: [u32; 2], block: u32) -> Result<Self> {
        let [w, h] = size;
        let options = SortOptions {
            rows: Some((block / w).max(1)),
            ..SortOptions::default()
        };
        let order = Texture::new(
            ctx,
            TextureDesc {
                width: w,
                height: h,
                format: TextureFormat::R32F,
                label: "fluid order check",
            },
        )?;
        let d = Defines::new();
        Ok(CoherentSort {
            sorter: Sorter::new(ctx, Variant::Blocked, w, h, options)?,
            merge: PingPong::new(ctx, "fluid merge", &["keys"], &[TextureFormat::Rg32F], w, h)?,
            order: Framebuffer::new(ctx, "fluid order check", vec![order])?,
            merge_pass: Program::new(ctx, FULLSCREEN_VERTEX, "fluid/merge.frag", &d)?,
            order_pass: Program::new(ctx, FULLSCREEN_VERTEX, "fluid/order.frag", &d)?,
            pass: FullscreenPass::new(ctx)?,
            tally: TruncationTally::new(ctx, [w, h])?,
            block,
            width: w,
            seen: 0,
            counts: ResortCounts::default(),
        })
    }

    /// Sorts the keys of `positions` with the cheap network and checks the order (one
    /// read-back of one texel); whether the entries in [`keys`](Self::keys) are sorted.
    pub(super) fn try_sort(
        &mut self,
        positions: &Texture,
        count: usize,
        mode: &KeyMode,
    ) -> Result<bool> {
        self.sorter.write_keys(positions, count, mode, true)?;
        self.sorter.sort();
        let n = self.sorter.len() as i32;
        let half = (self.block / 2) as i32;
        let merge = [
            ("u_log_w", Uniform::I32(self.width.trailing_zeros() as i32)),
            ("u_offset", Uniform::I32(half)),
            ("u_end", Uniform::I32(n - half)),
            ("u_block", Uniform::I32(self.block as i32)),
        ];
        let source = [("u_keys", self.sorter.keys().into())];
        (self.pass).draw(&self.merge_pass, &source, &merge, self.merge.back());
        self.merge.swap();
        let width = ("u_width", Uniform::I32(self.width as i32));
        let keys = [("u_keys", self.keys().into())];
        let uniforms = [width, ("u_count", Uniform::I32(n))];
        (self.pass).draw(&self.order_pass, &keys, &uniforms, &self.order);
        self.tally
            .add_flags(self.order.only_texture(), 0, n as usize);
        let total = self.tally.total()?;
        let found = total - self.seen;
        self.seen = total;
        self.counts.out_of_order += found;
        if found == 0 {
            self.counts.coherent += 1;
        } else {
            self.counts.fallbacks += 1;
        }
        Ok(found == 0)
    }

    /// The entries after the cheap network and the merge.
    pub(super) fn keys(&self) -> &Texture {
        self.merge.front().only_texture()
    }

    /// The counts so far.
    pub(super) fn counts(&self) -> ResortCounts {
        self.counts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` entries, each at most `d − 1` from its sorted place: index plus a random shift below
    /// `d`, ordered by that (a later entry passes an earlier one only within `d`).
    fn displaced(n: usize, d: usize, seed: u64) -> Vec<Entry> {
        let mut s = seed;
        let mut shifted: Vec<(usize, usize)> = (0..n)
            .map(|i| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (i + (s >> 33) as usize % d, i)
            })
            .collect();
        shifted.sort();
        // Ids the texel index (ties among keys: the GPU tests run real cells).
        (shifted.iter().enumerate())
            .map(|(t, &(_, i))| [i as f32, t as f32])
            .collect()
    }

    fn sorted(e: &[Entry]) -> Vec<Entry> {
        let mut want = e.to_vec();
        want.sort_by(|a, b| {
            if entry_less(*a, *b) {
                std::cmp::Ordering::Less
            } else {
                std::cmp::Ordering::Greater
            }
        });
        want
    }

    #[test]
    fn the_network_sorts_every_entry_within_half_a_block() {
        for (n, m) in [(64, 4), (256, 16), (1024, 64), (1024, 512), (4096, 128)] {
            for seed in 0..20 {
                let e = displaced(n, m / 2 + 1, seed * 7 + m as u64);
                let want = sorted(&e);
                let mut got = e.clone();
                coherent_network(&mut got, m);
                assert_eq!(got, want, "n {n}, block {m}, seed {seed}");
                assert_eq!(out_of_order(&got), 0);
            }
        }
    }

    #[test]
    fn a_jump_past_half_a_block_is_left_out_of_order_and_counted() {
        // The last entry belongs first: after the blocks it is first in the last block, and
        // the merge moves it back at most half a block.
        let (n, m) = (1024usize, 64usize);
        let mut e: Vec<Entry> = (0..n).map(|i| [(i + 1) as f32, i as f32]).collect();
        e[n - 1][0] = 0.0;
        let mut got = e.clone();
        coherent_network(&mut got, m);
        assert_ne!(got, sorted(&e));
        assert!(out_of_order(&got) >= 1);
        // A jump of exactly half a block is still sorted.
        let mut e: Vec<Entry> = (0..n).map(|i| [i as f32, i as f32]).collect();
        e[..=m / 2].rotate_right(1);
        let mut got = e.clone();
        coherent_network(&mut got, m);
        assert_eq!(got, sorted(&e));
    }

    #[test]
    fn the_coherent_pass_count_comes_from_the_schedules() {
        // 64×64 (4096 entries): the full blocked sort, and blocks of two rows (128 entries:
        // the merge pass and the check).
        let (full, coherent) = resort_passes(64, 64, 128);
        let o = SortOptions::default();
        let passes = |block| entry_pass_count(&passes_of(Variant::Blocked, 64, 64, block, &o));
        assert_eq!(full, passes(4096));
        let blocks = passes(128);
        assert_eq!(coherent, blocks + 2);
        assert!(coherent < full, "{coherent} against {full}");
        // Blocks of half the state cost more than the full sort: no saving there.
        let (full, coherent) = resort_passes(64, 64, 2048);
        assert!(coherent > full);
    }
}
