//! The fluid's error against run time: Martin & Moyce's dam break (a column of width a and
//! height 2a) run with `[fluid]`, swept over the time step, the smoothing length and the speed
//! of sound; per run the density error (largest and mean |ρ/ρ0 − 1|, largest compression) and
//! the surge front against Martin & Moyce (1952), beside the run time per simulated second
//! (docs/numerics.md). The density error's largest value is the free surface's kernel deficit;
//! the compression is what the speed of sound bounds, ~ (U / c)².

use std::path::{Path, PathBuf};

use crate::bench::Clock;
use crate::error::{Error, Result};
use crate::gl::{Context, PassTimer};
use crate::scene::{self, SceneFile};
use crate::sim::{ParticleSim, Simulation};

use super::plot::{loglog, Legend, Marker, Series};
use super::{num, Csv, Progress, ReportOptions, SectionOutput, Size};

/// Martin & Moyce (1952), Table 2: the surge front Z = z/a of a column of width a = 2¼ in and
/// height 2a (n² = 2) against T = t √(2g/a), up to T = 3.
pub const MARTIN_MOYCE: [(f64, f64); 13] = [
    (0.41, 1.11),
    (0.84, 1.22),
    (1.19, 1.44),
    (1.43, 1.67),
    (1.63, 1.89),
    (1.83, 2.11),
    (1.98, 2.33),
    (2.20, 2.56),
    (2.32, 2.78),
    (2.51, 3.00),
    (2.65, 3.22),
    (2.83, 3.44),
    (2.98, 3.67),
];

/// Martin & Moyce's column width a (m): 2¼ in.
pub const COLUMN: f32 = 0.05715;

/// One dam break: particles per column width, time step, smoothing length over spacing, speed
/// of sound, and the dimensionless end time T.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DamRun {
    /// Particles across the column's width a (the spacing is a / this).
    pub per_width: u32,
    /// Time step (s).
    pub dt: f32,
    /// Smoothing length h / Δx.
    pub h_ratio: f32,
    /// Speed of sound c (m/s).
    pub sound: f32,
    /// End time T = t √(2g/a).
    pub t_end: f64,
}

/// The dam break of `run` as a scene: the column against the left wall of a tank 5a long and
/// 2 Δx deep, plane colliders with the wall treatment, viscosity 0.05.
pub fn dam_scene(run: &DamRun) -> Result<SceneFile> {
    let a = COLUMN;
    let n = run.per_width;
    let dx = a / n as f32;
    let (w, d) = (5.0 * a, 2.0 * dx);
    // 2n × n × 2 particles in a square power-of-two texture.
    let side = (4 * n * n).isqrt().next_power_of_two();
    let side = if side * side < 4 * n * n {
        side * 2
    } else {
        side
    };
    let planes = [
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ([w, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, d], [0.0, 0.0, -1.0]),
    ];
    let planes: String = planes
        .iter()
        .map(|(p, n)| {
            format!("[[colliders.plane]]\npoint = {p:?}\nnormal = {n:?}\nresilience = 0.0\n")
        })
        .collect();
    let src = format!(
        "name = \"dam\"\nintegrator = \"euler\"\n[particles]\nsize = [{side}, {side}]\n\
         [time]\ndt = {dt}\n[[emitters.initial]]\nshape = \"box\"\ncenter = [{cx}, {a}, {dx}]\n\
         size = [{a}, {h2}, {d}]\ndirection = [0.0, -1.0, 0.0]\nspeed = [0.0, 0.0]\n\
         [[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n{planes}[fluid]\n\
         speed_of_sound = {c}\nviscosity = 0.05\nspacing = {dx}\nsmoothing = {h}\n\
         bounds = [[0.0, 0.0, 0.0], [{w}, {top}, {d}]]\n",
        dt = run.dt,
        cx = a / 2.0,
        h2 = 2.0 * a,
        c = run.sound,
        h = run.h_ratio * dx,
        top = 3.0 * a,
    );
    scene::parse("fluid report dam", &src)
}

/// What one run gave.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FluidRow {
    /// The swept setting: `dt`, `smoothing` or `sound`.
    pub sweep: String,
    /// The run.
    pub run: DamRun,
    /// Particles.
    pub particles: u64,
    /// Steps run.
    pub steps: u64,
    /// Largest |ρ/ρ0 − 1| over the samples (the free surface's deficit included).
    pub max_density_error: f64,
    /// Mean over the samples of the mean |ρ/ρ0 − 1|.
    pub mean_density_error: f64,
    /// Largest compression ρ/ρ0 − 1 over the samples.
    pub max_compression: f64,
    /// Largest |Z / Z_MM − 1| over Martin & Moyce's points up to the end time.
    pub front_error: f64,
    /// Martin & Moyce's points compared.
    pub front_points: usize,
    /// Run time of the steps per simulated second (ms/s), by the report's clock.
    pub ms_per_sim_second: f64,
    /// Searches that hit their bound (0 unless the search missed neighbours).
    pub truncated_searches: u64,
}

/// Runs `run`, sampling the density and the front at each of Martin & Moyce's times up to the
/// end (and at the end).
pub fn measure(ctx: &Context, sweep: &str, run: &DamRun) -> Result<FluidRow> {
    let s = dam_scene(run)?;
    let mut sim = ParticleSim::new(ctx, &s, 1)?;
    let timer = PassTimer::new(ctx, Clock::for_context(ctx))?;
    let a = COLUMN as f64;
    let scale = (2.0 * 9.81 / a).sqrt();
    let dx = a / run.per_width as f64;
    let mut row = FluidRow {
        sweep: sweep.into(),
        run: *run,
        particles: 0,
        steps: 0,
        max_density_error: 0.0,
        mean_density_error: 0.0,
        max_compression: 0.0,
        front_error: 0.0,
        front_points: 0,
        ms_per_sim_second: 0.0,
        truncated_searches: 0,
    };
    let (mut ms, mut samples) = (0.0, 0usize);
    let points = MARTIN_MOYCE.iter().filter(|p| p.0 <= run.t_end);
    let ends = points
        .map(|&(t, z)| (t, Some(z)))
        .chain([(run.t_end, None)]);
    for (t_ref, z_ref) in ends {
        while sim.time() * scale < t_ref {
            let mut r = Ok(());
            ms += timer.time(|| r = sim.step())?;
            r?;
            row.steps += 1;
        }
        let f = sim.fluid_stats()?.ok_or_else(|| {
            Error::InvalidInput("the dam break scene lost its [fluid] section".into())
        })?;
        row.particles = f.live;
        row.max_density_error = row.max_density_error.max(f.max_density_error);
        row.max_compression = row.max_compression.max(f.max_compression);
        row.mean_density_error += f.mean_density_error;
        samples += 1;
        if let Some(z_ref) = z_ref {
            let (x, _) = sim.read_state()?;
            let front = (x.chunks(4).filter(|p| p[3] > 0.0))
                .map(|p| p[0] as f64)
                .fold(0.0, f64::max)
                + dx / 2.0;
            row.front_error = row.front_error.max((front / a / z_ref - 1.0).abs());
            row.front_points += 1;
        }
    }
    row.mean_density_error /= samples as f64;
    row.ms_per_sim_second = ms / sim.time().max(f64::MIN_POSITIVE);
    row.truncated_searches = sim.truncated_searches()?;
    ctx.check_error("measuring the fluid")?;
    Ok(row)
}

/// The runs of a report size: the time step halved twice, then at the middle step the
/// smoothing length, then at the shortest step a speed of sound twice as high.
pub fn plan(size: Size) -> Vec<(&'static str, DamRun)> {
    let (per_width, t_end, dt0) = match size {
        Size::Quick => (8, 1.0, 1.6e-4),
        Size::Full => (16, 3.0, 8e-5),
    };
    let base = DamRun {
        per_width,
        dt: dt0,
        h_ratio: 1.0,
        sound: 15.0,
        t_end,
    };
    let mut runs: Vec<(&str, DamRun)> = [1.0, 0.5, 0.25]
        .iter()
        .map(|f| {
            (
                "dt",
                DamRun {
                    dt: dt0 * f,
                    ..base
                },
            )
        })
        .collect();
    for h_ratio in [1.25, 1.5] {
        let dt = dt0 * 0.5;
        runs.push((
            "smoothing",
            DamRun {
                dt,
                h_ratio,
                ..base
            },
        ));
    }
    let dt = dt0 * 0.25;
    runs.push((
        "sound",
        DamRun {
            dt,
            sound: 30.0,
            ..base
        },
    ));
    runs
}

/// Every run of `size`'s plan.
pub fn sweep(ctx: &Context, size: Size, progress: Progress<'_>) -> Result<Vec<FluidRow>> {
    let mut rows = Vec::new();
    for (sweep, run) in plan(size) {
        progress(&format!(
            "fluid: {sweep}, dt {:e} s, h {} dx, c {} m/s",
            run.dt, run.h_ratio, run.sound
        ));
        rows.push(measure(ctx, sweep, &run)?);
    }
    Ok(rows)
}

/// `fluid_error.csv`, `fluid_error.json` and the work-precision plot `fluid_error.png` (the dt
/// sweep).
pub fn write_files(rows: &[FluidRow], out: &Path) -> Result<Vec<PathBuf>> {
    let mut csv = Csv::new(&[
        "sweep",
        "dt_s",
        "h_over_dx",
        "sound_m_s",
        "particles",
        "steps",
        "max_density_error",
        "mean_density_error",
        "max_compression",
        "front_error",
        "ms_per_sim_second",
    ]);
    for r in rows {
        csv.row([
            r.sweep.clone(),
            num(Some(r.run.dt as f64)),
            num(Some(r.run.h_ratio as f64)),
            num(Some(r.run.sound as f64)),
            r.particles.to_string(),
            r.steps.to_string(),
            num(Some(r.max_density_error)),
            num(Some(r.mean_density_error)),
            num(Some(r.max_compression)),
            num(Some(r.front_error)),
            num(Some(r.ms_per_sim_second)),
        ]);
    }
    let (c, j, p) = (
        out.join("fluid_error.csv"),
        out.join("fluid_error.json"),
        out.join("fluid_error.png"),
    );
    csv.write(&c)?;
    super::write_json(&j, rows)?;
    // The work-precision curves: the dt sweep, one point per time step.
    let dt_rows: Vec<&FluidRow> = rows.iter().filter(|r| r.sweep == "dt").collect();
    let series = |label: &str, color, marker, y: fn(&FluidRow) -> f64| Series {
        label: label.into(),
        points: dt_rows
            .iter()
            .map(|r| (r.ms_per_sim_second, y(r)))
            .collect(),
        hollow: vec![false; dt_rows.len()],
        color,
        marker,
        dashed: false,
    };
    loglog(
        &p,
        "Dam break: error against run time (dt halved twice)",
        ("run time per simulated second (ms)", "error"),
        &[
            series("mean |ρ/ρ0 − 1|", (30, 90, 200), Marker::Circle, |r| {
                r.mean_density_error
            }),
            series(
                "largest compression",
                (200, 60, 40),
                Marker::Triangle,
                |r| r.max_compression,
            ),
            series(
                "front against Martin & Moyce",
                (40, 150, 60),
                Marker::Cross,
                |r| r.front_error,
            ),
        ],
        (720, 480),
        Legend::UpperRight,
    )?;
    Ok(vec![c, j, p])
}

/// The rows as markdown, under a `##` heading.
pub fn markdown(rows: &[FluidRow], size: Size, clock: Clock) -> String {
    let (n, t) = rows
        .first()
        .map_or((0, 0.0), |r| (r.particles, r.run.t_end));
    let mut md = format!(
        "## Fluid: error against run time\n\nMartin & Moyce's dam break (column a = 2¼ in, \
         height 2a) with `[fluid]`, {n} particles, to T = t √(2g/a) = {t}: the density error \
         sampled at Martin & Moyce's times and the end (largest and mean |ρ/ρ0 − 1|; the \
         largest is the free surface's kernel deficit), the largest compression, the largest \
         front error against their Table 2, and the steps' run time per simulated second \
         ({}){}; `fluid_error.csv`, `fluid_error.json`, `fluid_error.png`.\n\n\
         | sweep | dt (s) | h / Δx | c (m/s) | steps | max \\|ρ/ρ0 − 1\\| | mean \\|ρ/ρ0 − 1\\| \
         | max compression | front error | ms per simulated s |\n\
         | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
        clock.name(),
        if size == Size::Quick { ", quick" } else { "" }
    );
    for r in rows {
        md += &format!(
            "| {} | {:.2e} | {} | {} | {} | {:.4} | {:.5} | {:.5} | {:.1} % | {:.0} |\n",
            r.sweep,
            r.run.dt,
            r.run.h_ratio,
            r.run.sound,
            r.steps,
            r.max_density_error,
            r.mean_density_error,
            r.max_compression,
            100.0 * r.front_error,
            r.ms_per_sim_second
        );
    }
    md
}

/// The `fluid` section of `report all`.
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let rows = sweep(ctx, opts.size, progress)?;
    let warnings = (rows.iter())
        .filter(|r| r.truncated_searches > 0)
        .map(|r| {
            format!(
                "fluid report: {} searches hit their bound at dt {:e}, h {} dx: neighbours may \
                 be missing",
                r.truncated_searches, r.run.dt, r.run.h_ratio
            )
        })
        .collect();
    Ok(SectionOutput {
        files: write_files(&rows, out)?,
        markdown: markdown(&rows, opts.size, Clock::for_context(ctx)),
        warnings,
    })
}
