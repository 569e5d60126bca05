//! The passes each sort variant runs, computed without GL: the one place a variant's schedule
//! is written. The sorter builds its passes from [`network`]; the engine's plan, the trace and
//! the cost model read the same list.

use super::blocked::{merge_schedule, schedule as blocked_schedule, BlockPass};
use super::network::{bitonic_schedule, group_steps, odd_even_schedule, Step};
use super::{SortOptions, Variant};

/// One pass of a sort's network, in the order the sorter draws them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum NetworkPass {
    /// One compare-exchange step of a bitonic network (FP, GP/FP, packed) or of Latta's
    /// odd-even merge sort: one full-screen (or quad-geometry) pass.
    Step(Step),
    /// Several bitonic steps in one pass (multistep).
    Group(Vec<Step>),
    /// One pass of the blocked network: the steps it runs in registers over a group of bits.
    Blocked(BlockPass),
    /// The blocked network's last pass: the entries back into the row-major texture.
    Unpack,
}

/// The passes of one full sort by `variant` of a `width`×`height` texture sorted in blocks of
/// `block` entries (the whole texture, or `rows` rows at a time), in order. Sizes are powers of
/// two (the sorter checks them); a texture of one entry needs no pass.
pub fn network(
    variant: Variant,
    width: u32,
    height: u32,
    block: u32,
    options: &SortOptions,
) -> Vec<NetworkPass> {
    match variant {
        Variant::Fp | Variant::GpFp | Variant::Packed => bitonic_schedule(width, block)
            .into_iter()
            .map(NetworkPass::Step)
            .collect(),
        Variant::OddEven => odd_even_schedule(block)
            .into_iter()
            .map(NetworkPass::Step)
            .collect(),
        Variant::Multistep => group_steps(&bitonic_schedule(width, block), options.steps_per_pass)
            .into_iter()
            .map(NetworkPass::Group)
            .collect(),
        Variant::Blocked => {
            let n = (width * height).trailing_zeros();
            if n == 0 {
                return Vec::new();
            }
            let shape = options.blocked_shape(variant, width);
            let bits = shape.bits.min(n).max(1);
            let block_bits = block.trailing_zeros();
            let schedule = if shape.merge && !shape.pinned {
                merge_schedule(n, block_bits, bits)
            } else {
                blocked_schedule(n, block_bits, bits, shape.pinned)
            };
            let mut passes: Vec<NetworkPass> =
                schedule.into_iter().map(NetworkPass::Blocked).collect();
            passes.push(NetworkPass::Unpack);
            passes
        }
    }
}

/// Of `passes` (a [`network`]), those that write every entry: all but the blocked merges'
/// partition passes, which write one split for many entries. What a sort's bytes written scale
/// with.
pub fn entry_pass_count(passes: &[NetworkPass]) -> usize {
    passes
        .iter()
        .filter(|p| !matches!(p, NetworkPass::Blocked(b) if b.partition.is_some()))
        .count()
}

/// The number of passes of [`network`].
pub fn pass_count(
    variant: Variant,
    width: u32,
    height: u32,
    block: u32,
    options: &SortOptions,
) -> usize {
    network(variant, width, height, block, options).len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_variant_sorts_in_the_known_number_of_passes() {
        // 1024² in one block: log2(n) (log2(n) + 1) / 2 = 210 bitonic steps, 20 × 21 / 2.
        let (w, o) = (1024, SortOptions::default());
        let n = w * w;
        assert_eq!(pass_count(Variant::Fp, w, w, n, &o), 210);
        assert_eq!(pass_count(Variant::Packed, w, w, n, &o), 210);
        assert_eq!(pass_count(Variant::OddEven, w, w, n, &o), 210);
        let multi = pass_count(Variant::Multistep, w, w, n, &o);
        assert!(multi < 210 && multi > 60, "{multi}");
        // The blocked network alone runs every step once, in passes of at most `bits` group
        // bits, then the unpack.
        let mut net = o;
        net.blocked.merge = false;
        let blocked = network(Variant::Blocked, w, w, n, &net);
        assert_eq!(blocked.last(), Some(&NetworkPass::Unpack));
        let steps: usize = blocked
            .iter()
            .map(|p| match p {
                NetworkPass::Blocked(b) => b.steps.len(),
                NetworkPass::Step(_) | NetworkPass::Group(_) | NetworkPass::Unpack => 0,
            })
            .sum();
        assert_eq!(steps, 210);
        assert!(blocked.len() < 70, "{}", blocked.len());
        // The default merges: one network pass over runs of 16, 16 merge passes (those of runs
        // of 2^10 and more after a partition pass), the unpack.
        let merged = network(Variant::Blocked, w, w, n, &o);
        assert_eq!(merged.len(), 28);
        let count = |f: fn(&crate::sort::blocked::BlockPass) -> bool| {
            merged
                .iter()
                .filter(|p| matches!(p, NetworkPass::Blocked(b) if f(b)))
                .count()
        };
        assert_eq!(count(|b| b.merge.is_some()), 16);
        assert_eq!(count(|b| b.partition.is_some()), 10);
        assert!(network(Variant::Blocked, 1, 1, 1, &o).is_empty());
    }
}
