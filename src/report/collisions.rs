//! Collisions between particles (UberFlow §4.3-4.5), measured: the miss rate of the detection
//! against the GPU time of the collision passes, for the neighbour count k, the staggered
//! lattice, rows-only sorting and the cell size, on the built-in `collide` scene. The numbers are
//! those of `texflow collide-stats collide --sweep` ([`super::collide_runs::sweep`]): the pairs
//! the GPU found at the last step against all overlapping pairs from a CPU cell-list reference;
//! and the miss rate against density on the `gas` scene ([`density_sweep`]).

use std::path::{Path, PathBuf};

use super::collide_runs::{measure, sweep, sweep_table, SweepRow};
use super::collide_stats::CollisionStats;
use super::plot::{self, Legend, Marker, Series};
use super::{num, Csv, Progress, ReportOptions, SectionOutput, Size};
use crate::bench::{median, Clock};
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::scene::{self, SceneFile};

/// Steps simulated before the measured one: the docs' 240 (the pile has formed), 60 with
/// `--quick`.
pub fn steps(size: Size) -> u64 {
    match size {
        Size::Full => 240,
        Size::Quick => 60,
    }
}

/// Miss rate of a row, percent.
pub fn miss_rate(row: &SweepRow) -> f64 {
    100.0 * row.stats.missed as f64 / row.stats.pairs_true.max(1) as f64
}

/// Writes `collisions.csv`, `collisions.json` and `collisions_miss_rate.png`.
pub fn write_files(
    rows: &[SweepRow],
    device: &str,
    clock: Clock,
    steps: u64,
    out: &Path,
) -> Result<Vec<PathBuf>> {
    let csv = table(rows);
    let csv_path = out.join("collisions.csv");
    csv.write(&csv_path)?;
    let json_path = out.join("collisions.json");
    super::write_json(&json_path, rows)?;
    let series = miss_rate_series(rows);
    let png = out.join("collisions_miss_rate.png");
    plot::loglog(
        &png,
        &format!("collision detection: collide scene, step {steps} ({device})"),
        (
            &format!(
                "GPU time of the collision passes of one step (ms, {})",
                clock.name()
            ),
            "missed overlapping pairs (%)",
        ),
        &series,
        (900, 600),
        Legend::UpperRight,
    )?;
    Ok(vec![csv_path, json_path, png])
}

/// One CSV row per variant of the sweep.
fn table(rows: &[SweepRow]) -> Csv {
    let mut csv = Csv::new(&[
        "variant",
        "k",
        "staggered",
        "rows_only",
        "cell_m",
        "particles",
        "particles_per_cell",
        "pairs_true",
        "found",
        "missed",
        "miss_rate_percent",
        "false_pairs",
        "mutual",
        "conflicts",
        "missed_adjacent_cells",
        "missed_other_row",
        "missed_far_along_row",
        "missed_closer_partner",
        "tunnelled",
        "gpu_ms",
    ]);
    for r in rows {
        let s = &r.stats;
        csv.row([
            r.variant.replace(',', ";"),
            r.k.to_string(),
            r.staggered.to_string(),
            r.rows_only.map_or(String::new(), |n| n.to_string()),
            num(Some(r.cell as f64)),
            s.particles.to_string(),
            num(Some(s.particles_per_cell)),
            s.pairs_true.to_string(),
            s.found.to_string(),
            s.missed.to_string(),
            num(Some(miss_rate(r))),
            s.false_pairs.to_string(),
            s.mutual.to_string(),
            s.conflicts.to_string(),
            s.missed_adjacent_cells.to_string(),
            s.missed_other_row.to_string(),
            s.missed_far_along_row.to_string(),
            s.missed_closer_partner.to_string(),
            s.tunnelled.to_string(),
            num(Some(s.gpu_ms)),
        ]);
    }
    csv
}

/// The k sweep (the scene's lattice and sort) as a curve; every other setting one point.
fn miss_rate_series(rows: &[SweepRow]) -> Vec<Series> {
    let scene = rows.first();
    let same_but_k = |r: &SweepRow| {
        scene.is_some_and(|s| {
            r.staggered == s.staggered && r.rows_only == s.rows_only && r.cell == s.cell
        })
    };
    let mut k_rows: Vec<&SweepRow> = rows.iter().filter(|r| same_but_k(r)).collect();
    k_rows.sort_by_key(|r| r.k);
    let colors = [
        (40, 100, 200),
        (200, 60, 40),
        (40, 150, 60),
        (150, 60, 170),
        (220, 140, 20),
        (90, 90, 90),
    ];
    let mut series = vec![Series {
        label: format!(
            "k = {} (the scene's lattice and sort)",
            k_rows
                .iter()
                .map(|r| r.k.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        points: k_rows
            .iter()
            .map(|r| (r.stats.gpu_ms, miss_rate(r)))
            .collect(),
        hollow: Vec::new(),
        color: colors[0],
        marker: Marker::Circle,
        dashed: false,
    }];
    for (i, r) in rows.iter().filter(|r| !same_but_k(r)).enumerate() {
        series.push(Series {
            label: r.variant.clone(),
            points: vec![(r.stats.gpu_ms, miss_rate(r))],
            hollow: Vec::new(),
            color: colors[1 + i % (colors.len() - 1)],
            marker: if i < colors.len() - 1 {
                Marker::Triangle
            } else {
                Marker::Cross
            },
            dashed: false,
        });
    }
    series
}

/// The markdown of `summary.md`.
pub fn markdown(rows: &[SweepRow], steps: u64, clock: Clock) -> String {
    format!(
        "## Collisions between particles (UberFlow §4.3-4.5)\n\n\
         `collide` scene, detection at step {steps} against all overlapping pairs (CPU cell \
         lists); one setting changed at a time; GPU time ({}) of the collision passes of that \
         step. Plot: `collisions_miss_rate.png`.\n\n{}",
        clock.name(),
        sweep_table(rows)
    )
}

/// Radii of the density sweep on the `gas` scene (overlaps per particle grow as r^3), and its
/// steps and particles.
pub fn density_plan(size: Size) -> (Vec<f32>, u64, [u32; 2]) {
    match size {
        Size::Full => (vec![0.004, 0.008, 0.016], 100, [128, 128]),
        Size::Quick => (vec![0.016, 0.032], 10, [32, 32]),
    }
}

/// Writes `collisions_density.csv` and the plot `collisions_density.png` (miss rate against
/// overlaps per particle, one curve per configuration; zero miss rates cannot be drawn on log
/// axes and are named in the legend instead).
pub fn write_density(points: &[DensityPoint], device: &str, out: &Path) -> Result<Vec<PathBuf>> {
    let csv = density_csv(points);
    let csv_path = out.join("collisions_density.csv");
    csv.write(&csv_path)?;
    let series = density_series(points);
    let png = out.join("collisions_density.png");
    plot::loglog(
        &png,
        &format!("collision detection against density: gas scene ({device})"),
        (
            "overlapping neighbours per particle",
            "missed overlapping pairs (%)",
        ),
        &series,
        (900, 600),
        Legend::UpperLeft,
    )?;
    Ok(vec![csv_path, png])
}

/// The density sweep's table: one row per point, `;` for `,` in the configuration's name.
fn density_csv(points: &[DensityPoint]) -> Csv {
    let mut csv = Csv::new(&[
        "config",
        "radius_m",
        "overlaps_per_particle",
        "pairs_true",
        "missed",
        "miss_rate_percent",
        "partnered_percent",
        "gpu_ms",
    ]);
    for p in points {
        let s = &p.stats;
        csv.row([
            p.config.replace(',', ";"),
            num(Some(p.radius as f64)),
            num(Some(s.overlaps_per_particle)),
            s.pairs_true.to_string(),
            s.missed.to_string(),
            num(Some(100.0 * s.missed as f64 / s.pairs_true.max(1) as f64)),
            num(Some(
                100.0 * s.partnered as f64 / s.overlapping.max(1) as f64,
            )),
            num(Some(s.gpu_ms)),
        ]);
    }
    csv
}

/// One curve per configuration: the miss rate against the density (points with none missed
/// are not drawn on log axes, and the legend says how many).
fn density_series(points: &[DensityPoint]) -> Vec<Series> {
    let colors = [
        (40, 100, 200),
        (200, 60, 40),
        (40, 150, 60),
        (150, 60, 170),
        (220, 140, 20),
        (90, 90, 90),
    ];
    density_configs()
        .iter()
        .enumerate()
        .map(|(i, (name, _))| {
            let pts: Vec<(f64, f64)> = points
                .iter()
                .filter(|p| p.config == *name)
                .map(|p| {
                    (
                        p.stats.overlaps_per_particle,
                        100.0 * p.stats.missed as f64 / p.stats.pairs_true.max(1) as f64,
                    )
                })
                .collect();
            let zero = pts.iter().filter(|p| p.1 == 0.0).count();
            Series {
                label: if zero > 0 {
                    format!("{name} (0 missed at {zero} densities: not drawn)")
                } else {
                    (*name).to_owned()
                },
                points: pts,
                hollow: Vec::new(),
                color: colors[i % colors.len()],
                marker: if i % 2 == 0 {
                    Marker::Circle
                } else {
                    Marker::Triangle
                },
                dashed: false,
            }
        })
        .collect()
}

/// `report all`'s section.
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let steps = steps(opts.size);
    let scene = crate::scene::load("collide")?;
    let rows = sweep(ctx, &scene, steps, crate::engine::shader_seed(1), |name| {
        progress(&format!("collisions: {name}"))
    })?;
    let clock = Clock::for_context(ctx);
    let mut warnings = Vec::new();
    for r in rows.iter().filter(|r| r.stats.false_pairs > 0) {
        warnings.push(format!(
            "collisions, {}: {} reported pairs do not overlap",
            r.variant, r.stats.false_pairs
        ));
    }
    let mut files = write_files(&rows, &ctx.limits().renderer, clock, steps, out)?;
    let (radii, dsteps, size) = density_plan(opts.size);
    let mut gas = crate::scene::load("gas")?;
    gas.particles.size = size;
    let points = density_sweep(
        ctx,
        &gas,
        &radii,
        dsteps,
        crate::engine::shader_seed(1),
        |name| progress(&format!("collisions against density: {name}")),
    )?;
    files.extend(write_density(&points, &ctx.limits().renderer, out)?);
    let mut md = markdown(&rows, steps, clock);
    md += &format!(
        "\n### Miss rate against density\n\n`gas` scene at {}x{} particles, step {dsteps}, \
         radius varied; plot: `collisions_density.png`.\n\n{}",
        size[0],
        size[1],
        density_table(&points)
    );
    let plan = super::pile_depth::plan(opts.size);
    let seed = crate::engine::shader_seed(1);
    let piles = super::pile_depth::pile_sweep(ctx, plan, seed, progress)?;
    files.push(super::pile_depth::write_json(&piles, out)?);
    md += &super::pile_depth::markdown(&piles, plan, clock);
    Ok(SectionOutput {
        files,
        markdown: md,
        warnings,
    })
}

/// One point of [`density_sweep`]: a detection configuration at one density.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct DensityPoint {
    /// The configuration (one curve of the plot).
    pub config: String,
    /// Sphere radius (m).
    pub radius: f32,
    /// The measurement.
    pub stats: CollisionStats,
}

/// How a configuration of [`density_configs`] changes a scene's `[collisions]`.
pub type ConfigChange = fn(&mut scene::Collisions);

/// The detection configurations of [`density_sweep`]: name and how it changes the scene's
/// `[collisions]` at radius r (cell 2r or 8r, staggering, k, rows-only, exact).
pub fn density_configs() -> Vec<(&'static str, ConfigChange)> {
    fn cell(c: &mut scene::Collisions, f: f32) {
        c.cell = Some(f * c.radius);
    }
    vec![
        ("staggered, full sort, k 8, cell 2r", |c| cell(c, 2.0)),
        ("staggered, full sort, k 8, cell 8r", |c| cell(c, 8.0)),
        ("one lattice, full sort, k 8, cell 8r", |c| {
            cell(c, 8.0);
            c.staggered = false;
        }),
        ("staggered, full sort, k 2, cell 8r", |c| {
            cell(c, 8.0);
            c.neighbours = 2;
        }),
        ("staggered, rows only, k 8, cell 8r", |c| {
            cell(c, 8.0);
            c.rows_only = Some(1);
        }),
        ("exact, cell 2r", |c| {
            cell(c, 2.0);
            c.detection = scene::Detection::Exact;
        }),
    ]
}

/// The miss rate against density: `scene` (a gas such as the built-in `gas`) at each sphere
/// radius of `radii`, measured with every configuration of [`density_configs`].
pub fn density_sweep(
    ctx: &Context,
    scene: &SceneFile,
    radii: &[f32],
    steps: u64,
    seed: u32,
    mut progress: impl FnMut(&str),
) -> Result<Vec<DensityPoint>> {
    let mut out = Vec::new();
    for &r in radii {
        for (name, change) in density_configs() {
            progress(&format!("{name}, r = {r}"));
            let mut s = scene.clone();
            let Some(c) = s.collisions.as_mut() else {
                return Err(Error::InvalidInput(format!(
                    "scene `{}` has no [collisions] section",
                    scene.name
                )));
            };
            c.radius = r;
            change(c);
            let stats = measure(ctx, &s, steps, seed, || {})?;
            out.push(DensityPoint {
                config: name.to_owned(),
                radius: r,
                stats,
            });
        }
    }
    Ok(out)
}

/// The density sweep as a markdown table: one row per density, the miss rate of each
/// configuration (the density is the median of the configurations' own, which differ because
/// each detection moves the gas differently).
pub fn density_table(points: &[DensityPoint]) -> String {
    let configs: Vec<&str> = density_configs().iter().map(|c| c.0).collect();
    let mut out = String::from("| radius (m) | overlaps per particle |");
    let mut rule = String::from("| ---: | ---: |");
    for c in &configs {
        out += &format!(" {c}: missed |");
        rule += " ---: |";
    }
    out += &format!("\n{rule}\n");
    let mut radii: Vec<f32> = points.iter().map(|p| p.radius).collect();
    radii.dedup();
    for r in radii {
        let row: Vec<&DensityPoint> = points.iter().filter(|p| p.radius == r).collect();
        let d: Vec<f64> = row.iter().map(|p| p.stats.overlaps_per_particle).collect();
        out += &format!("| {r} | {:.3} |", median(&d));
        for c in &configs {
            match row.iter().find(|p| p.config == *c) {
                Some(p) => {
                    out += &format!(
                        " {:.1}% |",
                        100.0 * p.stats.missed as f64 / p.stats.pairs_true.max(1) as f64
                    )
                }
                None => out += " — |",
            }
        }
        out.push('\n');
    }
    out
}
