//! The CPU allocator of particle texel indices (Latta, "Building a Million Particle System",
//! GDC 2004, §3.4.1).
//!
//! Particle state lives in `width × height` textures, one particle per texel; index `i` is texel
//! `(i % width, i / width)`. The CPU hands out free indices to new particles and takes them back
//! when particles die. Death needs no read-back: the GPU kills a particle by its age and the CPU
//! runs the same clock, so it records each particle's death time at birth and frees the index when
//! that time has passed ([`Allocator::reclaim`]).
//!
//! Two strategies, as in the paper: a stack (LIFO, the cheapest) and a min-heap that always returns
//! the smallest free index, which keeps live particles packed in the first rows so that later GPU
//! passes can be restricted to [`Allocator::live_rows`] rows.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

/// How free indices are handed out: the scene's `allocator` key, one type for the file and the
/// allocator.
pub use crate::scene::AllocatorKind;

/// Why an allocator call was refused. Nothing changes in the allocator when one is returned.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum AllocError {
    /// The index is not below the capacity.
    #[error("particle index {index} is out of range for an allocator of capacity {capacity}")]
    OutOfRange {
        /// The index given.
        index: u32,
        /// The allocator's capacity.
        capacity: u32,
    },
    /// The index is free already (a double free, or never allocated).
    #[error("particle index {index} is not live (allocator capacity {capacity}); double free?")]
    NotLive {
        /// The index given.
        index: u32,
        /// The allocator's capacity.
        capacity: u32,
    },
    /// The lifetime is negative or not finite, or `now + lifetime` is not finite, so the particle
    /// would never be reclaimed or would die before it was born.
    #[error(
        "lifetime {lifetime} at time {now} gives no finite death time \
         (lifetime must be finite and >= 0, and now + lifetime finite)"
    )]
    InvalidLifetime {
        /// The birth time given.
        now: f64,
        /// The lifetime given.
        lifetime: f64,
    },
}

/// One pending death: the index dies at `time` if it still holds the allocation of `generation`.
#[derive(Debug, Clone, Copy)]
struct Death {
    time: f64,
    index: u32,
    generation: u32,
}

// Times are validated finite on insertion; total_cmp makes the order total anyway, so a heap of
// deaths is well defined without a float-ordering crate.
impl Ord for Death {
    fn cmp(&self, other: &Self) -> Ordering {
        self.time
            .total_cmp(&other.time)
            .then(self.index.cmp(&other.index))
            .then(self.generation.cmp(&other.generation))
    }
}

impl PartialOrd for Death {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Death {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Death {}

/// Free indices that have been used before; indices at or above `next_fresh` are implicitly free.
#[derive(Debug, Clone)]
enum FreeList {
    Stack(Vec<u32>),
    MinHeap(BinaryHeap<Reverse<u32>>),
}

/// Hands out texel indices `0..capacity` to particles and takes them back (Latta §3.4.1).
///
/// Indices never handed out are not stored: they are the range `next_fresh..capacity`, taken in
/// ascending order once the free list is empty. That makes `new` O(capacity / 64) for the liveness
/// bits plus the generation table, and keeps both strategies handing out 0, 1, 2, ... on a fresh
/// allocator.
#[derive(Debug, Clone)]
pub struct Allocator {
    kind: AllocatorKind,
    capacity: u32,
    /// Every index below this has been handed out at least once; every index above is free.
    next_fresh: u32,
    /// Indices below `next_fresh` that are free.
    free: FreeList,
    /// One bit per index: live or not. Bits, so `high_water` can skip 64 free indices at a time.
    live: Vec<u64>,
    live_count: u32,
    high_water: u32,
    /// Bumped on every allocation of an index, so that a death recorded for an earlier allocation
    /// (freed by hand since) is recognised as stale and skipped.
    generation: Vec<u32>,
    /// Whether the index's current allocation has a death in `deaths` not yet reclaimed.
    pending: Vec<u64>,
    deaths: BinaryHeap<Reverse<Death>>,
    /// How many records in `deaths` are stale; used to compact the heap when they dominate.
    stale: usize,
}

/// Compact the death heap only past this many stale records, so small heaps are never rebuilt.
const COMPACT_MIN_STALE: usize = 64;

fn bit(bits: &[u64], index: u32) -> bool {
    let i = index as usize;
    bits.get(i / 64).is_some_and(|w| (w >> (i % 64)) & 1 == 1)
}

fn set_bit(bits: &mut [u64], index: u32, value: bool) {
    let i = index as usize;
    if let Some(w) = bits.get_mut(i / 64) {
        let mask = 1u64 << (i % 64);
        if value {
            *w |= mask;
        } else {
            *w &= !mask;
        }
    }
}

impl Allocator {
    /// An allocator of `capacity` indices, all free. Both kinds hand out 0, 1, 2, ... first.
    pub fn new(kind: AllocatorKind, capacity: u32) -> Self {
        let words = (capacity as usize).div_ceil(64);
        let free = match kind {
            AllocatorKind::Stack => FreeList::Stack(Vec::new()),
            AllocatorKind::MinHeap => FreeList::MinHeap(BinaryHeap::new()),
        };
        Allocator {
            kind,
            capacity,
            next_fresh: 0,
            free,
            live: vec![0; words],
            live_count: 0,
            high_water: 0,
            generation: vec![0; capacity as usize],
            pending: vec![0; words],
            deaths: BinaryHeap::new(),
            stale: 0,
        }
    }

    /// A free index, now live, or `None` when every index is live.
    ///
    /// The stack returns the most recently freed index; the min-heap the smallest free one.
    pub fn allocate(&mut self) -> Option<u32> {
        // Every index in the free list is below next_fresh, so for the min-heap its top is the
        // smallest free index whenever the list is not empty.
        let reused = match &mut self.free {
            FreeList::Stack(s) => s.pop(),
            FreeList::MinHeap(h) => h.pop().map(|Reverse(i)| i),
        };
        let index = match reused {
            Some(i) => i,
            None if self.next_fresh < self.capacity => {
                self.next_fresh += 1;
                self.next_fresh - 1
            }
            None => return None,
        };
        set_bit(&mut self.live, index, true);
        if let Some(g) = self.generation.get_mut(index as usize) {
            *g = g.wrapping_add(1);
        }
        self.live_count += 1;
        self.high_water = self.high_water.max(index + 1);
        Some(index)
    }

    /// Allocates an index and records that its particle dies at `now + lifetime`, so that
    /// [`reclaim`](Self::reclaim) frees it without reading anything back from the GPU.
    ///
    /// `Ok(None)` when full. An invalid lifetime is an error and allocates nothing.
    pub fn allocate_with_lifetime(
        &mut self,
        now: f64,
        lifetime: f64,
    ) -> Result<Option<u32>, AllocError> {
        let time = now + lifetime;
        // Written as a positive test so that NaN anywhere fails it.
        let valid = lifetime.is_finite() && lifetime >= 0.0 && time.is_finite();
        if !valid {
            return Err(AllocError::InvalidLifetime { now, lifetime });
        }
        let Some(index) = self.allocate() else {
            return Ok(None);
        };
        let generation = self.generation.get(index as usize).copied().unwrap_or(0);
        self.deaths.push(Reverse(Death {
            time,
            index,
            generation,
        }));
        set_bit(&mut self.pending, index, true);
        Ok(Some(index))
    }

    /// Frees every index whose recorded death time is `<= now` and returns them, earliest death
    /// first (ties by index). Deaths of indices freed by hand since are skipped.
    ///
    /// A NaN `now` reclaims nothing.
    pub fn reclaim(&mut self, now: f64) -> Vec<u32> {
        let mut freed = Vec::new();
        while let Some(Reverse(d)) = self.deaths.peek().copied() {
            // False for a NaN `now` too, which then reclaims nothing.
            let due = d.time <= now;
            if !due {
                break;
            }
            self.deaths.pop();
            if self.is_current(&d) {
                set_bit(&mut self.pending, d.index, false);
                self.release(d.index);
                freed.push(d.index);
            } else {
                self.stale = self.stale.saturating_sub(1);
            }
        }
        freed
    }

    /// Frees a live index by hand (a particle killed early). Any death recorded for it is
    /// forgotten, so [`reclaim`](Self::reclaim) will not free the index again.
    pub fn free(&mut self, index: u32) -> Result<(), AllocError> {
        if index >= self.capacity {
            return Err(AllocError::OutOfRange {
                index,
                capacity: self.capacity,
            });
        }
        if !self.is_live(index) {
            return Err(AllocError::NotLive {
                index,
                capacity: self.capacity,
            });
        }
        if bit(&self.pending, index) {
            // Its death record stays in the heap but no longer matches a live allocation.
            set_bit(&mut self.pending, index, false);
            self.stale += 1;
            self.compact_if_stale();
        }
        self.release(index);
        Ok(())
    }

    /// Whether `index` is allocated (false for indices out of range).
    pub fn is_live(&self, index: u32) -> bool {
        bit(&self.live, index)
    }

    /// How many indices are allocated.
    pub fn live_count(&self) -> u32 {
        self.live_count
    }

    /// How many indices there are in all (`width × height` of the state textures).
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// The strategy this allocator was built with.
    pub fn kind(&self) -> AllocatorKind {
        self.kind
    }

    /// One past the highest live index; 0 when none is live.
    pub fn high_water(&self) -> u32 {
        self.high_water
    }

    /// Rows of a `width`-wide texture that hold every live index: `ceil(high_water / width)`.
    /// A GPU pass restricted to these rows touches every live particle.
    ///
    /// # Panics
    ///
    /// If `width` is 0 (no texture is zero texels wide).
    pub fn live_rows(&self, width: u32) -> u32 {
        assert!(width > 0, "live_rows: texture width must be > 0");
        self.high_water.div_ceil(width)
    }

    /// Whether a death record belongs to the index's current, still live allocation.
    fn is_current(&self, d: &Death) -> bool {
        self.is_live(d.index) && self.generation.get(d.index as usize) == Some(&d.generation)
    }

    /// Marks a live index free and returns it to the free list.
    fn release(&mut self, index: u32) {
        set_bit(&mut self.live, index, false);
        self.live_count -= 1;
        match &mut self.free {
            FreeList::Stack(s) => s.push(index),
            FreeList::MinHeap(h) => h.push(Reverse(index)),
        }
        if index + 1 == self.high_water {
            self.lower_high_water();
        }
    }

    /// Scans down from the old high water mark to the next live index, a 64-bit word at a time.
    /// With the min-heap the mark grows by at most one per allocation, so the scan is amortised
    /// O(1); with the stack a single free can cost up to capacity / 64 word reads.
    fn lower_high_water(&mut self) {
        let mut hw = self.high_water as usize;
        while hw > 0 {
            let word_index = (hw - 1) / 64;
            let Some(&word) = self.live.get(word_index) else {
                break;
            };
            // Keep only bits below hw within this word.
            let bits_in_word = hw - word_index * 64;
            let mask = if bits_in_word >= 64 {
                u64::MAX
            } else {
                (1u64 << bits_in_word) - 1
            };
            let w = word & mask;
            if w != 0 {
                hw = word_index * 64 + (64 - w.leading_zeros() as usize);
                break;
            }
            hw = word_index * 64;
        }
        // hw never exceeds the old u32 value, so the cast is lossless.
        self.high_water = hw as u32;
    }

    /// Drops stale death records once they are most of the heap, so that particles freed by hand
    /// with long lifetimes do not grow it without bound.
    fn compact_if_stale(&mut self) {
        if self.stale < COMPACT_MIN_STALE || self.stale * 2 < self.deaths.len() {
            return;
        }
        let deaths = std::mem::take(&mut self.deaths);
        let mut kept = deaths.into_vec();
        kept.retain(|Reverse(d)| self.is_current(d));
        self.deaths = BinaryHeap::from(kept);
        self.stale = 0;
    }
}

#[cfg(test)]
mod tests;
