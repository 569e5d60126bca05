//! The programs one collision step draws, each for the line of the pass list that describes it
//! ([`exact_passes`], [`neighbour_passes`](super::neighbour_passes), the features' UberFlow
//! lines), taken from the programs and sorters the stage built, and the exact mode's lines.

use super::{cells, tally, CollisionStage, Grid, Passes, EXACT_SCAN};
use crate::gl::PassDraw;
use crate::scene::CollisionSort;
use crate::sort::Sorter;

/// The exact mode's passes of one iteration (`collisions.iterations` per step), as `texflow
/// scene passes` lists them.
pub fn exact_passes(
    colliders: bool,
    sort: CollisionSort,
    search: cells::CellTables,
) -> Vec<String> {
    let table = search.collisions;
    let mut out: Vec<String> = vec![
        "collision keys: cell index in the lattice (z, y, x), every iteration".into(),
        format!(
            "collision sort: {}, every iteration",
            uberflow_sort(sort, None, false)
        ),
        "gather position, velocity, static in cell order".into(),
    ];
    if table {
        out.push(cells::table_line("collision", ", every iteration"));
    }
    out.extend([
        format!(
            "exact detection: partners closer than 2r counted in {}, and the closest ({}, at \
             most {EXACT_SCAN} particles per run{}); the separations with every partner \
             summed, with and without the closest partner's exchange",
            cells::walk_words(search.collisions_trimmed, "2r"),
            cells::search_words(table),
            cells::partner_words(cells::PartnerWork::Contacts)
        ),
        format!(
            "exact response, no walk: the count's sum with the closest partner's momentum \
             exchange (back-tracking to contact) if it chose this particle too, else the \
             separations alone{}",
            if colliders {
                "; boundary conditions (colliders)"
            } else {
                ""
            }
        ),
        tally::pass_line("truncation tally: the particles whose search hit the bound"),
    ]);
    out
}

/// How UberFlow's detection sorts a lattice, for its `collision sort` line: within `rows` rows
/// (or fully) on the `sort` network, and for a blocked sort within rows which entries it takes
/// (`row_cells`: 4-byte exact ones, [`crate::sort::SortOptions::row_cells`]).
pub fn uberflow_sort(sort: CollisionSort, rows: Option<u32>, row_cells: bool) -> String {
    let net = sort.label();
    let net = match (rows, row_cells) {
        (Some(1), true) => format!("{net}, 4-byte exact entries: cell key and column"),
        (_, true) => format!("{net}, 4-byte exact entries: cell key and place in the rows"),
        (Some(_), false) if sort == CollisionSort::Blocked => {
            format!("{net}, 8-byte entries: too many cells for 4-byte ones")
        }
        _ => net.to_string(),
    };
    match rows {
        Some(1) => format!("rows-only sort ({net})"),
        Some(r) => format!("sort within sets of {r} rows ({net})"),
        None => format!("full sort ({net})"),
    }
}

/// A lattice's keys, sort and gather, `times` times.
fn sort_draws(out: &mut Vec<PassDraw>, g: &Grid, times: u64) {
    out.extend(
        g.sorted
            .sort_draws("collision keys", "collision sort", times),
    );
}

impl CollisionStage {
    /// The draws of one step, in the order of the stage's pass lines.
    pub(crate) fn pass_draws(&self) -> Vec<PassDraw> {
        let mut out = Vec::new();
        let table = |times| self.first.sorted.table_draws("cell start", times);
        if let Some(n) = &self.neighbours {
            sort_draws(&mut out, &self.first, 1);
            out.extend(table(1));
            out.extend(n.pass_draws());
        }
        if !self.impulse_runs() {
            return out;
        }
        match &self.passes {
            Passes::Exact {
                count, response, ..
            } => {
                let k = self.config.iterations.max(1) as u64;
                sort_draws(&mut out, &self.first, k);
                out.extend(table(k));
                out.push(PassDraw::of("exact detection", count, k));
                out.push(PassDraw::of("exact response", response, k));
                if let Some(t) = &self.tally {
                    out.push(PassDraw::of("truncation tally", t.program(), k * t.draws()));
                }
                if self.first.spin.is_some() {
                    out.push(PassDraw::new("spin", Sorter::gather_program(), k));
                }
            }
            Passes::Uberflow {
                detect,
                mutual,
                response,
                ..
            } => {
                for g in std::iter::once(&self.first).chain(&self.second) {
                    sort_draws(&mut out, g, 1);
                    out.push(PassDraw::of("collision detection", detect, 1));
                    out.push(PassDraw::of("collision detection", mutual, 1));
                }
                out.push(PassDraw::of("collision response", response, 1));
                let spins = std::iter::once(&self.first).chain(&self.second);
                let spins = spins.filter(|g| g.spin.is_some()).count() as u64;
                if spins > 0 {
                    out.push(PassDraw::new("spin", Sorter::gather_program(), spins));
                }
            }
        }
        out
    }
}

/// The texel fetches of UberFlow's detection over a `width` × `rows` layout with `k` neighbours
/// each side, every particle live: its own position and each neighbour inside its row, up to `k`
/// each side (`glsl/collide/detect.frag`). A dead particle fetches only its own, so this is the
/// most the pass fetches: declared for the cost model, which counts what passes read.
pub fn detection_fetches(width: u32, rows: u32, k: u32) -> u64 {
    let (w, k) = (width as u64, k as u64);
    // Column x reaches min(k, x) to its left and min(k, w - 1 - x) to its right; summed over
    // the row each side gives the same count: 0 + 1 + ... + (k - 1), then k for the rest (in
    // closed form, as it is counted every step).
    let side = match w <= k {
        true => w * w.saturating_sub(1) / 2,
        false => k * k.saturating_sub(1) / 2 + (w - k) * k,
    };
    rows as u64 * (w + 2 * side)
}

#[cfg(test)]
mod tests {
    use super::detection_fetches;

    /// Against a count of the shader's loop, candidate by candidate.
    #[test]
    fn detection_fetches_count_the_row_window() {
        for (w, rows, k) in [
            (1, 1, 8),
            (5, 3, 8),
            (8, 1, 8),
            (9, 2, 8),
            (17, 2, 8),
            (64, 4, 1),
            (32, 1, 0),
        ] {
            let mut n = 0u64;
            for _ in 0..rows {
                for x in 0..w as i64 {
                    n += 1;
                    for m in 1..=k as i64 {
                        n += (x - m >= 0) as u64 + (x + m < w as i64) as u64;
                    }
                }
            }
            assert_eq!(detection_fetches(w, rows, k), n, "{w}×{rows}, k = {k}");
        }
    }
}
