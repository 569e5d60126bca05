//! Latta's sort spread over frames (§3.4.4), measured: how unsorted the drawing order is when
//! only `passes_per_frame` passes of the odd-even merge sort run per frame while the camera
//! moves and particles are born and die, against the GPU time that buys.
//!
//! The scene is the built-in `smoke-unlit` (alpha-blended sprites, sorted back to front) at a
//! larger state, with the camera orbiting (`render.camera.orbit`) slowly (a pan of 10°/s: frame-to-frame
//! coherence, what Latta's spread sort relies on) and fast (60°/s: one sort of 105 frames spans
//! 105° of turn, and depth orders that far apart are anti-correlated). For each speed and number
//! of passes per frame
//! the engine runs exactly as `texflow render` does (keys refreshed in the order reached so far,
//! this frame's passes, gather); after the sort stage of every measured frame the sorter's
//! entries are read back and compared with the order the frame's own keys call for:
//!
//! - **inversions**: pairs of live particles drawn in the wrong order (0 when sorted);
//! - **Spearman footrule**: the mean distance |i − rank(i)| between where a particle is drawn and
//!   where it belongs (numerics.md's sortedness measure), and its maximum, the **maximum
//!   displacement**.
//!
//! Dead particles (+inf keys) are left out: their order does not change the picture.

use std::path::Path;

use serde::Serialize;

use super::plot::{self, Legend, Marker, Series};
use super::{num, Csv, Progress, ReportOptions, SectionOutput, Size};
use crate::bench::{median, Clock, PassTimer};
use crate::engine::Stages;
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::scene::SceneFile;
use crate::sort::network::{inversions, key_order_bits, Entry};

/// Degrees per second the camera orbits in the measured scene: a slow pan and a fast turn.
pub const ORBITS_DEG_PER_S: [f32; 2] = [10.0, 60.0];

/// What to measure.
#[derive(Debug, Clone)]
pub struct SpreadSweep {
    /// State texture side (side × side particles).
    pub side: u32,
    /// Passes per frame to measure; a value at or above the network's pass count runs the whole
    /// sort every frame.
    pub passes_per_frame: Vec<usize>,
    /// Camera orbit speeds to measure, degrees per second.
    pub orbits: Vec<f32>,
    /// Frames measured per setting at least, rounded up to whole spread sorts (so that every
    /// phase of the pass sequence weighs the same).
    pub frames: usize,
    /// Seed of the scene.
    pub seed: u64,
}

impl SpreadSweep {
    /// The sweep of the report: 128² particles (32² with `--quick`), passes per frame from 1 to
    /// the whole sort in powers of two.
    pub fn for_size(size: Size) -> Self {
        let (side, frames) = match size {
            Size::Full => (128, 60),
            Size::Quick => (32, 12),
        };
        let total = total_passes(side);
        let mut passes: Vec<usize> = std::iter::successors(Some(1usize), |p| Some(p * 2))
            .take_while(|&p| p < total)
            .collect();
        if size == Size::Quick {
            passes.retain(|p| [1, 4, 16].contains(p));
        }
        passes.push(total);
        SpreadSweep {
            side,
            passes_per_frame: passes,
            orbits: ORBITS_DEG_PER_S.to_vec(),
            frames,
            seed: 1,
        }
    }
}

/// Passes of one odd-even merge sort of side × side entries.
pub fn total_passes(side: u32) -> usize {
    let o = crate::sort::SortOptions::default();
    crate::sort::pass_count(crate::sort::Variant::OddEven, side, side, side * side, &o)
}

/// How sorted an order is, against the order its own keys call for.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sortedness {
    /// Entries measured (live particles).
    pub n: usize,
    /// Pairs out of order.
    pub inversions: u64,
    /// Mean |position − rank| (Spearman footrule / n).
    pub mean_displacement: f64,
    /// Largest |position − rank|.
    pub max_displacement: u64,
    /// 99th percentile of |position − rank| (a newborn particle enters at the end of the order,
    /// far from its place, so the maximum alone says little).
    pub p99_displacement: u64,
}

/// Measures the order of the entries with a finite key (live particles), in the order given.
pub fn sortedness(entries: &[Entry]) -> Sortedness {
    let live: Vec<Entry> = entries
        .iter()
        .copied()
        .filter(|e| e[0].is_finite())
        .collect();
    let mut by_rank: Vec<usize> = (0..live.len()).collect();
    by_rank.sort_by_key(|&i| (key_order_bits(live[i][0]), live[i][1].to_bits()));
    let mut d: Vec<u64> = by_rank
        .iter()
        .enumerate()
        .map(|(rank, &i)| rank.abs_diff(i) as u64)
        .collect();
    let sum: u64 = d.iter().sum();
    d.sort_unstable();
    let max = d.last().copied().unwrap_or(0);
    let p99 = d
        .get((d.len() * 99).div_ceil(100).saturating_sub(1))
        .copied()
        .unwrap_or(0);
    Sortedness {
        n: live.len(),
        inversions: inversions(&live),
        mean_displacement: if live.is_empty() {
            0.0
        } else {
            sum as f64 / live.len() as f64
        },
        max_displacement: max,
        p99_displacement: p99,
    }
}

/// One setting of camera speed and passes per frame.
#[derive(Debug, Clone, Serialize)]
pub struct SpreadRow {
    /// Camera orbit, degrees per second.
    pub orbit_deg_per_s: f32,
    /// Passes run per frame (the whole sort when at least `total_passes`).
    pub passes_per_frame: usize,
    /// Passes of one whole sort.
    pub total_passes: usize,
    /// Frames one whole sort is spread over.
    pub frames_per_sort: usize,
    /// Frames measured.
    pub frames: usize,
    /// Mean live particles over the measured frames.
    pub live_mean: f64,
    /// Mean inversions per frame.
    pub inversions_mean: f64,
    /// Largest inversions of a frame.
    pub inversions_max: u64,
    /// Mean inversions as a fraction of all pairs of live particles.
    pub inversion_fraction: f64,
    /// Mean over frames of the mean displacement (positions).
    pub mean_displacement: f64,
    /// Largest displacement of any particle in any measured frame (positions).
    pub max_displacement: u64,
    /// Largest over frames of the frame's 99th-percentile displacement (positions).
    pub p99_displacement: u64,
    /// Median GPU time of a frame's sort stage: key pass, this frame's passes, gather (ms).
    pub gpu_ms: f64,
}

/// What [`run`] measured.
#[derive(Debug, Clone, Serialize)]
pub struct SpreadReport {
    /// Renderer of the device.
    pub device: String,
    /// How GPU time was taken.
    pub clock: Clock,
    /// State side.
    pub side: u32,
    /// Seconds simulated before measuring (the emitter fills the state).
    pub warmup_s: f64,
    /// One row per setting.
    pub rows: Vec<SpreadRow>,
}

/// The measured scene: `smoke-unlit` at side × side particles, its emitter scaled to fill about
/// three quarters of the state, the camera orbiting at `orbit` degrees per second, an odd-even merge
/// sort of `passes` per frame (`None`: the whole sort).
pub fn scene(side: u32, passes: Option<usize>, orbit: f32) -> Result<SceneFile> {
    let mut s = crate::scene::load("smoke-unlit")?;
    s.particles.size = [side, side];
    let e = s.emitters.allocator.first_mut().ok_or_else(|| {
        Error::InvalidInput("the smoke scene has no allocator emitter to scale".into())
    })?;
    let life = e.life_at(0.0).ok_or_else(|| {
        Error::InvalidInput("the smoke scene's emitter has no life span to scale by".into())
    })?;
    let mean_life = 0.5 * (life[0] + life[1]) as f64;
    e.rate = Some(((0.75 * (side * side) as f64 / mean_life) as f32).into());
    s.render.camera.orbit = orbit;
    s.render.sort.variant = Some(crate::sort::Variant::OddEven);
    s.render.sort.passes_per_frame = passes.map(|p| p as u32);
    Ok(s)
}

/// Runs the sweep.
pub fn run(ctx: &Context, sweep: &SpreadSweep, progress: Progress<'_>) -> Result<SpreadReport> {
    let total = total_passes(sweep.side);
    let timer = PassTimer::new(ctx, Clock::for_context(ctx))?;
    let mut rows = Vec::new();
    let mut warmup_s = 0.0;
    let settings = sweep
        .orbits
        .iter()
        .flat_map(|&o| sweep.passes_per_frame.iter().map(move |&p| (o, p)));
    for (orbit, p) in settings {
        if p == 0 {
            return Err(Error::InvalidInput(
                "passes per frame must be at least 1".into(),
            ));
        }
        progress(&format!(
            "sort spread over frames: camera {orbit}°/s, {p} passes per frame"
        ));
        let whole = p >= total;
        let s = scene(sweep.side, (!whole).then_some(p), orbit)?;
        let mut built = crate::engine::build_gpu(ctx, &s, sweep.seed)?;
        let engine = built.as_mut();
        let per_sort = total.div_ceil(p.min(total));
        warmup_s = warm_up(engine, &s, per_sort)?;
        let frames = sweep.frames.div_ceil(per_sort).max(1) * per_sort;
        let (mut times, mut inv, mut live) = (Vec::new(), Vec::new(), Vec::new());
        let (mut mean_disp, mut max_disp, mut p99_disp, mut fraction) = (0.0, 0u64, 0u64, 0.0);
        for _ in 0..frames {
            engine.advance_frame()?;
            let mut r = Ok(());
            times.push(timer.time(|| r = engine.order_for_drawing())?);
            r?;
            let sorter = engine
                .sorter()
                .ok_or_else(|| Error::InvalidInput("the measured scene does not sort".into()))?;
            let m = sortedness(&sorter.read()?);
            inv.push(m.inversions);
            live.push(m.n as f64);
            mean_disp += m.mean_displacement / frames as f64;
            max_disp = max_disp.max(m.max_displacement);
            p99_disp = p99_disp.max(m.p99_displacement);
            let pairs = (m.n as f64) * (m.n as f64 - 1.0) / 2.0;
            if pairs > 0.0 {
                fraction += m.inversions as f64 / pairs / frames as f64;
            }
        }
        ctx.check_error("measuring the sort spread over frames")?;
        rows.push(SpreadRow {
            orbit_deg_per_s: orbit,
            passes_per_frame: p.min(total),
            total_passes: total,
            frames_per_sort: per_sort,
            frames,
            live_mean: live.iter().sum::<f64>() / frames as f64,
            inversions_mean: inv.iter().sum::<u64>() as f64 / frames as f64,
            inversions_max: inv.iter().copied().max().unwrap_or(0),
            inversion_fraction: fraction,
            mean_displacement: mean_disp,
            max_displacement: max_disp,
            p99_displacement: p99_disp,
            gpu_ms: median(&times),
        });
    }
    Ok(SpreadReport {
        device: ctx.limits().renderer.clone(),
        clock: timer.clock(),
        side: sweep.side,
        warmup_s,
        rows,
    })
}

/// Fills the state of `s` (the sort does not run while the simulation warms up), then runs two
/// whole spread sorts of `per_sort` frames each; returns the simulated warm-up time (s).
fn warm_up(engine: &mut dyn Stages, s: &SceneFile, per_sort: usize) -> Result<f64> {
    let life = s.emitters.allocator[0]
        .longest_life()
        .map_or(0.0, |l| l as f64);
    let warm_frames = (life / (s.time.dt as f64 * s.time.substeps as f64)).ceil() as usize;
    let warmup_s = warm_frames as f64 * s.time.dt as f64 * s.time.substeps as f64;
    for _ in 0..warm_frames {
        engine.advance_frame()?;
    }
    // Two whole spread sorts, so the order reached is the steady state, not the first sort
    // from the emission order.
    for _ in 0..2 * per_sort {
        engine.advance_frame()?;
        engine.order_for_drawing()?;
    }
    Ok(warmup_s)
}

/// The rows as a markdown table.
pub fn table(r: &SpreadReport) -> String {
    let mut out = String::from(
        "| camera °/s | passes per frame | frames per sort | live | inversions (mean) | inversions (max) | \
         of all pairs | mean displacement | 99th pct displacement | max displacement | GPU ms per frame |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for row in &r.rows {
        out.push_str(&format!(
            "| {} | {}{} | {} | {:.0} | {:.0} | {} | {:.2e} | {:.2} | {} | {} | {:.3} |\n",
            row.orbit_deg_per_s,
            row.passes_per_frame,
            if row.passes_per_frame == row.total_passes {
                " (whole sort)"
            } else {
                ""
            },
            row.frames_per_sort,
            row.live_mean,
            row.inversions_mean,
            row.inversions_max,
            row.inversion_fraction,
            row.mean_displacement,
            row.p99_displacement,
            row.max_displacement,
            row.gpu_ms
        ));
    }
    out
}

/// Writes `sort_frames.csv`, `sort_frames.json` and the two plots; returns the files.
pub fn write_files(r: &SpreadReport, out: &Path) -> Result<Vec<std::path::PathBuf>> {
    let csv = csv_table(r);
    let csv_path = out.join("sort_frames.csv");
    csv.write(&csv_path)?;
    let json_path = out.join("sort_frames.json");
    super::write_json(&json_path, r)?;
    let mut files = vec![csv_path, json_path];
    let title = |what: &str| format!("{what}: {}² smoke ({})", r.side, r.device);
    let unit = "fraction (whole sort: 0, off the log axis)";
    let p1 = out.join("sort_frames_passes.png");
    plot::loglog(
        &p1,
        &title("odd-even sort spread over frames"),
        ("passes per frame", unit),
        &curves(r, &|row| row.passes_per_frame as f64),
        (900, 600),
        Legend::UpperRight,
    )?;
    let p2 = out.join("sort_frames_time.png");
    plot::loglog(
        &p2,
        &title("drawing order against GPU time"),
        (
            &format!(
                "GPU time of the sort stage per frame (ms, {})",
                r.clock.name()
            ),
            unit,
        ),
        &curves(r, &|row| row.gpu_ms),
        (900, 600),
        Legend::UpperRight,
    )?;
    files.push(p1);
    files.push(p2);
    Ok(files)
}

/// One CSV row per (orbit, passes per frame).
fn csv_table(r: &SpreadReport) -> Csv {
    let mut csv = Csv::new(&[
        "orbit_deg_per_s",
        "passes_per_frame",
        "total_passes",
        "frames_per_sort",
        "frames",
        "live_mean",
        "inversions_mean",
        "inversions_max",
        "inversion_fraction",
        "mean_displacement",
        "p99_displacement",
        "max_displacement",
        "gpu_ms",
    ]);
    for row in &r.rows {
        csv.row([
            num(Some(row.orbit_deg_per_s as f64)),
            row.passes_per_frame.to_string(),
            row.total_passes.to_string(),
            row.frames_per_sort.to_string(),
            row.frames.to_string(),
            num(Some(row.live_mean)),
            num(Some(row.inversions_mean)),
            row.inversions_max.to_string(),
            num(Some(row.inversion_fraction)),
            num(Some(row.mean_displacement)),
            row.p99_displacement.to_string(),
            row.max_displacement.to_string(),
            num(Some(row.gpu_ms)),
        ]);
    }
    csv
}

/// Per orbit speed, the inversions and the 99th percentile displacement against `x` of a row.
fn curves(r: &SpreadReport, x: &dyn Fn(&SpreadRow) -> f64) -> Vec<Series> {
    let mut orbits: Vec<f32> = r.rows.iter().map(|row| row.orbit_deg_per_s).collect();
    orbits.dedup();
    let colors = [(40, 100, 200), (200, 60, 40), (40, 150, 60), (150, 60, 170)];
    let mut out = Vec::new();
    for (k, &orbit) in orbits.iter().enumerate() {
        let rows: Vec<&SpreadRow> = r
            .rows
            .iter()
            .filter(|row| row.orbit_deg_per_s == orbit)
            .collect();
        let color = colors[k % colors.len()];
        out.push(Series {
            label: format!("{orbit}°/s: inversions / all pairs"),
            points: rows
                .iter()
                .map(|row| (x(row), row.inversion_fraction))
                .collect(),
            hollow: Vec::new(),
            color,
            marker: Marker::Circle,
            dashed: false,
        });
        out.push(Series {
            label: format!("{orbit}°/s: 99th pct displacement / live"),
            points: rows
                .iter()
                .map(|row| (x(row), row.p99_displacement as f64 / row.live_mean.max(1.0)))
                .collect(),
            hollow: Vec::new(),
            color,
            marker: Marker::Triangle,
            dashed: true,
        });
    }
    out
}

/// The markdown of `summary.md`.
pub fn markdown(r: &SpreadReport) -> String {
    format!(
        "## Sort spread over frames (Latta §3.4.4)\n\n\
         `smoke-unlit` at {0}×{0} particles with the camera orbiting, {1:.1} s of emission before \
         measuring; odd-even merge sort of {2} passes, keys refreshed every frame in the order \
         reached so far; whole spread sorts measured. Inversions and displacements among live \
         particles after each frame's sort stage; GPU time ({3}) of that stage. Plots: \
         `sort_frames_passes.png`, `sort_frames_time.png`.\n\n{4}",
        r.side,
        r.warmup_s,
        r.rows.first().map_or(0, |row| row.total_passes),
        r.clock.name(),
        table(r)
    )
}

/// `report all`'s section.
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let r = run(ctx, &SpreadSweep::for_size(opts.size), progress)?;
    let mut warnings = Vec::new();
    for row in r
        .rows
        .iter()
        .filter(|row| row.passes_per_frame == row.total_passes && row.inversions_max > 0)
    {
        warnings.push(format!(
            "the whole odd-even sort left {} inversions (camera {}°/s): the network is not \
             sorting",
            row.inversions_max, row.orbit_deg_per_s
        ));
    }
    Ok(SectionOutput {
        files: write_files(&r, out)?,
        markdown: markdown(&r),
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sortedness_counts_against_brute_force() {
        let mut g = 12345u64;
        let mut next = || {
            g = g.wrapping_mul(6364136223846793005).wrapping_add(1);
            (g >> 33) as f32 / (1u64 << 31) as f32
        };
        for n in [0usize, 1, 2, 7, 50] {
            let e: Vec<Entry> = (0..n)
                .map(|i| {
                    let k = if i % 5 == 3 {
                        f32::INFINITY
                    } else {
                        next().floor() + next()
                    };
                    [k, i as f32]
                })
                .collect();
            let m = sortedness(&e);
            let live: Vec<Entry> = e.iter().copied().filter(|x| x[0].is_finite()).collect();
            let mut brute = 0;
            for i in 0..live.len() {
                for j in i + 1..live.len() {
                    if crate::sort::network::entry_less(live[j], live[i]) {
                        brute += 1;
                    }
                }
            }
            assert_eq!(m.n, live.len());
            assert_eq!(m.inversions, brute);
            // Displacement: each entry's rank is the count of entries less than it.
            let mut max = 0;
            for (i, a) in live.iter().enumerate() {
                let rank = live
                    .iter()
                    .filter(|b| crate::sort::network::entry_less(**b, *a))
                    .count();
                max = max.max(rank.abs_diff(i) as u64);
            }
            assert_eq!(m.max_displacement, max);
            assert!(m.p99_displacement <= m.max_displacement);
        }
        // Sorted input: nothing out of place; reversed: every pair.
        let sorted: Vec<Entry> = (0..10).map(|i| [i as f32, i as f32]).collect();
        assert_eq!(sortedness(&sorted).inversions, 0);
        assert_eq!(sortedness(&sorted).max_displacement, 0);
        let rev: Vec<Entry> = sorted.iter().rev().copied().collect();
        assert_eq!(sortedness(&rev).inversions, 45);
        assert_eq!(sortedness(&rev).max_displacement, 9);
    }

    #[test]
    fn sweep_ends_with_the_whole_sort() {
        for size in [Size::Full, Size::Quick] {
            let s = SpreadSweep::for_size(size);
            assert_eq!(*s.passes_per_frame.last().unwrap(), total_passes(s.side));
            assert!(s.passes_per_frame.windows(2).all(|w| w[0] < w[1]));
        }
        // log2(n) (log2(n) + 1) / 2 passes for n = 2^14.
        assert_eq!(total_passes(128), 14 * 15 / 2);
    }
}
