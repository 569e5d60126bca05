//! Every sort the benchmark times is checked against the CPU's order of the same entries: a
//! time of a sort that does not sort is refused, not printed.

use rayon::slice::ParallelSliceMut;

use crate::error::{Error, Result};
use crate::sort::network::{entry_order as order, Entry};
use crate::sort::Quantiser;

/// Checks `got`, what the sort called `name` left after sorting `keys` (row-major, one block),
/// against the CPU: exact entries bit for bit in the (key, id) order; compact ones (`quantiser`)
/// by identifier in the order of (quantisation level, identifier). An error names how many
/// places differ and the first.
pub(super) fn check_sorted(
    name: &str,
    n: u32,
    keys: &[Entry],
    got: &[Entry],
    quantiser: Option<Quantiser>,
) -> Result<()> {
    let (bad, first) = match quantiser {
        None => {
            let mut want = keys.to_vec();
            want.par_sort_unstable_by(order);
            let same = |(g, w): (&Entry, &Entry)| {
                g[0].to_bits() == w[0].to_bits() && g[1].to_bits() == w[1].to_bits()
            };
            differences(got.iter().zip(&want).map(same), got.len(), want.len())
        }
        Some(q) => {
            let mut want: Vec<(u32, u32)> =
                keys.iter().map(|e| (q.level(e[0]), e[1] as u32)).collect();
            want.par_sort_unstable();
            let same = |(g, w): (&Entry, &(u32, u32))| g[1] as u32 == w.1;
            differences(got.iter().zip(&want).map(same), got.len(), want.len())
        }
    };
    match first {
        None => Ok(()),
        Some(i) => Err(Error::Mismatch(format!(
            "the {name} sort at {n}² did not sort: {bad} of {} entries differ from the CPU's \
             order of the same keys, the first at index {i}; no time is reported for it (a \
             driver or shader fault: run `cargo test --test sort` on this device)",
            keys.len()
        ))),
    }
}

/// How many places differ (a length difference counts as a difference at the shorter end),
/// and the first.
fn differences(
    same: impl Iterator<Item = bool>,
    got: usize,
    want: usize,
) -> (usize, Option<usize>) {
    let mut bad = got.abs_diff(want);
    let mut first = (bad > 0).then_some(got.min(want));
    for (i, s) in same.enumerate() {
        if !s {
            bad += 1;
            first = Some(first.map_or(i, |f| f.min(i)));
        }
    }
    (bad, first)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys() -> Vec<Entry> {
        let mut s = 7u64;
        (0..4096)
            .map(|i| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let key = match s >> 60 {
                    0 => f32::NAN,
                    1 => f32::INFINITY,
                    _ => ((s >> 40) % 500) as f32 - 250.0,
                };
                [key, i as f32]
            })
            .collect()
    }

    #[test]
    fn a_sorted_copy_passes_and_any_swap_or_loss_is_refused() {
        let k = keys();
        let mut sorted = k.clone();
        sorted.sort_by(order);
        check_sorted("test", 64, &k, &sorted, None).unwrap();
        let mut swapped = sorted.clone();
        swapped.swap(100, 101);
        let err = check_sorted("test", 64, &k, &swapped, None).unwrap_err();
        assert!(
            err.to_string().contains("2 of 4096 entries differ"),
            "{err}"
        );
        assert!(err.to_string().contains("index 100"), "{err}");
        // A duplicated entry in place of another, and a short read.
        let mut lost = sorted.clone();
        lost[7] = lost[8];
        assert!(check_sorted("test", 64, &k, &lost, None).is_err());
        assert!(check_sorted("test", 64, &k, &sorted[..4095], None).is_err());
        // The unsorted input itself.
        assert!(check_sorted("test", 64, &k, &k, None).is_err());
    }

    #[test]
    fn compact_entries_are_checked_by_level_then_identifier() {
        let k = keys();
        let q = Quantiser::new(12, -250.0, 250.0).unwrap();
        let mut want: Vec<(u32, u32)> = k.iter().map(|e| (q.level(e[0]), e[1] as u32)).collect();
        want.sort_unstable();
        // Keys come back as their level's bound: only the identifiers' order is compared.
        let got: Vec<Entry> = want.iter().map(|&(l, id)| [l as f32, id as f32]).collect();
        check_sorted("test", 64, &k, &got, Some(q)).unwrap();
        let mut swapped = got.clone();
        swapped.swap(0, 4095);
        assert!(check_sorted("test", 64, &k, &swapped, Some(q)).is_err());
    }
}
