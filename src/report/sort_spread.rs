//! The `local` spread against the `even` one (`render.sort.spread`; Latta §4 leaves weighting
//! the spread sort by visual importance to future work), measured by what shows: **visible
//! inversions**, pairs of live particles drawn in the wrong order whose sprites overlap on
//! screen (centres closer than the nominal sprite size, `render.point_size` pixels), where the
//! wrong order changes pixels. All inversions are counted beside them. The scene is the one of
//! [`super::sort_frames`] (`smoke-unlit`, the camera orbiting), the same frames for both spreads.

use serde::Serialize;

use super::sort_frames::{scene, sortedness, SpreadSweep};
use super::{Progress, ReportOptions, SectionOutput, Size};
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::scene::Spread;
use crate::sort::network::{entry_less, Entry};

/// Pairs of entries with a finite key drawn in the wrong order (a later one sorts before an
/// earlier one) whose screen positions, `screen[id]` in pixels, lie closer than `size` pixels.
///
/// Exact, by a grid of cells of `size` pixels on the screen (a close pair lies in the same or
/// neighbouring cells), the drawn entries split among threads: all pairs of the report's
/// 12,000 live particles over 960 frames took minutes.
pub fn visible_inversions(order: &[Entry], screen: &[[f32; 2]], size: f32) -> u64 {
    use rayon::prelude::*;
    use std::collections::HashMap;
    let cell = size.abs();
    // A position that is not finite is at no finite distance from any other: never close.
    let live: Vec<(Entry, [f32; 2])> = (order.iter())
        .filter(|e| e[0].is_finite())
        .filter_map(|e| Some((*e, *screen.get(e[1] as usize)?)))
        .filter(|(_, p)| p[0].is_finite() && p[1].is_finite())
        .collect();
    if cell.is_nan() || cell == 0.0 || live.len() < 2 {
        return 0;
    }
    // Cell coordinates saturate far out; the neighbour cells are deduplicated, so a cell is
    // never scanned twice.
    let key = |p: [f32; 2]| {
        (
            (p[0] as f64 / cell as f64).floor() as i64,
            (p[1] as f64 / cell as f64).floor() as i64,
        )
    };
    let mut grid: HashMap<(i64, i64), Vec<usize>> = HashMap::new();
    for (i, (_, p)) in live.iter().enumerate() {
        grid.entry(key(*p)).or_default().push(i);
    }
    let r2 = size * size;
    (0..live.len())
        .into_par_iter()
        .map(|i| {
            let (a, pa) = live[i];
            let (cx, cy) = key(pa);
            let mut cells: Vec<(i64, i64)> = (-1..=1i64)
                .flat_map(|dx| (-1..=1i64).map(move |dy| (dx, dy)))
                .map(|(dx, dy)| (cx.saturating_add(dx), cy.saturating_add(dy)))
                .collect();
            cells.sort_unstable();
            cells.dedup();
            let mut count = 0u64;
            for c in cells {
                // Each pair once: from the one drawn first.
                for &j in grid.get(&c).map_or(&[][..], |v| v.as_slice()) {
                    let (b, pb) = live[j];
                    let (dx, dy) = (pa[0] - pb[0], pa[1] - pb[1]);
                    if j > i && entry_less(b, a) && dx * dx + dy * dy < r2 {
                        count += 1;
                    }
                }
            }
            count
        })
        .sum()
}

/// One spread at one camera speed and budget.
#[derive(Debug, Clone, Serialize)]
pub struct SpreadCompareRow {
    /// `even` or `local`.
    pub spread: String,
    /// Camera orbit, degrees per second.
    pub orbit_deg_per_s: f32,
    /// Passes per frame.
    pub passes_per_frame: usize,
    /// Frames measured.
    pub frames: usize,
    /// Mean visible inversions per frame.
    pub visible_mean: f64,
    /// Mean inversions per frame.
    pub inversions_mean: f64,
}

/// The comparison: per camera speed and budget, `even` then `local`.
pub fn run(ctx: &Context, size: Size, progress: Progress<'_>) -> Result<Vec<SpreadCompareRow>> {
    let sweep = SpreadSweep::for_size(size);
    let budgets: &[usize] = match size {
        Size::Full => &[4, 16],
        Size::Quick => &[4],
    };
    let mut rows = Vec::new();
    for &orbit in &sweep.orbits {
        for &p in budgets {
            for spread in [Spread::Even, Spread::Local] {
                let name = if spread == Spread::Even {
                    "even"
                } else {
                    "local"
                };
                progress(&format!(
                    "{name} spread: camera {orbit}°/s, {p} passes per frame"
                ));
                let mut s = scene(sweep.side, Some(p), orbit)?;
                s.render.sort.spread = spread;
                let (visible, inversions) = measure(ctx, &s, sweep.frames * 2, sweep.seed)?;
                rows.push(SpreadCompareRow {
                    spread: name.into(),
                    orbit_deg_per_s: orbit,
                    passes_per_frame: p,
                    frames: sweep.frames * 2,
                    visible_mean: visible,
                    inversions_mean: inversions,
                });
            }
        }
    }
    Ok(rows)
}

/// Mean visible inversions and mean inversions over `frames` frames after the emission filled
/// the state and two whole sorts ran.
fn measure(
    ctx: &Context,
    s: &crate::scene::SceneFile,
    frames: usize,
    seed: u64,
) -> Result<(f64, f64)> {
    let mut built = crate::engine::build_gpu(ctx, s, seed)?;
    let engine = built.as_mut();
    let life = s.emitters.allocator[0]
        .longest_life()
        .map_or(0.0, |l| l as f64);
    let warm = (life / (s.time.dt as f64 * s.time.substeps as f64)).ceil() as usize;
    for _ in 0..warm {
        engine.advance_frame()?;
    }
    let [rw, rh] = s.render.resolution;
    let (mut visible, mut inversions) = (0u64, 0u64);
    let cycle = engine.sorter().map_or(1, |s| s.cycle_len());
    let per_frame = s.render.sort.passes_per_frame.unwrap_or(1) as usize;
    for k in 0..2 * cycle.div_ceil(per_frame) + frames {
        engine.advance_frame()?;
        engine.order_for_drawing()?;
        if k < 2 * cycle.div_ceil(per_frame) {
            continue;
        }
        let sorter = engine
            .sorter()
            .ok_or_else(|| Error::InvalidInput("the measured scene does not sort".into()))?;
        let order = sorter.read()?;
        let vp = engine.camera().view_projection(rw as f32 / rh as f32);
        let screen: Vec<[f32; 2]> = (engine.sim().drawn().positions.read_f32()?.chunks_exact(4))
            .map(|p| {
                let c = vp * glam::Vec4::new(p[0], p[1], p[2], 1.0);
                let ndc = [c.x / c.w, c.y / c.w];
                [
                    (ndc[0] * 0.5 + 0.5) * rw as f32,
                    (ndc[1] * 0.5 + 0.5) * rh as f32,
                ]
            })
            .collect();
        visible += visible_inversions(&order, &screen, s.render.point_size);
        inversions += sortedness(&order).inversions;
    }
    ctx.check_error("measuring the weighted spread")?;
    Ok((
        visible as f64 / frames as f64,
        inversions as f64 / frames as f64,
    ))
}

/// The `sort_frames` section of `report all`: [`super::sort_frames::section`], then this
/// comparison (`sort_spread.json` and its table).
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &std::path::Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let mut s = super::sort_frames::section(ctx, opts, out, progress)?;
    let weighted = run(ctx, opts.size, progress)?;
    let json = out.join("sort_spread.json");
    super::write_json(&json, &weighted)?;
    s.files.push(json);
    s.markdown = s.markdown + "\n" + &markdown(&weighted);
    Ok(s)
}

/// The comparison as a markdown section.
pub fn markdown(rows: &[SpreadCompareRow]) -> String {
    let mut out = String::from(
        "## Weighted spread: `local` against `even` (Latta §4)\n\n\
         The same scene and frames; `local` re-runs the odd-even merge sort's first 3 stages \
         (runs of 8 neighbours) before each later stage (`crate::sort::spread`). Visible \
         inversions: pairs drawn in the wrong order whose centres lie closer than the sprite \
         size on screen.\n\n\
         | camera °/s | passes per frame | spread | visible inversions (mean) | inversions (mean) |\n\
         |---:|---:|---|---:|---:|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {} | {} | {:.1} | {:.0} |\n",
            r.orbit_deg_per_s, r.passes_per_frame, r.spread, r.visible_mean, r.inversions_mean
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sort::network::inversions;

    /// Against the CPU's inversion count: every pair visible when the size covers the frame,
    /// none when it is 0, and a hand-counted case.
    #[test]
    fn visible_inversions_count_against_the_cpu() {
        let order: Vec<Entry> = [5.0, 1.0, 4.0, f32::INFINITY, 2.0, 3.0]
            .iter()
            .enumerate()
            .map(|(i, &k)| [k, i as f32])
            .collect();
        let screen: Vec<[f32; 2]> = (0..6).map(|i| [i as f32 * 10.0, 0.0]).collect();
        let live: Vec<Entry> = order.iter().copied().filter(|e| e[0].is_finite()).collect();
        assert_eq!(visible_inversions(&order, &screen, 1e6), inversions(&live));
        assert_eq!(visible_inversions(&order, &screen, 0.0), 0);
        // Within 15 px only neighbours by position: of them only (5, 1) is inverted; (4, 2) is
        // inverted too, but 20 px apart.
        assert_eq!(visible_inversions(&order, &screen, 15.0), 1);
    }

    /// All pairs, the definition.
    fn all_pairs(order: &[Entry], screen: &[[f32; 2]], size: f32) -> u64 {
        let live: Vec<(Entry, [f32; 2])> = (order.iter())
            .filter(|e| e[0].is_finite())
            .filter_map(|e| Some((*e, *screen.get(e[1] as usize)?)))
            .collect();
        let mut count = 0;
        for (i, (a, pa)) in live.iter().enumerate() {
            for (b, pb) in &live[i + 1..] {
                let (dx, dy) = (pa[0] - pb[0], pa[1] - pb[1]);
                if entry_less(*b, *a) && dx * dx + dy * dy < size * size {
                    count += 1;
                }
            }
        }
        count
    }

    /// The grid count equals all pairs' on random orders and screens: clusters, points on cell
    /// faces, equal keys, dead entries, positions far out or not finite, every size.
    #[test]
    fn the_grid_counts_what_all_pairs_count() {
        let mut next = crate::test_rng::uniform(0x2545_f491_4f6c_dd1d);
        for case in 0..60 {
            let n = 1 + (next() * 400.0) as usize;
            let order: Vec<Entry> = (0..n)
                .map(|i| {
                    let k = match (next() * 10.0) as u32 {
                        0 => f32::INFINITY,
                        1 => 3.0,
                        _ => (next() * 50.0) as f32,
                    };
                    [k, ((i * 7 + case) % n) as f32]
                })
                .collect();
            let screen: Vec<[f32; 2]> = (0..n)
                .map(|_| match (next() * 20.0) as u32 {
                    0 => [f32::NAN, 1.0],
                    1 => [f32::INFINITY, 0.0],
                    2 => [3.0e38, -3.0e38],
                    3 => [40.0 * (next() * 5.0).floor() as f32, 40.0],
                    _ => [(next() * 300.0) as f32, (next() * 200.0) as f32],
                })
                .collect();
            for size in [0.0, 1.0, 15.0, 40.0, -40.0, 1e4] {
                assert_eq!(
                    visible_inversions(&order, &screen, size),
                    all_pairs(&order, &screen, size),
                    "case {case}, size {size}"
                );
            }
        }
    }
}
