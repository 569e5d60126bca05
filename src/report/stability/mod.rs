//! Stability on stiff and extreme cases (docs/numerics.md), on the GPU.
//!
//! - **Stiff spring** x'' = −ω² x, swept in ω·dt across 2 for each integrator: where it diverges
//!   (amplitude beyond [`DIVERGED`] times the start, or non-finite state counted on the GPU by
//!   [`NonFiniteCounter`](crate::sim::nonfinite::NonFiniteCounter)), the measured amplitude
//!   growth per step against the spectral radius of the scheme's amplification matrix, and for
//!   Latta's (symplectic) Euler and Verlet the boundary found by a 4-ary search against theory,
//!   ω·dt = 2. UberFlow's update has
//!   det = 1 + ω²dt²/2 > 1: it grows at every dt and has no boundary to find.
//! - **Stiff drag** a = −c v, swept in c·dt across 2: every scheme multiplies the velocity by
//!   1 − c·dt per step (Verlet's backward-difference velocity too), so all diverge beyond 2.
//! - **Extreme cases**, each with its documented [`Outcome`]: speeds of 10^6 m/s, half-float
//!   velocities overflowing at 65504 and stalling in free fall, coordinates of 10^7 m, dt = 0
//!   and 10^-9 s, non-finite scene values, identifiers beyond 2^24 (fp32) and 2^17 (fp24), and
//!   10^5 particles sorted into one cell. A case whose measured outcome differs from the
//!   documented one is flagged (`ok = false`): that is what the tests assert.

use std::path::Path;

use glam::Vec3;
use serde::Serialize;

use super::convergence::integrator_name;
use super::{Progress, ReportOptions, SectionOutput};
use crate::error::Result;
use crate::gl::Context;
use crate::scene::{self, Integrator, SceneFile};
use crate::sim::ParticleSim;

// The stiff sweeps, the integration's extreme cases and the sort's: one file each; the types,
// the scenes they share, and the tables here.
mod extremes;
mod sort_cases;
mod stiff;

pub use extremes::extremes;
pub use stiff::{spring_theory, stiff};

/// An amplitude this many times the start counts as diverged.
pub const DIVERGED: f64 = 1e3;

/// Time step of the stiff sweeps (a power of two), s.
pub const STIFF_DT: f64 = 1.0 / 64.0;

/// ω·dt of the stiff-spring table (numerics.md's values, and beyond).
pub const SPRING_SWEEP: [f64; 8] = [0.05, 0.5, 1.0, 1.9, 1.99, 2.01, 2.1, 2.5];

/// c·dt of the stiff-drag table.
pub const DRAG_SWEEP: [f64; 6] = [0.5, 1.5, 1.9, 1.99, 2.01, 2.1];

/// Stable or not, within the run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Stability {
    /// Stayed within [`DIVERGED`] times its start and finite.
    Bounded,
    /// Grew beyond [`DIVERGED`] times its start, or became non-finite.
    Diverged,
}

/// One stiff run.
#[derive(Debug, Clone, Serialize)]
pub struct StiffRow {
    /// `spring` (h = ω·dt) or `drag` (h = c·dt).
    pub case: &'static str,
    /// Integrator.
    pub integrator: &'static str,
    /// ω·dt or c·dt.
    pub h: f64,
    /// Verdict.
    pub stability: Stability,
    /// First sampled step beyond [`DIVERGED`] or non-finite.
    pub diverged_at_step: Option<u64>,
    /// Measured growth of the amplitude (spring: |x| envelope; drag: |v|) per step.
    pub growth_per_step: Option<f64>,
    /// Theory: the spectral radius of the scheme's amplification matrix.
    pub theory_growth_per_step: f64,
    /// Live particles of this row with non-finite state at the end.
    pub non_finite: u64,
}

/// A stability boundary.
#[derive(Debug, Clone, Serialize)]
pub struct Boundary {
    /// `spring` or `drag`.
    pub case: &'static str,
    /// Integrator.
    pub integrator: &'static str,
    /// Where theory puts it (h), if the scheme has one.
    pub theory: Option<f64>,
    /// Measured bracket [last bounded, first diverged], if the sweep found one.
    pub measured: Option<[f64; 2]>,
    /// How it was found, or why there is none.
    pub note: String,
}

/// How an extreme case ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Outcome {
    /// Finite, and as accurate as the format allows.
    Finite,
    /// Finite, but the motion is lost to rounding (steps smaller than the float spacing).
    Stalled,
    /// Non-finite state, counted on the GPU and reported with the particles.
    NonFinite,
    /// Finite but clamped at the format's largest value (a half-float conversion that rounds
    /// toward zero saturates instead of overflowing): reported with the particles.
    Saturated,
    /// Refused at the boundary as bad input (a scene error, exit code 2 on the command line).
    Refused,
    /// Identifiers collide: particles would be duplicated and lost by a rearrangement.
    IdsCollide,
    /// Every identifier distinct.
    IdsDistinct,
    /// Lost, duplicated or NaN entries where none should be.
    Corrupted,
}

/// One extreme case.
#[derive(Debug, Clone, Serialize)]
pub struct ExtremeCase {
    /// Short name.
    pub name: &'static str,
    /// What is run.
    pub setup: String,
    /// The documented outcome.
    pub expected: Outcome,
    /// What happened.
    pub measured: Outcome,
    /// The numbers behind it.
    pub detail: String,
    /// Particles (or entries) concerned: non-finite, stalled, colliding.
    pub failing: u64,
    /// The first few of them (indices).
    pub failing_ids: Vec<u64>,
    /// `measured == expected`.
    pub ok: bool,
}

/// An extreme case, `ok` when it ended as documented; the first few failing ids kept.
fn case(
    name: &'static str,
    setup: impl Into<String>,
    expected: Outcome,
    measured: Outcome,
    detail: impl Into<String>,
    failing: Vec<u64>,
) -> ExtremeCase {
    ExtremeCase {
        name,
        setup: setup.into(),
        expected,
        measured,
        detail: detail.into(),
        failing: failing.len() as u64,
        failing_ids: {
            let mut ids = failing;
            ids.sort_unstable();
            ids.dedup();
            ids.truncate(8);
            ids
        },
        ok: measured == expected,
    }
}

/// The whole report.
#[derive(Debug, Clone, Serialize)]
pub struct StabilityReport {
    /// The GL renderer.
    pub device: String,
    /// Steps of each stiff run.
    pub stiff_steps: u64,
    /// The stiff runs.
    pub stiff: Vec<StiffRow>,
    /// Boundaries.
    pub boundaries: Vec<Boundary>,
    /// The extreme cases.
    pub extremes: Vec<ExtremeCase>,
}

/// How much to run.
#[derive(Debug, Clone, Copy)]
pub struct StabilityOptions {
    /// Steps of each stiff run.
    pub stiff_steps: u64,
    /// Rounds of the 4-ary boundary search (each narrows the bracket five-fold).
    pub search_rounds: usize,
    /// Particles sorted into one cell.
    pub cell_particles: usize,
}

impl Default for StabilityOptions {
    /// What the report runs (about 3 s on llvmpipe, so `--quick` runs it whole too).
    fn default() -> Self {
        StabilityOptions {
            stiff_steps: 2000,
            search_rounds: 3,
            cell_particles: 100_000,
        }
    }
}

/// A permanent-particle scene: `types` initial emitters with the given masses.
fn scene(integrator: Integrator, size: [u32; 2], dt: f64, masses: &[f64], extra: &str) -> String {
    let mut s = format!(
        "name = \"stability\"\nintegrator = \"{}\"\n[particles]\nsize = [{}, {}]\n\
         [time]\ndt = {dt:?}\n",
        integrator_name(integrator),
        size[0],
        size[1]
    );
    for m in masses {
        s += &format!(
            "[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\nmass = {m:?}\n"
        );
    }
    s + extra
}

/// Builds a sim and uploads particles (position, velocity, type); the other texels are dead.
fn start(ctx: &Context, s: &SceneFile, particles: &[(Vec3, Vec3, u32)]) -> Result<ParticleSim> {
    let mut sim = ParticleSim::new(ctx, s, 1)?;
    let n = (sim.size().x * sim.size().y) as usize;
    let mut pos = vec![f32::INFINITY; n * 4];
    let mut vel = vec![0f32; n * 4];
    let mut st = vec![0f32; n * 4];
    for i in 0..n {
        pos[i * 4 + 3] = 0.0;
    }
    for (i, (x, v, ty)) in particles.iter().enumerate() {
        pos[i * 4..i * 4 + 4].copy_from_slice(&x.extend(1.0).to_array());
        vel[i * 4..i * 4 + 3].copy_from_slice(&v.to_array());
        st[i * 4 + 1] = *ty as f32;
        st[i * 4 + 3] = 0.5;
    }
    sim.set_state(&pos, &vel, &st)?;
    Ok(sim)
}

fn parse(src: &str) -> Result<SceneFile> {
    scene::parse("stability", src)
}

/// Runs the whole report.
pub fn run(
    ctx: &Context,
    opts: &StabilityOptions,
    progress: Progress<'_>,
) -> Result<StabilityReport> {
    let (stiff, boundaries) = stiff(ctx, opts, progress)?;
    let extremes = extremes(ctx, opts, progress)?;
    Ok(StabilityReport {
        device: ctx.limits().renderer.clone(),
        stiff_steps: opts.stiff_steps,
        stiff,
        boundaries,
        extremes,
    })
}

fn opt(x: Option<f64>, digits: usize) -> String {
    x.map_or("-".into(), |v| format!("{v:.digits$}"))
}

/// The report as markdown tables.
pub fn table(r: &StabilityReport) -> String {
    let mut s = format!(
        "### Stiff cases ({} steps of dt = 1/64 s; diverged: amplitude beyond {DIVERGED:.0}x the \
         start, or non-finite)\n\n\
         | case | integrator | h | outcome | diverged at step | amplitude growth per step | theory | non-finite particles |\n\
         |---|---|---:|---|---:|---:|---:|---:|\n",
        r.stiff_steps
    );
    for row in &r.stiff {
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {:.4} | {} |\n",
            if row.case == "spring" {
                "spring (ω·dt)"
            } else {
                "drag (c·dt)"
            },
            row.integrator,
            row.h,
            match row.stability {
                Stability::Bounded => "bounded",
                Stability::Diverged => "diverged",
            },
            row.diverged_at_step.map_or("-".into(), |n| n.to_string()),
            opt(row.growth_per_step, 4),
            row.theory_growth_per_step,
            row.non_finite
        );
    }
    s += "\n### Stability boundaries\n\n| case | integrator | theory | measured | how |\n|---|---|---:|---|---|\n";
    for b in &r.boundaries {
        s += &format!(
            "| {} | {} | {} | {} | {} |\n",
            b.case,
            b.integrator,
            opt(b.theory, 1),
            b.measured
                .map_or("none".into(), |[lo, hi]| format!("{lo:.4} … {hi:.4}")),
            b.note.replace('|', "\\|")
        );
    }
    s += "\n### Extreme cases\n\n| case | expected | measured | ok | failing | detail |\n|---|---|---|---|---:|---|\n";
    let name = |o: Outcome| {
        serde_json::to_value(o)
            .ok()
            .and_then(|v| v.as_str().map(str::to_owned))
            .unwrap_or_default()
    };
    for c in &r.extremes {
        s += &format!(
            "| {} | {} | {} | {} | {} | {} |\n",
            c.name,
            name(c.expected),
            name(c.measured),
            if c.ok { "yes" } else { "NO" },
            c.failing,
            c.detail.replace('|', "\\|")
        );
    }
    s
}

/// One line per extreme case that did not end in its documented outcome.
pub fn warnings(r: &StabilityReport) -> Vec<String> {
    r.extremes
        .iter()
        .filter(|c| !c.ok)
        .map(|c| {
            format!(
                "extreme case `{}` ended {:?}, documented {:?}: {}",
                c.name, c.measured, c.expected, c.detail
            )
        })
        .collect()
}

/// `texflow report all`'s stability section: `stability.json` and `stability.md` (the same at
/// every report size: it takes seconds).
pub fn section(
    ctx: &Context,
    _opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let r = run(ctx, &StabilityOptions::default(), progress)?;
    let md = format!(
        "## Stability on stiff and extreme cases\n\nDevice: {}. Every case also in \
         `stability.json`.\n\n{}",
        r.device,
        table(&r)
    );
    let json = out.join("stability.json");
    super::write_json(&json, &r)?;
    let mdf = out.join("stability.md");
    super::write_atomic(&mdf, md.as_bytes())?;
    Ok(SectionOutput {
        files: vec![json, mdf],
        markdown: md,
        warnings: warnings(&r),
    })
}
