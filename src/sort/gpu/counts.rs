//! What one full sort draws, counted from its passes: network, partition and unpack passes (for
//! the benchmarks' floors) and texel fetches (for the cost model).

use super::{group_shape, Pass, Sorter};
use crate::gl::Framebuffer;

impl Sorter {
    /// The passes of one full sort that are network passes (all but the blocked variant's
    /// unpack and partition passes), each writing every entry.
    pub fn network_pass_count(&self) -> usize {
        self.passes.len() - self.partition_pass_count() - self.unpack_pass_count()
    }

    /// The blocked variant's partition passes of one full sort (each writing one split for
    /// every 2^[`crate::sort::blocked::partition_bits`] entries into
    /// [`Sorter::partition_target`]).
    pub fn partition_pass_count(&self) -> usize {
        let b = self.blocked.as_ref();
        self.passes
            .iter()
            .filter(
                |p| matches!(p, Pass::Blocked(i) if b.and_then(|b| b.partition_run(*i)).is_some()),
            )
            .count()
    }

    fn unpack_pass_count(&self) -> usize {
        self.passes
            .iter()
            .filter(|p| matches!(p, Pass::Unpack))
            .count()
    }

    /// The framebuffer the partition passes write (for floors in benchmarks), where there are
    /// any.
    pub fn partition_target(&self) -> Option<&Framebuffer> {
        self.blocked.as_ref().and_then(|b| b.partition_target())
    }

    /// Texel fetches of one run of the network (every pass once), counted from what each pass's
    /// fragment program fetches: for the cost model (`texflow report cost`).
    pub fn network_fetches(&self) -> u64 {
        (0..self.passes.len()).map(|i| self.pass_fetches(i)).sum()
    }

    /// Texel fetches of pass `index` (what [`Sorter::run_pass`] declares as it runs it).
    pub(super) fn pass_fetches(&self, index: usize) -> u64 {
        let n = self.len() as u64;
        match &self.passes[index] {
            Pass::Fragment(_) => 2 * n,
            Pass::Group(steps) => (n / 2) << group_shape(steps).0,
            Pass::Geometry { .. } if self.variant.packed() => n,
            Pass::Geometry { .. } => 2 * n,
            Pass::Blocked(i) => {
                let b = self
                    .blocked
                    .as_ref()
                    .expect("blocked passes have a network");
                let fragments = n >> self.blocked_shape().bits;
                match (b.merge_run(*i), b.partition_run(*i)) {
                    // Each entry it writes, fetched once, and the first of the other
                    // run; before them a binary search fetching two entries a step,
                    // between two splits (two fetches more) or over the whole run.
                    (Some(_), _) if b.partitioned(*i) => {
                        let steps = b.partition_bits() as u64;
                        n + fragments + (2 * steps + 2) * fragments
                    }
                    (Some(r), _) => n + fragments + 2 * r as u64 * fragments,
                    // A full search of `r` steps for every split.
                    (None, Some(r)) => 2 * r as u64 * (n >> b.partition_bits()),
                    (None, None) if self.blocked_shape().pinned => n / 2,
                    (None, None) => n,
                }
            }
            Pass::Unpack => n,
        }
    }
}
