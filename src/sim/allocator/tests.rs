//! Unit tests of the allocator.

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
fn kind_serializes_as_the_scene_file_writes_it() {
    assert_eq!(
        serde_json::to_string(&AllocatorKind::MinHeap).unwrap(),
        "\"min_heap\""
    );
    assert_eq!(
        serde_json::to_string(&AllocatorKind::Stack).unwrap(),
        "\"stack\""
    );
}
