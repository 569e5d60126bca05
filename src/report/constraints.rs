//! The constraint relaxation's work-precision diagram: the built-in `cloth` hanging at rest
//! (after [`STEPS`] steps), for each scheme (Jacobi or Gauss-Seidel sets, each with and without
//! long-range attachments) and a range of iterations per step, the worst and mean relative edge
//! error against the fragment passes per step and against the GPU time of the relaxation per
//! step (docs/numerics.md, "Distance constraints").

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::plot::{self, Legend, Marker, Series};
use super::{num, Csv, Progress, ReportOptions, SectionOutput, Size};
use crate::bench::{median, Clock, PassTimer};
use crate::error::Result;
use crate::gl::Context;
use crate::scene::{self, RelaxScheme, SceneFile};
use crate::sim::constraints::set_count;
use crate::sim::{ParticleSim, Stage};

/// Steps before the error is measured: 5 s, the sheet hangs still.
pub const STEPS: usize = 600;

/// The schemes compared: scheme and whether the long-range attachments run.
pub const SCHEMES: [(RelaxScheme, bool); 4] = [
    (RelaxScheme::Jacobi, false),
    (RelaxScheme::Jacobi, true),
    (RelaxScheme::GaussSeidel, false),
    (RelaxScheme::GaussSeidel, true),
];

/// One scheme at one number of iterations.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// `jacobi` or `gauss-seidel`, `+ attachments` when they run.
    pub scheme: String,
    /// Iterations per step (the scene's `iterations`).
    pub iterations: u32,
    /// Fragment passes per step: iterations × (edge passes + the attachments' pass).
    pub passes: u32,
    /// Largest |(length - rest) / rest| over the constraints after [`STEPS`] steps.
    pub worst: f64,
    /// Mean of the same.
    pub mean: f64,
    /// Median GPU time of one step's relaxation, ms.
    pub gpu_ms: f64,
    /// `gpu_ms / passes`.
    pub gpu_ms_per_pass: f64,
}

/// The measured runs and where.
#[derive(Debug, Clone, Serialize)]
pub struct ConstraintReport {
    /// The renderer.
    pub device: String,
    /// The clock of the GPU times.
    pub clock: String,
    /// State texture side (the built-in cloth's 32, or smaller for the quick report).
    pub side: u32,
    /// Steps before the error is measured.
    pub steps: usize,
    /// Every scheme at every iteration count.
    pub rows: Vec<Row>,
}

/// The label of a scheme.
pub fn label(scheme: RelaxScheme, attachments: bool) -> String {
    match attachments {
        true => format!("{} + attachments", scheme.name()),
        false => scheme.name().to_owned(),
    }
}

/// The built-in cloth with `side`² particles, `scheme` and `iterations`.
fn cloth(side: u32, scheme: RelaxScheme, attachments: bool, iterations: u32) -> Result<SceneFile> {
    let mut s = scene::builtin("cloth")?;
    s.particles.size = [side, side];
    if let Some(c) = &mut s.constraints {
        // The same sheet: the spacing grows as the particles get fewer.
        c.spacing *= 32.0 / side as f32;
        c.scheme = scheme;
        c.attachments = attachments;
        c.iterations = iterations;
    }
    Ok(s)
}

/// One scheme at one iteration count: [`STEPS`] steps, the error, then `repeats` timed
/// relaxations.
pub fn run_row(
    ctx: &Context,
    timer: &PassTimer,
    side: u32,
    (scheme, attachments): (RelaxScheme, bool),
    iterations: u32,
    repeats: usize,
) -> Result<Row> {
    let s = cloth(side, scheme, attachments, iterations)?;
    let mut sim = ParticleSim::new(ctx, &s, 1)?;
    for _ in 0..STEPS {
        sim.step()?;
    }
    let layout = sim
        .constraint_layout()
        .expect("the cloth has constraints")
        .clone();
    let e = layout.error(&sim.read_positions()?);
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        times.push(crate::engine::timed(timer, || sim.run(Stage::Relax))?);
    }
    ctx.check_error("constraint report run")?;
    let edges = match scheme {
        RelaxScheme::Jacobi => 1,
        RelaxScheme::GaussSeidel => set_count(layout.kind),
    };
    let passes = iterations * (edges + attachments as u32);
    let gpu_ms = median(&times);
    Ok(Row {
        scheme: label(scheme, attachments),
        iterations,
        passes,
        worst: e.worst,
        mean: e.mean,
        gpu_ms,
        gpu_ms_per_pass: gpu_ms / passes as f64,
    })
}

/// Every scheme at every iteration count of `size`.
pub fn run(ctx: &Context, size: Size, progress: Progress<'_>) -> Result<ConstraintReport> {
    let clock = Clock::for_context(ctx);
    let timer = PassTimer::new(ctx, clock)?;
    let (side, iterations, repeats): (u32, &[u32], usize) = match size {
        Size::Full => (32, &[1, 2, 4, 8, 16, 32], 9),
        Size::Quick => (16, &[2, 8], 3),
    };
    let mut rows = Vec::new();
    for scheme in SCHEMES {
        for &n in iterations {
            progress(&format!("constraints {} × {n}", label(scheme.0, scheme.1)));
            rows.push(run_row(ctx, &timer, side, scheme, n, repeats)?);
        }
    }
    Ok(ConstraintReport {
        device: ctx.limits().renderer.clone(),
        clock: clock.name().to_owned(),
        side,
        steps: STEPS,
        rows,
    })
}

/// The table: one row per scheme and iteration count.
pub fn table(r: &ConstraintReport) -> String {
    let mut md = String::from(
        "| scheme | iterations | passes per step | worst edge error | mean edge error | GPU ms \
         per step | GPU ms per pass |\n| --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for row in &r.rows {
        md += &format!(
            "| {} | {} | {} | {:.2} % | {:.3} % | {:.3} | {:.4} |\n",
            row.scheme,
            row.iterations,
            row.passes,
            100.0 * row.worst,
            100.0 * row.mean,
            row.gpu_ms,
            row.gpu_ms_per_pass
        );
    }
    md
}

/// The markdown of `summary.md`.
pub fn markdown(r: &ConstraintReport) -> String {
    format!(
        "## Distance constraints: error against passes and GPU time (Latta §3.4.3)\n\n\
         The built-in `cloth` ({side}² particles) hanging at rest after {steps} steps: the worst \
         and mean |length - rest| / rest over its constraints, against the fragment passes per \
         step and the GPU time of one step's relaxation ({clock}), {device}. Plots: \
         constraints_passes.png, constraints_time.png.\n\n{table}",
        side = r.side,
        steps = r.steps,
        clock = r.clock,
        device = r.device,
        table = table(r)
    )
}

/// Per scheme, the worst and the mean error against `x` of a row.
fn curves(r: &ConstraintReport, x: &dyn Fn(&Row) -> f64) -> Vec<Series> {
    let colors = [(200, 60, 40), (200, 150, 40), (40, 100, 200), (40, 150, 60)];
    let mut out = Vec::new();
    for (k, (scheme, attachments)) in SCHEMES.into_iter().enumerate() {
        let name = label(scheme, attachments);
        let rows: Vec<&Row> = r.rows.iter().filter(|row| row.scheme == name).collect();
        for (what, marker, dashed, y) in [
            (
                "worst",
                Marker::Circle,
                false,
                (|row: &Row| row.worst) as fn(&Row) -> f64,
            ),
            ("mean", Marker::Triangle, true, |row: &Row| row.mean),
        ] {
            out.push(Series {
                label: format!("{name}: {what}"),
                points: rows.iter().map(|row| (x(row), y(row))).collect(),
                hollow: Vec::new(),
                color: colors[k],
                marker,
                dashed,
            });
        }
    }
    out
}

/// Writes `constraints.csv`, `constraints.json` and the two plots; returns the files.
pub fn write_files(r: &ConstraintReport, out: &Path) -> Result<Vec<PathBuf>> {
    let mut csv = Csv::new(&[
        "scheme",
        "iterations",
        "passes",
        "worst",
        "mean",
        "gpu_ms",
        "gpu_ms_per_pass",
    ]);
    for row in &r.rows {
        csv.row([
            row.scheme.clone(),
            row.iterations.to_string(),
            row.passes.to_string(),
            num(Some(row.worst)),
            num(Some(row.mean)),
            num(Some(row.gpu_ms)),
            num(Some(row.gpu_ms_per_pass)),
        ]);
    }
    let csv_path = out.join("constraints.csv");
    csv.write(&csv_path)?;
    let json_path = out.join("constraints.json");
    super::write_json(&json_path, r)?;
    let title = |what: &str| format!("{what}: {}² cloth at rest ({})", r.side, r.device);
    let unit = "relative edge error |L - r| / r";
    let p1 = out.join("constraints_passes.png");
    plot::loglog(
        &p1,
        &title("constraint error against passes"),
        ("fragment passes per step", unit),
        &curves(r, &|row| row.passes as f64),
        (900, 600),
        Legend::UpperRight,
    )?;
    let p2 = out.join("constraints_time.png");
    plot::loglog(
        &p2,
        &title("constraint error against GPU time"),
        (
            &format!("GPU time of the relaxation per step (ms, {})", r.clock),
            unit,
        ),
        &curves(r, &|row| row.gpu_ms),
        (900, 600),
        Legend::UpperRight,
    )?;
    Ok(vec![csv_path, json_path, p1, p2])
}

/// `texflow report all`'s constraints section.
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let r = run(ctx, opts.size, progress)?;
    Ok(SectionOutput {
        files: write_files(&r, out)?,
        markdown: markdown(&r),
        warnings: Vec::new(),
    })
}
