//! Stability on stiff and extreme cases (../shared/docs/numerics.md), on the GPU.
//!
//! - **Stiff spring** x'' = −ω² x, swept in ω·dt across 2 for each integrator: where it diverges
//!   (amplitude beyond [`DIVERGED`] times the start, or non-finite state counted on the GPU by
//!   [`NonFiniteCounter`]), the measured amplitude growth per step against the spectral radius of
//!   the scheme's amplification matrix, and for Latta's (symplectic) Euler and Verlet the
//!   boundary found by a 4-ary search against theory, ω·dt = 2. UberFlow's update has
//!   det = 1 + ω²dt²/2 > 1: it grows at every dt and has no boundary to find.
//! - **Stiff drag** a = −c v, swept in c·dt across 2: every scheme multiplies the velocity by
//!   1 − c·dt per step (Verlet's backward-difference velocity too), so all diverge beyond 2.
//! - **Extreme cases**, each with its documented [`Outcome`]: speeds of 10^6 m/s, half-float
//!   velocities overflowing at 65504 and stalling in free fall, coordinates of 10^7 m, dt = 0
//!   and 10^-9 s, non-finite scene values, identifiers beyond 2^24 (fp32) and 2^17 (fp24), and
//!   10^5 particles sorted into one cell. A case whose measured outcome differs from the
//!   documented one is flagged (`ok = false`): that is what the tests assert.

use std::path::Path;
use std::time::Instant;

use glam::{UVec3, Vec3};
use serde::Serialize;

use super::convergence::{integrator_name, INTEGRATORS};
use super::{Progress, ReportOptions, SectionOutput};
use crate::error::{Error, Result};
use crate::gl::{Context, Texture, TextureDesc, TextureFormat};
use crate::scene::{self, Integrator, SceneFile};
use crate::sim::nonfinite::{NonFiniteCount, NonFiniteCounter};
use crate::sim::ParticleSim;
use crate::sort::precision::{FloatFormat, R300};
use crate::sort::{KeyMode, SortOptions, Sorter, Variant};

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

/// Spectral radius of λ² − tr λ + det = 0.
fn spectral_radius(tr: f64, det: f64) -> f64 {
    let disc = tr * tr - 4.0 * det;
    if disc < 0.0 {
        det.sqrt()
    } else {
        let r = disc.sqrt();
        ((tr + r).abs()).max((tr - r).abs()) / 2.0
    }
}

/// Theory for the undamped spring at h = ω·dt: the amplification matrices of (x, v), or of
/// (x_n, x_{n-1}) for Verlet.
pub fn spring_theory(integrator: Integrator, h: f64) -> f64 {
    match integrator {
        // [[1 - h², h], [-h, 1]]: det 1, trace 2 - h².
        Integrator::Euler => spectral_radius(2.0 - h * h, 1.0),
        // [[1 - h²/2, h], [-h, 1]]: det 1 + h²/2, trace 2 - h²/2.
        Integrator::Uberflow => spectral_radius(2.0 - h * h / 2.0, 1.0 + h * h / 2.0),
        // x' = (2 - h²) x - x_prev: det 1, trace 2 - h².
        Integrator::Verlet => spectral_radius(2.0 - h * h, 1.0),
    }
}

/// Growth per step of an amplitude sampled as (step, value), starting from 1: from the envelopes
/// (maxima over eight windows) of the first and the last window whose samples are all finite and
/// within [10^-6, 10^30], or, when growth or decay is too fast for that, from the first and last
/// such samples. Below 10^-6 a decaying amplitude meets the float floor (a Verlet velocity is a
/// difference of positions; denormals are flushed) and stops telling the scheme's factor.
fn growth(samples: &[(u64, f64)], steps: u64) -> Option<f64> {
    let good = |a: f64| a.is_finite() && (1e-6..1e30).contains(&a);
    let windows = 8u64;
    let width = (steps / windows).max(1);
    let mut env = vec![None::<f64>; windows as usize];
    let mut broken = vec![false; windows as usize];
    for &(n, a) in samples {
        let w = (((n.max(1) - 1) / width) as usize).min(windows as usize - 1);
        if good(a) {
            env[w] = Some(env[w].map_or(a, |e: f64| e.max(a)));
        } else {
            broken[w] = true;
        }
    }
    let whole: Vec<(usize, f64)> = env
        .iter()
        .enumerate()
        .filter(|(w, e)| e.is_some() && !broken[*w])
        .map(|(w, e)| (w, e.unwrap_or(0.0)))
        .collect();
    if whole.len() >= 3 && whole[0].0 == 0 {
        let (first, last) = (whole[0], whole[whole.len() - 1]);
        if first.1 > 0.0 && last.1 > 0.0 {
            return Some((last.1 / first.1).powf(1.0 / ((last.0 - first.0) as f64 * width as f64)));
        }
    }
    let fine: Vec<&(u64, f64)> = samples.iter().filter(|s| good(s.1) && s.1 > 0.0).collect();
    match (fine.first(), fine.last()) {
        (Some(a), Some(b)) if b.0 > a.0 => Some((b.1 / a.1).powf(1.0 / (b.0 - a.0) as f64)),
        _ => None,
    }
}

/// Runs up to four spring particles at once (one particle type each, mass (dt/h)² with
/// stiffness 1), sampling |x| every 10 steps.
fn spring_rows(
    ctx: &Context,
    integrator: Integrator,
    hs: &[f64],
    steps: u64,
) -> Result<Vec<StiffRow>> {
    let masses: Vec<f64> = hs.iter().map(|h| (STIFF_DT / h).powi(2)).collect();
    let src = scene(
        integrator,
        [hs.len() as u32, 1],
        STIFF_DT,
        &masses,
        "[[forces.spring]]\nanchor = [0.0, 0.0, 0.0]\nstiffness = 1.0\n",
    );
    let particles: Vec<(Vec3, Vec3, u32)> = (0..hs.len())
        .map(|j| (Vec3::X, Vec3::ZERO, j as u32))
        .collect();
    let mut sim = start(ctx, &parse(&src)?, &particles)?;
    let amplitude = |p: &[f32], j: usize| -> f64 {
        let x = &p[j * 4..j * 4 + 3];
        (x.iter().map(|v| (*v as f64).powi(2)).sum::<f64>()).sqrt()
    };
    track(ctx, &mut sim, hs.len(), steps, |sim| {
        let p = sim.read_positions()?;
        Ok((0..hs.len()).map(|j| amplitude(&p, j)).collect())
    })
    .map(|tracks| {
        tracks
            .into_iter()
            .zip(hs)
            .map(|(t, &h)| StiffRow {
                case: "spring",
                integrator: integrator_name(integrator),
                h,
                stability: t.stability,
                diverged_at_step: t.diverged_at,
                growth_per_step: growth(&t.samples, steps),
                theory_growth_per_step: spring_theory(integrator, h),
                non_finite: t.non_finite,
            })
            .collect()
    })
}

struct Track {
    samples: Vec<(u64, f64)>,
    stability: Stability,
    diverged_at: Option<u64>,
    non_finite: u64,
}

/// Steps `sim`, sampling `measure` (one amplitude per particle, start amplitude 1) every step
/// for the first 50 steps and every 10th after; at the end the GPU counts non-finite state, and the count must agree with the
/// read-back (it is what the report shows).
fn track(
    ctx: &Context,
    sim: &mut ParticleSim,
    particles: usize,
    steps: u64,
    mut measure: impl FnMut(&ParticleSim) -> Result<Vec<f64>>,
) -> Result<Vec<Track>> {
    let mut tracks: Vec<Track> = (0..particles)
        .map(|_| Track {
            samples: Vec::new(),
            stability: Stability::Bounded,
            diverged_at: None,
            non_finite: 0,
        })
        .collect();
    let mut n = 0;
    while n < steps {
        // Every step at first (fast decays and growths), then every 10th.
        let every = if n < 50 { 1 } else { 10 };
        for _ in 0..every.min(steps - n) {
            sim.integrate_only();
            n += 1;
        }
        for (t, a) in tracks.iter_mut().zip(measure(sim)?) {
            t.samples.push((n, a));
            if t.diverged_at.is_none() && (a.is_nan() || a > DIVERGED) {
                t.diverged_at = Some(n);
                t.stability = Stability::Diverged;
            }
        }
    }
    let gpu = NonFiniteCounter::for_sim(ctx, sim)?.count_sim(sim)?;
    let velocities = match sim.velocities().or(sim.previous()) {
        Some(t) => t.read_f32()?,
        None => Vec::new(),
    };
    let positions = sim.read_positions()?;
    let cpu = NonFiniteCount::of_slices(&positions, &velocities);
    if gpu != cpu {
        return Err(Error::Gl(format!(
            "the GPU count of non-finite particles {gpu:?} differs from the read-back {cpu:?}"
        )));
    }
    for (j, t) in tracks.iter_mut().enumerate() {
        let one = NonFiniteCount::of_slices(
            &positions[j * 4..j * 4 + 4],
            velocities.get(j * 4..j * 4 + 4).unwrap_or(&[]),
        );
        t.non_finite = one.non_finite;
        if one.non_finite > 0 {
            t.stability = Stability::Diverged;
            t.diverged_at.get_or_insert(steps);
        }
    }
    ctx.check_error("stiff run")?;
    Ok(tracks)
}

/// One drag run: a particle at 1 m/s under damping c = h / dt, |v| sampled every 10 steps.
fn drag_row(ctx: &Context, integrator: Integrator, h: f64, steps: u64) -> Result<StiffRow> {
    let src = scene(
        integrator,
        [1, 1],
        STIFF_DT,
        &[1.0],
        &format!("[[forces.damping]]\nrate = {:?}\n", h / STIFF_DT),
    );
    let mut sim = start(ctx, &parse(&src)?, &[(Vec3::ZERO, Vec3::X, 0)])?;
    let t = track(ctx, &mut sim, 1, steps, |sim| {
        let v = sim.read_velocities()?;
        Ok(vec![(v[..3]
            .iter()
            .map(|x| (*x as f64).powi(2))
            .sum::<f64>())
        .sqrt()])
    })?
    .remove(0);
    Ok(StiffRow {
        case: "drag",
        integrator: integrator_name(integrator),
        h,
        stability: t.stability,
        diverged_at_step: t.diverged_at,
        growth_per_step: growth(&t.samples, steps),
        theory_growth_per_step: (1.0 - h).abs(),
        non_finite: t.non_finite,
    })
}

/// The stiff spring table and boundary search, and the stiff drag table.
pub fn stiff(
    ctx: &Context,
    opts: &StabilityOptions,
    progress: Progress<'_>,
) -> Result<(Vec<StiffRow>, Vec<Boundary>)> {
    let steps = opts.stiff_steps;
    let mut rows = Vec::new();
    let mut boundaries = Vec::new();
    for &integrator in &INTEGRATORS {
        let name = integrator_name(integrator);
        progress(&format!("stiff spring {name}"));
        let mut table = Vec::new();
        for chunk in SPRING_SWEEP.chunks(4) {
            table.extend(spring_rows(ctx, integrator, chunk, steps)?);
        }
        let verdict = |h: f64, t: &[StiffRow]| {
            t.iter()
                .find(|r| r.h == h)
                .map(|r| r.stability == Stability::Diverged)
        };
        let boundary = if integrator == Integrator::Uberflow {
            let first = table.iter().find(|r| r.stability == Stability::Diverged);
            Boundary {
                case: "spring",
                integrator: name,
                theory: None,
                measured: None,
                note: format!(
                    "no stability limit: det = 1 + (ω·dt)²/2 > 1, the energy grows at every dt \
                     (measured growth per step above 1 at every ω·dt of the sweep); beyond {DIVERGED:.0}x \
                     within {steps} steps from ω·dt = {}",
                    first.map_or("-".to_owned(), |r| r.h.to_string())
                ),
            }
        } else if verdict(1.9, &table) == Some(false) && verdict(2.1, &table) == Some(true) {
            let (mut lo, mut hi) = (1.9f64, 2.1f64);
            for _ in 0..opts.search_rounds {
                let hs: Vec<f64> = (1..=4).map(|j| lo + (hi - lo) * j as f64 / 5.0).collect();
                let found = spring_rows(ctx, integrator, &hs, steps)?;
                match found
                    .iter()
                    .position(|r| r.stability == Stability::Diverged)
                {
                    Some(0) => hi = hs[0],
                    Some(k) => (lo, hi) = (hs[k - 1], hs[k]),
                    None => lo = hs[3],
                }
            }
            Boundary {
                case: "spring",
                integrator: name,
                theory: Some(2.0),
                measured: Some([lo, hi]),
                note: format!(
                    "{}-round 4-ary search in [1.9, 2.1], {steps} steps each; theory: the \
                     amplification matrix has det 1 and trace 2 − (ω·dt)², within [−2, 2] up to \
                     ω·dt = 2",
                    opts.search_rounds
                ),
            }
        } else {
            Boundary {
                case: "spring",
                integrator: name,
                theory: Some(2.0),
                measured: None,
                note: "not bracketed by ω·dt = 1.9 (bounded) and 2.1 (diverged)".into(),
            }
        };
        boundaries.push(boundary);
        rows.extend(table);
    }
    for &integrator in &INTEGRATORS {
        let name = integrator_name(integrator);
        progress(&format!("stiff drag {name}"));
        let table: Vec<StiffRow> = DRAG_SWEEP
            .iter()
            .map(|&h| drag_row(ctx, integrator, h, steps))
            .collect::<Result<_>>()?;
        let lo = table
            .iter()
            .filter(|r| r.stability == Stability::Bounded)
            .map(|r| r.h)
            .fold(f64::NAN, f64::max);
        let hi = table
            .iter()
            .filter(|r| r.stability == Stability::Diverged)
            .map(|r| r.h)
            .fold(f64::NAN, f64::min);
        boundaries.push(Boundary {
            case: "drag",
            integrator: name,
            theory: Some(2.0),
            measured: (lo < hi).then_some([lo, hi]),
            note: "velocity × (1 − c·dt) per step for every scheme".into(),
        });
        rows.extend(table);
    }
    Ok((rows, boundaries))
}

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

fn count(ctx: &Context, sim: &ParticleSim) -> Result<NonFiniteCount> {
    NonFiniteCounter::for_sim(ctx, sim)?.count_sim(sim)
}

/// Indices of live particles with non-finite state in a read-back.
fn non_finite_ids(sim: &ParticleSim) -> Result<Vec<u64>> {
    let p = sim.read_positions()?;
    let v = sim.read_velocities()?;
    Ok((0..p.len() / 4)
        .filter(|&i| {
            NonFiniteCount::of_slices(&p[i * 4..i * 4 + 4], &v[i * 4..i * 4 + 4]).non_finite > 0
        })
        .map(|i| i as u64)
        .collect())
}

fn motion_scene(integrator: Integrator, n: u32, dt: f64, extra: &str, velocity: &str) -> String {
    scene(integrator, [n, 1], dt, &[1.0], extra)
        .replace("[particles]\n", &format!("[particles]\n{velocity}\n"))
}

/// Speeds of 10^6 m/s in fp32, for each integrator: finite, positions v·t to f32 rounding.
fn speed_1e6(ctx: &Context) -> Result<ExtremeCase> {
    let mut worst = 0.0f64;
    let mut bad = Vec::new();
    for &integrator in &INTEGRATORS {
        let s = parse(&motion_scene(integrator, 4, 1.0 / 64.0, "", ""))?;
        let v = Vec3::new(1e6, -1e6, 5e5);
        let mut sim = start(ctx, &s, &[(Vec3::ZERO, v, 0); 4])?;
        for _ in 0..64 {
            sim.integrate_only();
        }
        let c = count(ctx, &sim)?;
        bad.extend(non_finite_ids(&sim)?);
        let p = sim.read_positions()?;
        for k in 0..3 {
            worst = worst.max(((p[k] - v[k]) as f64 / 1e6).abs());
        }
        if !c.is_clean() {
            worst = f64::INFINITY;
        }
    }
    let measured = if bad.is_empty() && worst < 1e-6 {
        Outcome::Finite
    } else if bad.is_empty() {
        Outcome::Stalled
    } else {
        Outcome::NonFinite
    };
    Ok(case(
        "speed 1e6 m/s",
        "v = (1e6, -1e6, 5e5) m/s, fp32, dt = 1/64 s, 64 steps, each integrator",
        Outcome::Finite,
        measured,
        format!("largest relative position error after 1 s: {worst:.1e}"),
        bad,
    ))
}

/// How the driver converts fragment outputs to half floats (GL leaves it open).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum HalfRounding {
    Nearest,
    TowardZero,
    Unknown,
}

/// Half-float velocities overflow: from 65000 m/s under 3000 m/s², |v| passes 65504. Round to
/// nearest gives +inf (non-finite, counted on the GPU); rounding toward zero saturates at 65504
/// (finite but wrong): either way the particles are reported.
fn half_overflow(ctx: &Context, rounding: HalfRounding) -> Result<ExtremeCase> {
    let s = parse(&motion_scene(
        Integrator::Euler,
        16,
        1.0 / 64.0,
        "[[forces.gravity]]\nacceleration = [3000.0, 0.0, 0.0]\n",
        "velocity_format = \"rgba16f\"",
    ))?;
    let mut sim = start(
        ctx,
        &s,
        &[(Vec3::ZERO, Vec3::new(65000.0, 0.0, 0.0), 0); 16],
    )?;
    let mut first_inf = None;
    let mut largest = 0.0f32;
    for step in 1..=64u64 {
        sim.integrate_only();
        let v = sim.read_velocities()?[0];
        if v.is_finite() {
            largest = largest.max(v);
        } else if first_inf.is_none() {
            first_inf = Some(step);
        }
    }
    let c = count(ctx, &sim)?;
    let v = sim.read_velocities()?;
    let saturated: Vec<u64> = (0..16u64)
        .filter(|&i| {
            v[i as usize * 4..i as usize * 4 + 3]
                .iter()
                .any(|x| x.abs() == 65504.0)
        })
        .collect();
    let clamped = saturated.len();
    let (measured, ids) = if c.non_finite > 0 {
        (Outcome::NonFinite, non_finite_ids(&sim)?)
    } else if !saturated.is_empty() {
        (Outcome::Saturated, saturated)
    } else {
        (Outcome::Finite, Vec::new())
    };
    let expected = match rounding {
        HalfRounding::TowardZero => Outcome::Saturated,
        _ => Outcome::NonFinite,
    };
    Ok(case(
        "half-float overflow",
        "rgba16f velocities from 65000 m/s under 3000 m/s², dt = 1/64 s, 16 particles",
        expected,
        measured,
        format!(
            "largest finite stored speed {largest} m/s (true: {:.0} m/s after 1 s); velocity +inf \
             {}; GPU count: {} of {} live particles non-finite ({} with non-finite \
             positions); {} clamped at 65504. Expected from the driver's half-float rounding \
             ({rounding:?}, measured by the free fall): +inf with round to nearest, saturation \
             toward zero",
            65000.0 + 3000.0,
            first_inf.map_or("never".into(), |s| format!("at step {s}")),
            c.non_finite,
            c.live,
            c.non_finite_position,
            clamped,
        ),
        ids,
    ))
}

/// Half-float free fall at 60 Hz stalls where g·dt falls below half the float spacing: 512 m/s
/// with round-to-nearest, 256 m/s if the conversion truncates (GL leaves it open: detected).
fn half_free_fall(ctx: &Context) -> Result<(ExtremeCase, HalfRounding)> {
    let s = parse(&motion_scene(
        Integrator::Euler,
        1,
        1.0 / 60.0,
        "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n",
        "velocity_format = \"rgba16f\"",
    ))?;
    let mut sim = start(
        ctx,
        &s,
        &[(Vec3::new(0.0, 1e4, 0.0), Vec3::new(0.0, -200.0, 0.0), 0)],
    )?;
    let mut history = Vec::new();
    for _ in 0..1800 {
        sim.integrate_only();
        history.push(sim.read_velocities()?[1]);
    }
    let last = history[history.len() - 1];
    let stalled = history[history.len() - 200..].iter().all(|v| *v == last);
    let (rounding, mode) = match -last {
        512.0 => (HalfRounding::Nearest, "round to nearest"),
        256.0 => (HalfRounding::TowardZero, "truncation (toward zero)"),
        _ => (HalfRounding::Unknown, "an unexpected conversion"),
    };
    let c = case(
        "half-float free fall",
        "rgba16f velocities, g = 9.81 m/s², dt = 1/60 s, from -200 m/s, 1800 steps",
        Outcome::Stalled,
        if stalled {
            Outcome::Stalled
        } else {
            Outcome::Finite
        },
        format!(
            "speed stalls at {} m/s (true speed after 30 s: {:.0} m/s): the driver converts to \
             half floats by {mode}. Round to nearest stalls at 512 m/s, where g·dt = 0.16 m/s is \
             under half the spacing of 0.5 m/s; truncation at 256 m/s, where it is under the \
             spacing of 0.25 m/s",
            -last,
            200.0 + 9.81 * 30.0
        ),
        if stalled { vec![0] } else { vec![] },
    );
    Ok((c, rounding))
}

/// Large coordinates: at 0.1 m/s and 60 Hz a step is 1.7 mm; float spacing eats it.
fn large_coordinates(ctx: &Context) -> Result<ExtremeCase> {
    let xs = [1e3f32, 1e4, 1e5, 1e6, 1e7];
    let s = parse(&motion_scene(Integrator::Euler, 5, 1.0 / 60.0, "", ""))?;
    let particles: Vec<(Vec3, Vec3, u32)> = xs
        .iter()
        .map(|&x| (Vec3::new(x, 0.0, 0.0), Vec3::new(0.1, 0.0, 0.0), 0))
        .collect();
    let mut sim = start(ctx, &s, &particles)?;
    for _ in 0..600 {
        sim.integrate_only();
    }
    let c = count(ctx, &sim)?;
    let p = sim.read_positions()?;
    let moved: Vec<f64> = (0..xs.len())
        .map(|i| p[i * 4] as f64 - xs[i] as f64)
        .collect();
    let stalled: Vec<u64> = (0..xs.len())
        .filter(|&i| moved[i].abs() < 0.5)
        .map(|i| i as u64)
        .collect();
    let measured = if !c.is_clean() {
        Outcome::NonFinite
    } else if stalled.contains(&4) {
        Outcome::Stalled
    } else {
        Outcome::Finite
    };
    let detail = xs
        .iter()
        .zip(&moved)
        .map(|(x, m)| format!("x = {x:.0e}: moved {m:.3} m"))
        .collect::<Vec<_>>()
        .join("; ");
    Ok(case(
        "position 1e7 m",
        "v = 0.1 m/s at x = 1e3 … 1e7 m, fp32, dt = 1/60 s, 600 steps (1 m expected)",
        Outcome::Stalled,
        measured,
        format!(
            "{detail}. Motion stops where v·dt < half the float spacing, |x| ≥ 2^24·v·dt ≈ 2.8e4 m \
             here; stalled particles are listed"
        ),
        stalled,
    ))
}

/// dt = 0 is refused when the scene is checked.
fn dt_zero(ctx: &Context) -> Result<ExtremeCase> {
    let mut s = parse(&motion_scene(Integrator::Euler, 1, 1.0 / 60.0, "", ""))?;
    s.time.dt = 0.0;
    let (measured, detail) = match ParticleSim::new(ctx, &s, 1) {
        Err(e) if e.is_bad_input() => (Outcome::Refused, e.to_string()),
        Err(e) => (
            Outcome::Corrupted,
            format!("failed, but not as bad input: {e}"),
        ),
        Ok(_) => (Outcome::Finite, "accepted".into()),
    };
    Ok(case(
        "dt = 0",
        "a scene with time.dt = 0 (also `render --dt 0`)",
        Outcome::Refused,
        measured,
        detail,
        vec![],
    ))
}

/// dt = 1e-9: allowed and finite for every integrator (Verlet divides by dt), but motion at
/// |x| = 1 is below the float spacing.
fn dt_tiny(ctx: &Context) -> Result<ExtremeCase> {
    let mut bad = Vec::new();
    let mut stalled = Vec::new();
    let mut details = Vec::new();
    for &integrator in &INTEGRATORS {
        let s = parse(&motion_scene(
            integrator,
            2,
            1e-9,
            "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n",
            "",
        ))?;
        let mut sim = start(
            ctx,
            &s,
            &[
                (Vec3::new(1.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0), 0),
                (Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), 0),
            ],
        )?;
        for _ in 0..1000 {
            sim.integrate_only();
        }
        let c = count(ctx, &sim)?;
        if !c.is_clean() {
            bad.extend(non_finite_ids(&sim)?);
        }
        let p = sim.read_positions()?;
        let (far, near) = (p[0] as f64 - 1.0, p[4] as f64);
        if far.abs() < 0.5e-6 {
            stalled.push(0);
        }
        details.push(format!(
            "{}: moved {far:.1e} m at x = 1, {near:.2e} m at x = 0",
            integrator_name(integrator)
        ));
    }
    let measured = if !bad.is_empty() {
        Outcome::NonFinite
    } else if stalled.len() == INTEGRATORS.len() {
        Outcome::Stalled
    } else {
        Outcome::Finite
    };
    Ok(case(
        "dt = 1e-9",
        "dt = 1e-9 s, 1000 steps at 1 m/s under gravity, from x = 1 m and x = 0, each integrator",
        Outcome::Stalled,
        measured,
        format!(
            "allowed and finite; {} (expected 1e-6 m: v·dt is below half the spacing 6e-8 of \
             floats at 1 m)",
            details.join("; ")
        ),
        stalled,
    ))
}

/// Non-finite scene values are refused when the file is read.
fn scene_non_finite() -> ExtremeCase {
    let dt = 1.0 / 60.0;
    let base = motion_scene(Integrator::Euler, 1, dt, "", "");
    let tries = [
        base.replace(&format!("dt = {dt:?}"), "dt = nan"),
        base.clone() + "[[forces.gravity]]\nacceleration = [inf, 0.0, 0.0]\n",
    ];
    let refused: Vec<String> = tries
        .iter()
        .filter_map(|src| parse(src).err())
        .filter(|e| e.is_bad_input())
        .map(|e| e.to_string())
        .collect();
    case(
        "nan and inf in a scene",
        "time.dt = nan; gravity = [inf, 0, 0]",
        Outcome::Refused,
        if refused.len() == tries.len() {
            Outcome::Refused
        } else {
            Outcome::Finite
        },
        refused.join("; "),
        vec![],
    )
}

/// Identifiers beyond 2^24 in fp32: integers above 2^24 are not all floats.
fn ids_fp32() -> ExtremeCase {
    let f32_format = FloatFormat {
        mantissa_bits: 23,
        exponent_bits: 8,
    };
    let limit = f32_format.max_exact_integer();
    let ids: Vec<u64> = (limit - 16..limit + 16).collect();
    let colliding: Vec<u64> = ids
        .iter()
        .copied()
        .filter(|&i| (i as f32) as u64 != i)
        .collect();
    case(
        "ids beyond 2^24 (fp32)",
        "particle ids 2^24 - 16 … 2^24 + 15 as f32 (the key pass writes float(i))",
        Outcome::IdsCollide,
        if colliding.is_empty() {
            Outcome::IdsDistinct
        } else {
            Outcome::IdsCollide
        },
        format!(
            "{} of the 16 ids above 2^24 = {limit} round onto a neighbour (2^24 + 1 → 2^24): \
             checked on the CPU, a 2^25-particle state needs over 1 GiB of textures; `texflow \
             sort` refuses more than 2^24 keys (exit 2)",
            colliding.len()
        ),
        colliding,
    )
}

fn state_texture(ctx: &Context, w: u32, h: u32, data: &[f32]) -> Result<Texture> {
    let t = Texture::new(
        ctx,
        TextureDesc {
            width: w,
            height: h,
            format: TextureFormat::Rgba32F,
            label: "stability positions",
        },
    )?;
    t.upload_f32(data)?;
    Ok(t)
}

/// Identifiers under emulated 24-bit floats: the key pass's plain ids of 2^18 particles, and the
/// paper's enumeration.
fn ids_fp24(ctx: &Context) -> Result<[ExtremeCase; 2]> {
    let (w, h) = (512u32, 512u32);
    let n = (w * h) as usize;
    let positions = state_texture(ctx, w, h, &vec![1.0; n * 4])?;
    let mode = KeyMode::GridCell {
        origin: Vec3::ZERO,
        spacing: 1.0,
        dims: UVec3::splat(4),
    };
    let mut out = Vec::new();
    for table in [false, true] {
        let options = SortOptions {
            precision: Some(R300),
            id_table: table,
            ..SortOptions::default()
        };
        let mut sorter = Sorter::new(ctx, Variant::Fp, w, h, options)?;
        sorter.write_keys(&positions, n, &mode, false)?;
        let ids: Vec<f32> = sorter.read()?.iter().map(|e| e[1]).collect();
        let mut bits: Vec<u32> = ids.iter().map(|v| v.to_bits()).collect();
        bits.sort_unstable();
        bits.dedup();
        let distinct = bits.len();
        let colliding: Vec<u64> = if table {
            Vec::new()
        } else {
            (0..n as u64)
                .filter(|&i| ids[i as usize] as u64 != i)
                .collect()
        };
        out.push(if table {
            case(
                "ids 2^18 (fp24, paper's table)",
                "key pass of 512x512 particles, R300 floats, UberFlow's identifier enumeration",
                Outcome::IdsDistinct,
                if distinct == n {
                    Outcome::IdsDistinct
                } else {
                    Outcome::IdsCollide
                },
                format!("{distinct} distinct of {n}"),
                vec![],
            )
        } else {
            case(
                "ids beyond 2^17 (fp24)",
                "key pass of 512x512 particles, R300 floats (16 stored mantissa bits), plain ids",
                Outcome::IdsCollide,
                if distinct < n {
                    Outcome::IdsCollide
                } else {
                    Outcome::IdsDistinct
                },
                format!(
                    "{distinct} distinct of {n}; first wrong id {} (exact up to 2^17 = 131072: 16 \
                     stored bits and the hidden one; docs/sorting.md)",
                    colliding.first().map_or("-".into(), |i| i.to_string())
                ),
                colliding,
            )
        });
    }
    ctx.check_error("identifier experiment")?;
    let [a, b]: [ExtremeCase; 2] = out
        .try_into()
        .map_err(|_| Error::Gl("two identifier cases".into()))?;
    Ok([a, b])
}

/// `count` particles at one point sorted by grid cell (UberFlow's collision sort, packed
/// bitonic): every key that cell's, no NaN, the ids a permutation, in bounded time.
fn one_cell(ctx: &Context, count: usize) -> Result<ExtremeCase> {
    let n = count.next_power_of_two().max(4);
    let w = ((n as f64).sqrt() as u32).next_power_of_two().max(2);
    let h = (n as u32 / w).max(1);
    let mut data = vec![0f32; (w * h) as usize * 4];
    for p in data.chunks_exact_mut(4) {
        p.copy_from_slice(&[1.5, 1.5, 1.5, 1.0]);
    }
    let positions = state_texture(ctx, w, h, &data)?;
    let mode = KeyMode::GridCell {
        origin: Vec3::ZERO,
        spacing: 1.0,
        dims: UVec3::splat(4),
    };
    let t0 = Instant::now();
    let mut sorter = Sorter::new(ctx, Variant::Packed, w, h, SortOptions::default())?;
    sorter.write_keys(&positions, count, &mode, true)?;
    sorter.sort();
    let entries = sorter.read()?;
    let seconds = t0.elapsed().as_secs_f64();
    let cell = ((4 + 1) * 4 + 1) as f32;
    let mut seen = vec![0u32; count];
    let mut bad_keys = 0u64;
    let mut wrong: Vec<u64> = Vec::new();
    for (j, e) in entries[..count].iter().enumerate() {
        if e[0] != cell {
            bad_keys += 1;
            wrong.push(j as u64);
        }
        match seen.get_mut(e[1] as usize) {
            Some(s) if e[1] >= 0.0 && e[1].fract() == 0.0 => *s += 1,
            _ => wrong.push(j as u64),
        }
    }
    let lost: Vec<u64> = (0..count as u64)
        .filter(|&i| seen[i as usize] != 1)
        .collect();
    let padding_ok = entries[count..].iter().all(|e| e[0].is_nan());
    let ascending = entries[..count].windows(2).all(|p| p[0][1] < p[1][1]);
    wrong.extend(&lost);
    wrong.sort_unstable();
    wrong.dedup();
    let measured = if wrong.is_empty() && padding_ok {
        Outcome::Finite
    } else {
        Outcome::Corrupted
    };
    Ok(case(
        "1e5 particles in one cell",
        format!(
            "{count} particles at one point, grid-cell keys, packed bitonic sort of {w}x{h} entries"
        ),
        Outcome::Finite,
        measured,
        format!(
            "keys all {cell} (the cell) except {bad_keys}; ids a permutation: {} lost or \
             duplicated; ties in id order: {ascending}; padding after them: {padding_ok}; {} \
             passes in {seconds:.2} s",
            lost.len(),
            sorter.pass_count()
        ),
        wrong,
    ))
}

/// Every extreme case.
pub fn extremes(
    ctx: &Context,
    opts: &StabilityOptions,
    progress: Progress<'_>,
) -> Result<Vec<ExtremeCase>> {
    let mut v = Vec::new();
    progress("extreme speeds");
    v.push(speed_1e6(ctx)?);
    let (fall, rounding) = half_free_fall(ctx)?;
    v.push(half_overflow(ctx, rounding)?);
    v.push(fall);
    progress("extreme coordinates and steps");
    v.push(large_coordinates(ctx)?);
    v.push(dt_zero(ctx)?);
    v.push(dt_tiny(ctx)?);
    v.push(scene_non_finite());
    progress("identifiers");
    v.push(ids_fp32());
    v.extend(ids_fp24(ctx)?);
    progress("one cell");
    v.push(one_cell(ctx, opts.cell_particles)?);
    Ok(v)
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
