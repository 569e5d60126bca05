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

/// How free indices are handed out.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum AllocatorKind {
    /// LIFO: the most recently freed index comes back first. O(1) per operation.
    Stack,
    /// Always the smallest free index, so live particles stay in the first rows. O(log n).
    MinHeap,
}

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
mod tests {
    use super::*;
    use std::collections::{BTreeSet, HashMap, HashSet};

    /// Numerical Recipes' 64-bit LCG; the high bits are the good ones.
    fn lcg(state: &mut u64) -> u32 {
        *state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*state >> 33) as u32
    }

    fn below(state: &mut u64, n: u32) -> u32 {
        lcg(state) % n
    }

    const KINDS: [AllocatorKind; 2] = [AllocatorKind::Stack, AllocatorKind::MinHeap];

    #[test]
    fn min_heap_returns_smallest_free_index_against_btreeset_model() {
        let capacity = 300;
        let mut a = Allocator::new(AllocatorKind::MinHeap, capacity);
        let mut model_free: BTreeSet<u32> = (0..capacity).collect();
        let mut live: Vec<u32> = Vec::new();
        let mut rng = 0x1234_5678u64;
        let mut fulls = 0;
        for n in 0..50_000 {
            // Phases biased towards allocation, then towards freeing, so the allocator goes
            // through full, nearly empty and everything in between.
            let alloc_bias = if (n / 2000) % 2 == 0 { 65 } else { 35 };
            if below(&mut rng, 100) < alloc_bias || live.is_empty() {
                let got = a.allocate();
                let want = model_free.pop_first();
                assert_eq!(got, want);
                match got {
                    Some(i) => live.push(i),
                    None => fulls += 1,
                }
            } else {
                let k = below(&mut rng, live.len() as u32) as usize;
                let i = live.swap_remove(k);
                assert_eq!(a.free(i), Ok(()));
                assert!(model_free.insert(i));
            }
            assert_eq!(a.live_count() as usize, live.len());
            let want_hw = live.iter().max().map_or(0, |m| m + 1);
            assert_eq!(a.high_water(), want_hw);
        }
        assert!(fulls > 0, "the sequence never filled the allocator");
    }

    #[test]
    fn no_index_handed_out_twice_while_live_for_both_kinds() {
        for kind in KINDS {
            let capacity = 257;
            let mut a = Allocator::new(kind, capacity);
            // Model: live index -> death time (None for plain allocations).
            let mut model: HashMap<u32, Option<f64>> = HashMap::new();
            let mut rng = 0xdead_beefu64 ^ kind as u64;
            let mut now = 0.0f64;
            let mut fulls = 0;
            for step in 0..20_000 {
                match below(&mut rng, 10) {
                    0..=3 => {
                        let lifetime = f64::from(below(&mut rng, 40));
                        match a.allocate_with_lifetime(now, lifetime) {
                            Ok(Some(i)) => {
                                assert!(i < capacity);
                                assert!(
                                    model.insert(i, Some(now + lifetime)).is_none(),
                                    "{kind:?} handed out live index {i} at step {step}"
                                );
                            }
                            Ok(None) => {
                                assert_eq!(model.len(), capacity as usize);
                                fulls += 1;
                            }
                            Err(e) => panic!("valid lifetime refused: {e}"),
                        }
                    }
                    4..=5 => match a.allocate() {
                        Some(i) => {
                            assert!(i < capacity);
                            assert!(
                                model.insert(i, None).is_none(),
                                "{kind:?} handed out live index {i} at step {step}"
                            );
                        }
                        None => {
                            assert_eq!(model.len(), capacity as usize);
                            fulls += 1;
                        }
                    },
                    6..=7 if !model.is_empty() => {
                        let mut keys: Vec<u32> = model.keys().copied().collect();
                        keys.sort_unstable();
                        let i = keys[below(&mut rng, keys.len() as u32) as usize];
                        assert_eq!(a.free(i), Ok(()));
                        model.remove(&i);
                    }
                    _ => {
                        now += 1.0;
                        let mut want: Vec<u32> = model
                            .iter()
                            .filter(|(_, d)| d.is_some_and(|t| t <= now))
                            .map(|(i, _)| *i)
                            .collect();
                        want.sort_unstable();
                        let mut got = a.reclaim(now);
                        got.sort_unstable();
                        assert_eq!(got, want, "{kind:?} reclaim at t={now}");
                        for i in &want {
                            model.remove(i);
                        }
                    }
                }
                assert_eq!(a.live_count() as usize, model.len());
                for i in 0..capacity {
                    assert_eq!(a.is_live(i), model.contains_key(&i));
                }
            }
            assert!(
                fulls > 0,
                "{kind:?}: the sequence never filled the allocator"
            );
        }
    }

    #[test]
    fn full_allocators_return_none() {
        for kind in KINDS {
            let mut a = Allocator::new(kind, 100);
            let got: HashSet<u32> = (0..100).filter_map(|_| a.allocate()).collect();
            assert_eq!(got, (0..100).collect());
            assert_eq!(a.allocate(), None);
            assert_eq!(a.allocate_with_lifetime(0.0, 1.0), Ok(None));
            assert_eq!(a.live_count(), 100);
            assert!(a.deaths.is_empty(), "a refused allocation recorded a death");
            assert_eq!(a.free(42), Ok(()));
            assert_eq!(a.allocate(), Some(42));

            let mut empty = Allocator::new(kind, 0);
            assert_eq!(empty.allocate(), None);
            assert_eq!(empty.high_water(), 0);
            assert_eq!(empty.live_rows(16), 0);
        }
    }

    #[test]
    fn steady_emission_keeps_min_heap_packed_in_first_rows() {
        let width = 64;
        let capacity = width * 64;
        // Integer times keep the death comparisons exact; 37 per step does not divide the width,
        // so the last row is partial.
        let per_step = 37;
        let lifetime = 40.0;
        let mut a = Allocator::new(AllocatorKind::MinHeap, capacity);
        for step in 0..500u32 {
            let now = f64::from(step);
            let died = a.reclaim(now);
            if step >= 40 {
                assert_eq!(died.len() as u32, per_step, "step {step}");
            }
            for _ in 0..per_step {
                let got = a.allocate_with_lifetime(now, lifetime);
                assert!(matches!(got, Ok(Some(_))), "step {step}: {got:?}");
            }
            let live = a.live_count();
            assert_eq!(live, per_step * (step + 1).min(40));
            // Every live index is below live_count: no holes at all.
            assert_eq!(a.high_water(), live, "step {step}");
            assert!((0..live).all(|i| a.is_live(i)));
            assert!((live..capacity).all(|i| !a.is_live(i)));
            assert_eq!(a.live_rows(width), live.div_ceil(width), "step {step}");
        }
        assert_eq!(a.live_rows(width), (37 * 40u32).div_ceil(64));
    }

    #[test]
    fn stack_is_lifo() {
        let mut a = Allocator::new(AllocatorKind::Stack, 10);
        assert_eq!(a.kind(), AllocatorKind::Stack);
        assert_eq!(a.capacity(), 10);
        let first: Vec<u32> = (0..5).filter_map(|_| a.allocate()).collect();
        assert_eq!(first, vec![0, 1, 2, 3, 4]);
        a.free(1).unwrap();
        a.free(3).unwrap();
        a.free(0).unwrap();
        // Last in, first out; then the never-used indices in order.
        assert_eq!(a.allocate(), Some(0));
        assert_eq!(a.allocate(), Some(3));
        assert_eq!(a.allocate(), Some(1));
        assert_eq!(a.allocate(), Some(5));

        // The min-heap, given the same frees, returns the smallest instead.
        let mut h = Allocator::new(AllocatorKind::MinHeap, 10);
        (0..5).for_each(|_| {
            h.allocate();
        });
        h.free(1).unwrap();
        h.free(3).unwrap();
        h.free(0).unwrap();
        assert_eq!(h.allocate(), Some(0));
        assert_eq!(h.allocate(), Some(1));
        assert_eq!(h.allocate(), Some(3));
        assert_eq!(h.allocate(), Some(5));
    }

    #[test]
    fn double_free_and_out_of_range_free_are_errors() {
        for kind in KINDS {
            let mut a = Allocator::new(kind, 8);
            let i = a.allocate().unwrap();
            assert_eq!(a.free(i), Ok(()));
            let e = a.free(i).unwrap_err();
            assert_eq!(
                e,
                AllocError::NotLive {
                    index: i,
                    capacity: 8
                }
            );
            let msg = e.to_string();
            assert!(msg.contains(&i.to_string()) && msg.contains('8'), "{msg}");
            // Never allocated.
            assert_eq!(
                a.free(5),
                Err(AllocError::NotLive {
                    index: 5,
                    capacity: 8
                })
            );
            let e = a.free(8).unwrap_err();
            assert_eq!(
                e,
                AllocError::OutOfRange {
                    index: 8,
                    capacity: 8
                }
            );
            let msg = e.to_string();
            assert!(
                msg.contains("index 8") && msg.contains("capacity 8"),
                "{msg}"
            );
            assert!(a.free(u32::MAX).is_err());
            // A refused free changes nothing.
            assert_eq!(a.live_count(), 0);
            assert_eq!(a.allocate(), Some(i));
        }
    }

    #[test]
    fn invalid_lifetimes_are_errors_and_allocate_nothing() {
        let mut a = Allocator::new(AllocatorKind::MinHeap, 4);
        for (now, lifetime) in [
            (0.0, -1.0),
            (0.0, f64::NAN),
            (0.0, f64::INFINITY),
            (f64::NAN, 1.0),
            (f64::INFINITY, 1.0),
            (f64::MAX, f64::MAX),
        ] {
            let got = a.allocate_with_lifetime(now, lifetime);
            assert!(
                matches!(got, Err(AllocError::InvalidLifetime { .. })),
                "({now}, {lifetime}) gave {got:?}"
            );
        }
        assert_eq!(a.live_count(), 0);
        assert_eq!(a.high_water(), 0);
        // A zero lifetime is valid: the particle dies at the next reclaim of the same time.
        assert_eq!(a.allocate_with_lifetime(3.0, 0.0), Ok(Some(0)));
        assert_eq!(a.reclaim(2.5), Vec::<u32>::new());
        assert_eq!(a.reclaim(f64::NAN), Vec::<u32>::new());
        assert_eq!(a.reclaim(3.0), vec![0]);
    }

    #[test]
    fn reclaim_skips_indices_freed_by_hand() {
        for kind in KINDS {
            let mut a = Allocator::new(kind, 4);
            let x = a.allocate_with_lifetime(0.0, 5.0).unwrap().unwrap();
            let y = a.allocate_with_lifetime(0.0, 5.0).unwrap().unwrap();
            a.free(x).unwrap();
            // Freed, not reused: its death must not be reported.
            assert_eq!(a.reclaim(6.0), vec![y]);
            assert_eq!(a.live_count(), 0);

            // Freed and reused by a plain allocation: the old death must not free the new owner.
            let x = a.allocate_with_lifetime(10.0, 5.0).unwrap().unwrap();
            a.free(x).unwrap();
            let again = a.allocate().unwrap();
            assert_eq!(again, x);
            assert_eq!(a.reclaim(100.0), Vec::<u32>::new());
            assert!(a.is_live(x));
            a.free(x).unwrap();

            // Freed and reused with a longer life: only the new death counts.
            let x = a.allocate_with_lifetime(200.0, 1.0).unwrap().unwrap();
            a.free(x).unwrap();
            assert_eq!(a.allocate_with_lifetime(200.0, 50.0), Ok(Some(x)));
            assert_eq!(a.reclaim(210.0), Vec::<u32>::new());
            assert!(a.is_live(x));
            assert_eq!(a.reclaim(250.0), vec![x]);
            assert!(!a.is_live(x));
            // And it is not reported twice.
            assert_eq!(a.reclaim(1e9), Vec::<u32>::new());
        }
    }

    #[test]
    fn stale_deaths_do_not_pile_up() {
        let mut a = Allocator::new(AllocatorKind::Stack, 16);
        for _ in 0..10_000 {
            let i = a.allocate_with_lifetime(0.0, 1e6).unwrap().unwrap();
            a.free(i).unwrap();
        }
        assert!(
            a.deaths.len() <= 2 * COMPACT_MIN_STALE,
            "{} death records kept for 0 live particles",
            a.deaths.len()
        );
        assert_eq!(a.reclaim(1e7), Vec::<u32>::new());
        assert_eq!(a.stale, 0);
    }

    #[test]
    fn high_water_and_live_rows_after_frees_at_the_top() {
        for kind in KINDS {
            let mut a = Allocator::new(kind, 20);
            assert_eq!((a.high_water(), a.live_rows(4)), (0, 0));
            for _ in 0..10 {
                a.allocate();
            }
            assert_eq!((a.high_water(), a.live_rows(4)), (10, 3));
            a.free(9).unwrap();
            assert_eq!((a.high_water(), a.live_rows(4)), (9, 3));
            a.free(7).unwrap(); // Below the top: no change.
            assert_eq!(a.high_water(), 9);
            a.free(8).unwrap(); // Top freed: scans past the hole at 7.
            assert_eq!((a.high_water(), a.live_rows(4)), (7, 2));
            assert_eq!(a.live_rows(7), 1);
            assert_eq!(a.live_rows(1), 7);
            for i in 0..7 {
                a.free(i).unwrap();
            }
            assert_eq!((a.high_water(), a.live_rows(4)), (0, 0));
        }

        // Across 64-bit words: live {0, 130}, freeing 130 must fall all the way to 1.
        let mut a = Allocator::new(AllocatorKind::Stack, 200);
        for _ in 0..200 {
            a.allocate();
        }
        assert_eq!(a.high_water(), 200);
        for i in (1..200).filter(|&i| i != 130) {
            a.free(i).unwrap();
        }
        assert_eq!(a.high_water(), 131);
        assert_eq!(a.live_rows(64), 3);
        a.free(130).unwrap();
        assert_eq!((a.high_water(), a.live_rows(64)), (1, 1));
        a.free(0).unwrap();
        assert_eq!(a.high_water(), 0);
        // The stack then hands back 0 (freed last), and the mark rises with whatever comes back.
        assert_eq!(a.allocate(), Some(0));
        assert_eq!(a.allocate(), Some(130));
        assert_eq!(a.high_water(), 131);
    }

    #[test]
    #[should_panic(expected = "width must be > 0")]
    fn live_rows_of_zero_width_panics() {
        Allocator::new(AllocatorKind::MinHeap, 4).live_rows(0);
    }

    #[test]
    fn kind_serializes_lowercase() {
        assert_eq!(
            serde_json::to_string(&AllocatorKind::MinHeap).unwrap(),
            "\"minheap\""
        );
        assert_eq!(
            serde_json::to_string(&AllocatorKind::Stack).unwrap(),
            "\"stack\""
        );
    }
}
