//! How a sort spread over frames orders its passes (Latta §3.4.4; §4 leaves weighting the spread
//! by visual importance to future work).
//!
//! `even` runs the network's passes in order, `passes_per_frame` a frame, and starts again after
//! the last. `local` weights the spread towards what a moving camera disturbs most: between two
//! depths that nearly agree, i.e. between neighbours in the order reached so far. Before each
//! merge stage after the first [`LOCAL_STAGES`], it runs the network's first [`LOCAL_STAGES`]
//! stages again, which sort every aligned run of 2^[`LOCAL_STAGES`] neighbours. After a merge
//! stage those runs are sorted already (runs of 2^stage are), so with keys that hold still the
//! extra passes change nothing and a whole cycle still ends sorted; with keys refreshed from a
//! moving camera they repair the runs several times a cycle instead of once. Odd-even merge sort
//! only: its runs all ascend after each stage (the bitonic stages alternate directions).

use super::network::Step;

/// Merge stages re-run inside the `local` cycle: runs of 8 neighbours, 6 passes.
pub const LOCAL_STAGES: usize = 3;

// The spread is named by the scene file format (`render.sort.spread`); its cycle is the sort's.
pub use crate::scene::Spread;

/// Whether `step` ends a merge stage of the odd-even merge sort (its stride-1 pass).
fn ends_stage(step: &Step) -> bool {
    matches!(
        step,
        Step::OddEvenRecursion { step: 1, .. } | Step::OddEvenEnd { step: 1 }
    )
}

/// The pass indices of one cycle of `spread` over the odd-even merge sort's `steps`; `None`
/// when the steps are not that network's (the `local` spread needs it).
pub fn cycle(steps: &[Step], spread: Spread) -> Option<Vec<usize>> {
    let all = (0..steps.len()).collect();
    if spread == Spread::Even {
        return Some(all);
    }
    let odd_even = steps
        .iter()
        .all(|s| matches!(s, Step::OddEvenRecursion { .. } | Step::OddEvenEnd { .. }));
    if !odd_even {
        return None;
    }
    let ends: Vec<usize> = (0..steps.len())
        .filter(|&i| ends_stage(&steps[i]))
        .collect();
    let Some(&prefix_end) = ends.get(LOCAL_STAGES - 1) else {
        return Some(all);
    };
    let prefix: Vec<usize> = (0..=prefix_end).collect();
    let mut out = Vec::new();
    for (i, _) in steps.iter().enumerate() {
        out.push(i);
        // After a stage past the local ones, and not after the last: the runs again.
        if i > prefix_end && i + 1 < steps.len() && ends_stage(&steps[i]) {
            out.extend(&prefix);
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sort::network::{apply_step, blocks_sorted, odd_even_schedule, Entry};

    fn random(n: usize, seed: u64) -> Vec<Entry> {
        let mut g = seed;
        (0..n)
            .map(|i| {
                g = g
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                [(g >> 40) as f32 / 1024.0, i as f32]
            })
            .collect()
    }

    /// A whole `local` cycle sorts any keys that hold still (against the CPU's sort), and its
    /// prefix sorts every run of 2^LOCAL_STAGES.
    #[test]
    fn local_cycle_ends_sorted_and_its_prefix_sorts_the_runs() {
        for n in [64usize, 256, 1024] {
            let steps = odd_even_schedule(n as u32);
            let seq = cycle(&steps, Spread::Local).unwrap();
            assert!(seq.len() > steps.len(), "{n}: no pass re-run");
            let mut data = random(n, n as u64);
            let mut expected = data.clone();
            expected.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
            let prefix = LOCAL_STAGES * (LOCAL_STAGES + 1) / 2;
            for (k, &i) in seq.iter().enumerate() {
                apply_step(&mut data, &steps[i], n as u32);
                if k + 1 == prefix {
                    assert!(
                        blocks_sorted(&data, 1 << LOCAL_STAGES),
                        "{n}: runs unsorted"
                    );
                }
            }
            assert_eq!(data, expected, "{n}: the local cycle did not sort");
        }
        assert!(cycle(
            &crate::sort::network::bitonic_schedule(8, 64),
            Spread::Local
        )
        .is_none());
    }
}
