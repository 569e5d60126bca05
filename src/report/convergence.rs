//! Work-precision diagrams (../shared/docs/numerics.md): for each problem with an exact solution,
//! each integrator (Latta's Euler, UberFlow's update, Verlet) and each storage precision (fp32,
//! half-float velocities, emulated 24-bit floats), a sweep of time steps run on the GPU through
//! [`ParticleSim`]; the error at a fixed end time (or its maximum over the run) against the GPU
//! time per simulated second, and the observed convergence order from successive halvings.
//!
//! # Measurements the harness refuses
//!
//! - **Turning points.** A position error taken where the exact speed is small (x = ±1 of an
//!   oscillator) reads the phase error to second order and shows false orders. Every end time of a
//!   final-position measurement is checked against the exact speed there ([`TURNING_POINT`] of the
//!   largest speed on the path); a measurement at a turning point is an error, not a number.
//! - **The rounding floor.** Every run is repeated on the CPU by an `f64` twin of the same scheme
//!   (the integrators of `glsl/sim/integrate.frag` with the forces and the plane of the
//!   problems, without rounding). The difference between the GPU and the twin is what rounding
//!   and storage precision did; a point where it exceeds [`FLOOR_FRACTION`] of the error is at
//!   the floor and takes no part in the fit. A curve with fewer than two points above the floor
//!   has no order (status `floor`), however regular its numbers look.
//! - **Divergence.** Points with non-finite state (counted on the GPU by [`NonFiniteCounter`])
//!   are `diverged` and never fitted.
//! - **Large errors.** A point whose error exceeds [`LARGE_FRACTION`] of the problem's scale is
//!   outside the asymptotic range and not fitted either; a curve with no two such points left is
//!   `pre-asymptotic` (or `no convergence` if its errors do not fall at all).
//!
//! Orders are fitted on the longest run of consecutive valid points: successive orders
//! log(e_i / e_{i+1}) / log(dt_i / dt_{i+1}) and their least-squares slope. A spread of the
//! successive orders over [`ERRATIC_SPREAD`] marks the curve `erratic` (not in the asymptotic
//! range, or an error that depends on where in the step an event falls).

use std::f64::consts::PI;
use std::path::Path;

use glam::DVec3;
use serde::Serialize;

use super::plot::{self, Legend, Marker, Series};
use super::{num, Csv, Progress, ReportOptions, SectionOutput, Size};
use crate::bench::{median, Clock, PassTimer};
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::scene::file::{self, Integrator, SceneFile};
use crate::sim::nonfinite::NonFiniteCounter;
use crate::sim::ParticleSim;

/// Gravity of the problems, m/s².
pub const G: f64 = 9.81;

/// An end time is at a turning point when the exact speed there is below this fraction of the
/// largest speed on the path up to it.
pub const TURNING_POINT: f64 = 0.2;

/// A point is at the rounding floor when the GPU differs from the rounding-free twin by more
/// than this fraction of its error (which could then move a successive order by up to
/// log2(1.1 / 0.9) ≈ 0.3, and typically far less).
pub const FLOOR_FRACTION: f64 = 0.1;

/// A point is outside the asymptotic range when its error exceeds this fraction of the problem's
/// scale ([`Problem::scale`]): the leading error term no longer dominates.
pub const LARGE_FRACTION: f64 = 0.3;

/// Successive orders spreading more than this make a curve `erratic`.
pub const ERRATIC_SPREAD: f64 = 0.3;

/// `SKIN` of `glsl/sim/colliders.glsl`.
const SKIN: f64 = 1e-4;

/// The three integrators, in table order.
pub const INTEGRATORS: [Integrator; 3] =
    [Integrator::Euler, Integrator::Uberflow, Integrator::Verlet];

fn integrator_index(i: Integrator) -> usize {
    match i {
        Integrator::Euler => 0,
        Integrator::Uberflow => 1,
        Integrator::Verlet => 2,
    }
}

/// The scene-file name of an integrator.
pub fn integrator_name(i: Integrator) -> &'static str {
    match i {
        Integrator::Euler => "euler",
        Integrator::Uberflow => "uberflow",
        Integrator::Verlet => "verlet",
    }
}

/// How the state is stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum StatePrecision {
    /// Everything in RGBA32F.
    #[serde(rename = "fp32")]
    Fp32,
    /// Velocities in RGBA16F (Latta: half floats suffice); positions in RGBA32F.
    #[serde(rename = "fp16v")]
    Fp16Velocity,
    /// Everything written rounded to the ATI R300's 24-bit floats (16-bit mantissa, emulated).
    #[serde(rename = "fp24")]
    Fp24,
}

impl StatePrecision {
    /// All three, in table order.
    pub const ALL: [StatePrecision; 3] = [
        StatePrecision::Fp32,
        StatePrecision::Fp16Velocity,
        StatePrecision::Fp24,
    ];

    /// Short name (CSV, file names).
    pub fn name(self) -> &'static str {
        match self {
            StatePrecision::Fp32 => "fp32",
            StatePrecision::Fp16Velocity => "fp16v",
            StatePrecision::Fp24 => "fp24",
        }
    }

    /// Whether an integrator has anything to store this way: Verlet keeps no velocity texture.
    pub fn applies_to(self, i: Integrator) -> bool {
        !(self == StatePrecision::Fp16Velocity && i == Integrator::Verlet)
    }

    fn toml(self) -> &'static str {
        match self {
            StatePrecision::Fp32 => "",
            StatePrecision::Fp16Velocity => "velocity_format = \"rgba16f\"",
            StatePrecision::Fp24 => "precision = \"fp24\"",
        }
    }
}

/// What a problem's error is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// |x − x_exact| at the end time, largest over the particles (m).
    FinalPosition,
    /// |E − E0| / |E0|, largest over fixed sample times and particles.
    MaxEnergy,
    /// |apex_n − e^(2n) h0| over the first bounces, largest over particles (m).
    Apex,
}

/// A test problem with an exact solution. All particles of a run start alike, except for the
/// bouncing ball, whose drop heights spread over the state so that contacts fall at every place
/// in a step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Problem {
    /// A projectile under gravity with linear drag a = g − c v (`drag` = c in 1/s; 0 for none)
    /// from x0 = (0, 1, 0) m with v0 = (4, 8, 0) m/s; position error at `end` seconds.
    Drag {
        /// c, 1/s.
        drag: f64,
        /// End time, s.
        end: f64,
    },
    /// A harmonic oscillator x'' = −ω² x (spring to the origin) from x0 = (1, 0, 0) m at rest;
    /// position error at `end` seconds.
    Oscillator {
        /// ω, rad/s.
        omega: f64,
        /// End time, s.
        end: f64,
    },
    /// A Kepler orbit (GM = 1 m³/s², semi-major axis 1 m, period 2π s) of the given
    /// eccentricity, from periapsis; the largest relative energy error over `periods` periods,
    /// sampled every [`Problem::sample_interval`].
    Kepler {
        /// e.
        eccentricity: f64,
        /// Orbits to run.
        periods: f64,
    },
    /// A ball dropped at rest from h0 ∈ [1, 1.5] m on the plane y = 0 of resilience e (no
    /// friction); the largest error of the first `bounces` apex heights against e^(2n) h0.
    Bounce {
        /// e.
        resilience: f64,
        /// Apexes measured.
        bounces: u32,
    },
}

impl Problem {
    /// Short name (CSV, file names).
    pub fn name(&self) -> &'static str {
        match self {
            Problem::Drag { drag, .. } if *drag == 0.0 => "projectile",
            Problem::Drag { .. } => "drag",
            Problem::Oscillator { .. } => "oscillator",
            Problem::Kepler { .. } => "kepler",
            Problem::Bounce { .. } => "bounce",
        }
    }

    /// A line for plot titles and tables.
    pub fn title(&self) -> String {
        match *self {
            Problem::Drag { drag: 0.0, end } => {
                format!("projectile without drag, position error at t = {end} s")
            }
            Problem::Drag { drag, end } => {
                format!("projectile with linear drag c = {drag} /s, position error at t = {end} s")
            }
            Problem::Oscillator { omega, end } => {
                format!("harmonic oscillator ω = {omega} rad/s, position error at t = {end} s")
            }
            Problem::Kepler {
                eccentricity,
                periods,
            } => format!(
                "Kepler orbit e = {eccentricity}, largest energy error over {periods} periods"
            ),
            Problem::Bounce {
                resilience,
                bounces,
            } => {
                format!("bouncing ball e = {resilience}, error of the first {bounces} apex heights")
            }
        }
    }

    /// The error's kind.
    pub fn metric(&self) -> Metric {
        match self {
            Problem::Drag { .. } | Problem::Oscillator { .. } => Metric::FinalPosition,
            Problem::Kepler { .. } => Metric::MaxEnergy,
            Problem::Bounce { .. } => Metric::Apex,
        }
    }

    /// The error axis label, with its unit.
    pub fn error_label(&self) -> &'static str {
        match self.metric() {
            Metric::MaxEnergy => "relative energy error |E − E₀|/|E₀| (dimensionless)",
            _ => "error (m)",
        }
    }

    /// The order theory expects (../shared/docs/numerics.md, docs/pipeline.md); `None` where
    /// there is none to expect (exact schemes, Verlet's position constraints at a contact).
    pub fn expected_order(&self, i: Integrator) -> Option<f64> {
        use Integrator::*;
        match (self, i) {
            // Exact for constant acceleration: errors are rounding only.
            (Problem::Drag { drag, .. }, Uberflow | Verlet) if *drag == 0.0 => None,
            // Velocity-dependent force: Euler's velocity update (all), and Verlet's
            // backward-difference velocity, are first order.
            (Problem::Drag { .. }, _) => Some(1.0),
            (Problem::Oscillator { .. } | Problem::Kepler { .. }, Verlet) => Some(2.0),
            (Problem::Oscillator { .. } | Problem::Kepler { .. }, _) => Some(1.0),
            (Problem::Bounce { .. }, Verlet) => None,
            (Problem::Bounce { .. }, _) => Some(1.0),
        }
    }

    /// The forces and colliders in scene-file TOML.
    fn scene_toml(&self) -> String {
        match *self {
            Problem::Drag { drag, .. } => {
                let mut s = format!("[[forces.gravity]]\nacceleration = [0.0, {:?}, 0.0]\n", -G);
                if drag > 0.0 {
                    s += &format!("[[forces.damping]]\nrate = {drag:?}\n");
                }
                s
            }
            Problem::Oscillator { omega, .. } => format!(
                "[[forces.spring]]\nanchor = [0.0, 0.0, 0.0]\nstiffness = {:?}\n",
                omega * omega
            ),
            Problem::Kepler { .. } => format!(
                "[[forces.attractor]]\nposition = [0.0, 0.0, 0.0]\nstrength = 1.0\n\
                 softening = {KEPLER_SOFTENING:?}\n"
            ),
            Problem::Bounce { resilience, .. } => format!(
                "[[forces.gravity]]\nacceleration = [0.0, {:?}, 0.0]\n\
                 [[colliders.plane]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\n\
                 friction = 0.0\nresilience = {resilience:?}\n",
                -G
            ),
        }
    }

    /// The rounding-free twin of the scheme for this problem.
    fn twin(&self, integrator: Integrator, dt: f64) -> Twin {
        let mut t = Twin {
            integrator,
            dt,
            gravity: DVec3::ZERO,
            damping: 0.0,
            spring: 0.0,
            attractor: None,
            plane: None,
        };
        match *self {
            Problem::Drag { drag, .. } => {
                t.gravity = DVec3::new(0.0, -G, 0.0);
                t.damping = drag;
            }
            Problem::Oscillator { omega, .. } => t.spring = omega * omega,
            Problem::Kepler { .. } => t.attractor = Some(KEPLER_SOFTENING),
            Problem::Bounce { resilience, .. } => {
                t.gravity = DVec3::new(0.0, -G, 0.0);
                t.plane = Some(resilience);
            }
        }
        t
    }

    /// Initial position and velocity of particle `i` of `n`, as the GPU stores them (rounded to
    /// f32, so that twin and exact solution start where the GPU does).
    pub fn initial(&self, i: usize, n: usize) -> (DVec3, DVec3) {
        let (x, v) = match *self {
            Problem::Drag { .. } => (DVec3::new(0.0, 1.0, 0.0), DVec3::new(4.0, 8.0, 0.0)),
            Problem::Oscillator { .. } => (DVec3::X, DVec3::ZERO),
            Problem::Kepler {
                eccentricity: e, ..
            } => (
                DVec3::new(1.0 - e, 0.0, 0.0),
                DVec3::new(0.0, ((1.0 + e) / (1.0 - e)).sqrt(), 0.0),
            ),
            Problem::Bounce { .. } => (
                DVec3::new(0.0, 1.0 + 0.5 * (i as f64 + 0.5) / n as f64, 0.0),
                DVec3::ZERO,
            ),
        };
        (x.as_vec3().as_dvec3(), v.as_vec3().as_dvec3())
    }

    /// The end of a run, s.
    pub fn end_time(&self) -> f64 {
        match *self {
            Problem::Drag { end, .. } | Problem::Oscillator { end, .. } => end,
            Problem::Kepler { periods, .. } => periods * 2.0 * PI,
            Problem::Bounce { .. } => {
                let (t, rise) = self.apex_time(1.5, self.bounces());
                t + 0.5 * rise
            }
        }
    }

    fn bounces(&self) -> u32 {
        match self {
            Problem::Bounce { bounces, .. } => *bounces,
            _ => 0,
        }
    }

    /// Energy samples are taken at multiples of this time (the same for every dt of a sweep).
    pub fn sample_interval(&self) -> f64 {
        0.125
    }

    /// Exact position and velocity at `t` (final-position problems).
    pub fn exact(&self, x0: DVec3, v0: DVec3, t: f64) -> (DVec3, DVec3) {
        match *self {
            Problem::Drag { drag, .. } => {
                let g = DVec3::new(0.0, -G, 0.0);
                if drag == 0.0 {
                    (x0 + v0 * t + 0.5 * g * t * t, v0 + g * t)
                } else {
                    let vinf = g / drag;
                    let decay = (-drag * t).exp();
                    (
                        x0 + vinf * t + (v0 - vinf) * (1.0 - decay) / drag,
                        vinf + (v0 - vinf) * decay,
                    )
                }
            }
            Problem::Oscillator { omega: w, .. } => {
                let (s, c) = (w * t).sin_cos();
                (x0 * c + v0 / w * s, -x0 * w * s + v0 * c)
            }
            _ => (x0, v0),
        }
    }

    /// Energy per unit mass (Kepler: GM = 1, the same softened potential as the GPU's).
    pub fn energy(&self, x: DVec3, v: DVec3) -> f64 {
        let q = x.length_squared() + KEPLER_SOFTENING * KEPLER_SOFTENING;
        0.5 * v.length_squared() - 1.0 / q.sqrt()
    }

    /// Bounce: time of apex `n` (1-based) and its rise time, for a drop from `h0`.
    pub fn apex_time(&self, h0: f64, n: u32) -> (f64, f64) {
        let e = match self {
            Problem::Bounce { resilience, .. } => *resilience,
            _ => 1.0,
        };
        let fall = (2.0 * h0 / G).sqrt();
        // Fall, then up and down after each of the first n-1 bounces, then up after bounce n.
        let mut t = fall;
        for k in 1..n {
            t += 2.0 * e.powi(k as i32) * fall;
        }
        let rise = e.powi(n as i32) * fall;
        (t + rise, rise)
    }

    /// What errors are measured against to call them large: the extent of the exact path up to
    /// the end (final-position problems, m), 1 (relative energy), the lowest drop height (m).
    pub fn scale(&self) -> f64 {
        match self.metric() {
            Metric::FinalPosition => {
                let (x0, v0) = self.initial(0, 1);
                let t = self.end_time();
                (0..=2000)
                    .map(|k| (self.exact(x0, v0, t * k as f64 / 2000.0).0 - x0).length())
                    .fold(0.0, f64::max)
            }
            Metric::MaxEnergy => 1.0,
            Metric::Apex => self.initial(0, 1).0.y.min(1.0),
        }
    }

    /// Checks that a final-position error at `t` is not taken at a turning point: the exact
    /// speed there must be at least [`TURNING_POINT`] of the largest speed on the path.
    pub fn check_end_time(&self, t: f64) -> Result<()> {
        if self.metric() != Metric::FinalPosition {
            return Ok(());
        }
        let (x0, v0) = self.initial(0, 1);
        let speed = |s: f64| self.exact(x0, v0, s).1.length();
        let largest = (0..=2000)
            .map(|k| speed(t * k as f64 / 2000.0))
            .fold(0.0, f64::max);
        let here = speed(t);
        if here < TURNING_POINT * largest {
            return Err(Error::InvalidInput(format!(
                "{}: the end time {t} s is at a turning point (exact speed {here:.3} m/s, {:.0}% \
                 of the largest on the path, {largest:.3} m/s): a position error there measures \
                 the phase error to second order and gives false orders (docs/numerics.md); \
                 choose an end time where the particle moves",
                self.name(),
                100.0 * here / largest.max(f64::MIN_POSITIVE)
            )));
        }
        Ok(())
    }
}

/// Kepler's softening length (the scene format requires one above 0): far below rounding at the
/// orbit's smallest radius.
const KEPLER_SOFTENING: f64 = 1e-6;

/// The rounding-free `f64` twin of `glsl/sim/integrate.frag` for the problems' forces (gravity,
/// damping, a spring to the origin, an attractor of strength 1 at the origin) and a plane y = 0
/// without friction, for one particle of mass 1.
#[derive(Debug, Clone, Copy)]
struct Twin {
    integrator: Integrator,
    dt: f64,
    gravity: DVec3,
    damping: f64,
    spring: f64,
    attractor: Option<f64>,
    plane: Option<f64>,
}

/// Position and velocity (explicit integrators) or previous position (Verlet).
#[derive(Debug, Clone, Copy)]
struct TwinState {
    x: DVec3,
    v: DVec3,
    prev: DVec3,
}

impl Twin {
    fn accel(&self, x: DVec3, v: DVec3) -> DVec3 {
        let mut a = self.gravity - self.damping * v - self.spring * x;
        if let Some(soft) = self.attractor {
            let d = -x;
            let r = d.length();
            if r > 0.0 {
                let q = r * r + soft * soft;
                a += d / (q * q.sqrt());
            }
        }
        a
    }

    fn start(&self, x: DVec3, v: DVec3) -> TwinState {
        let dt = self.dt;
        TwinState {
            x,
            v,
            prev: x - v * dt + 0.5 * self.accel(x, v) * dt * dt,
        }
    }

    fn advance(&self, x: DVec3, v: DVec3, vb: DVec3) -> DVec3 {
        match self.integrator {
            Integrator::Uberflow => x + 0.5 * (v + vb) * self.dt,
            _ => x + vb * self.dt,
        }
    }

    fn step(&self, s: &mut TwinState) {
        let dt = self.dt;
        if self.integrator == Integrator::Verlet {
            let v = (s.x - s.prev) / dt;
            let mut xn = 2.0 * s.x - s.prev + self.accel(s.x, v) * dt * dt;
            if let Some(e) = self.plane {
                if xn.y < 0.0 {
                    xn.y -= (1.0 + e) * xn.y;
                }
                if xn.y < 0.0 {
                    xn.y = SKIN;
                }
            }
            s.prev = s.x;
            s.x = xn;
            return;
        }
        let mut x = s.x;
        let v = s.v;
        let mut vb = v + self.accel(x, v) * dt;
        let mut xb = self.advance(x, v, vb);
        if let Some(e) = self.plane {
            if xb.y < 0.0 {
                if x.y < 0.0 {
                    x.y = SKIN;
                    vb.y = vb.y.abs();
                } else if vb.y < 0.0 {
                    vb.y *= -e;
                }
                xb = self.advance(x, v, vb);
            }
            if xb.y < 0.0 {
                xb.y = SKIN;
                vb.y = vb.y.max(0.0);
            }
        }
        s.x = xb;
        s.v = vb;
    }
}

/// A sweep of time steps on one problem. As in the work-precision diagrams of ODE benchmark
/// suites, each method gets its own range of steps: where it is in its asymptotic range and
/// above its rounding floor.
#[derive(Debug, Clone, Serialize)]
pub struct Sweep {
    /// The problem.
    pub problem: Problem,
    /// Per integrator (in [`INTEGRATORS`] order): the coarsest time step is 2^-k s. Powers of
    /// two are exact in f32, so the end time is exactly n·dt.
    pub coarsest: [i32; 3],
    /// Time steps per integrator, each half the one before.
    pub count: usize,
    /// State side: side × side particles per run.
    pub side: u32,
    /// Timed batches per point (the median is reported).
    pub repeats: usize,
    /// Integration passes per timed batch.
    pub batch: usize,
    /// Refuse end times at turning points (off only to show what the check prevents).
    pub check_turning_points: bool,
}

impl Sweep {
    /// A sweep of `count` time steps from dt = 2^-`coarsest` s down, for every integrator.
    pub fn new(problem: Problem, coarsest: i32, count: usize, side: u32) -> Self {
        Sweep {
            problem,
            coarsest: [coarsest; 3],
            count,
            side,
            repeats: 9,
            batch: 10,
            check_turning_points: true,
        }
    }

    /// Starts `integrator`'s time steps at 2^-`coarsest` s.
    pub fn with_coarsest(mut self, integrator: Integrator, coarsest: i32) -> Self {
        self.coarsest[integrator_index(integrator)] = coarsest;
        self
    }

    /// The time steps of `integrator`, coarsest first.
    pub fn dts(&self, integrator: Integrator) -> Vec<f64> {
        let k = self.coarsest[integrator_index(integrator)];
        (0..self.count)
            .map(|j| 2f64.powi(-(k + j as i32)))
            .collect()
    }

    /// Steps to the end time at `dt`.
    pub fn steps(&self, dt: f64) -> u64 {
        (self.problem.end_time() / dt).round() as u64
    }

    /// Refuses the sweep if any of its end times is a turning point.
    pub fn check(&self) -> Result<()> {
        if self.count == 0 {
            return Err(Error::InvalidInput("a sweep needs time steps".into()));
        }
        if self.check_turning_points {
            for &i in &INTEGRATORS {
                for dt in self.dts(i) {
                    self.problem.check_end_time(self.steps(dt) as f64 * dt)?;
                }
            }
        }
        Ok(())
    }
}

/// The sweeps of the report. Ranges per integrator where the first choice would leave the
/// asymptotic range or hit the floor: on the Kepler orbit UberFlow's energy drifts by about
/// 3·dt·t (it needs dt eight times smaller than Euler for the same error) and Verlet reaches the
/// f32 floor (its velocity is a difference of positions) near 10^-4, so it starts coarser.
pub fn default_sweeps(size: Size) -> Vec<Sweep> {
    let (side, n, periods, repeats) = match size {
        Size::Full => (32, 5, 50.0, 9),
        Size::Quick => (16, 4, 2.0, 5),
    };
    let mut s = vec![
        // Verlet's backward-difference velocity is still pre-asymptotic at c·dt = 1/8.
        Sweep::new(
            Problem::Drag {
                drag: 1.0,
                end: 2.0,
            },
            3,
            n,
            side,
        )
        .with_coarsest(Integrator::Verlet, 4),
        Sweep::new(
            Problem::Oscillator {
                omega: 1.0,
                end: 2.0,
            },
            2,
            n,
            side,
        ),
        Sweep::new(
            Problem::Kepler {
                eccentricity: 0.6,
                periods,
            },
            6,
            3,
            side,
        )
        .with_coarsest(Integrator::Uberflow, 9)
        .with_coarsest(Integrator::Verlet, 4),
        Sweep::new(
            Problem::Bounce {
                resilience: 0.8,
                bounces: 3,
            },
            7,
            n,
            side,
        ),
    ];
    for w in &mut s {
        w.repeats = repeats;
    }
    s
}

/// Whether a point can be fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointStatus {
    /// Rounding is a small part of the error.
    Ok,
    /// Rounding or storage precision makes more than [`FLOOR_FRACTION`] of the error.
    Floor,
    /// The error exceeds [`LARGE_FRACTION`] of the problem's scale.
    Large,
    /// Non-finite state or error.
    Diverged,
}

/// One run: one time step.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// Time step, s.
    pub dt: f64,
    /// Steps to the end time.
    pub steps: u64,
    /// The GPU's error against the exact solution.
    pub error: f64,
    /// The error of the rounding-free twin of the scheme (the truncation error alone).
    pub scheme_error: f64,
    /// What rounding and storage did, in the error's unit: the largest difference between the
    /// GPU's particles (or energy samples) and the twin's; for the bouncing ball, whose contacts
    /// are decisions that rounding can move by a step, the difference of the two errors.
    pub deviation: f64,
    /// Fit or not.
    pub status: PointStatus,
    /// Median GPU time of one integration pass, ms.
    pub gpu_ms_per_step: f64,
    /// GPU time per simulated second, ms (`gpu_ms_per_step / dt`).
    pub gpu_ms_per_sim_s: f64,
    /// Live particles with non-finite state at the end (GPU count).
    pub non_finite: u64,
}

/// The verdict on a curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveStatus {
    /// An order was measured.
    Measured,
    /// Measured, but successive orders spread by more than [`ERRATIC_SPREAD`].
    Erratic,
    /// Errors do not fall with dt (slope under 0.3).
    NoConvergence,
    /// Fewer than two points above the rounding floor: no order.
    Floor,
    /// Fewer than two points with errors small enough for the asymptotic range: no order.
    PreAsymptotic,
    /// Fewer than two finite points.
    Diverged,
}

impl CurveStatus {
    /// Name in tables.
    pub fn name(self) -> &'static str {
        match self {
            CurveStatus::Measured => "measured",
            CurveStatus::Erratic => "erratic",
            CurveStatus::NoConvergence => "no convergence",
            CurveStatus::Floor => "rounding floor",
            CurveStatus::PreAsymptotic => "pre-asymptotic",
            CurveStatus::Diverged => "diverged",
        }
    }
}

/// The order fitted on a curve.
#[derive(Debug, Clone, Serialize)]
pub struct Fit {
    /// Least-squares slope of log error against log dt on the valid points.
    pub order: Option<f64>,
    /// Orders of successive halvings among the valid points.
    pub successive: Vec<f64>,
    /// Indices of the points fitted (the longest run of consecutive valid points).
    pub fitted: Vec<usize>,
    /// Verdict.
    pub status: CurveStatus,
}

/// Fits the order of `points` (coarsest dt first).
pub fn fit(points: &[Point]) -> Fit {
    // The longest run of consecutive valid points (the first of equal length).
    let mut best: Vec<usize> = Vec::new();
    let mut run: Vec<usize> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        if p.status == PointStatus::Ok {
            run.push(i);
            if run.len() > best.len() {
                best = run.clone();
            }
        } else {
            run.clear();
        }
    }
    let successive: Vec<f64> = best
        .windows(2)
        .map(|w| {
            let (a, b) = (&points[w[0]], &points[w[1]]);
            (a.error / b.error).ln() / (a.dt / b.dt).ln()
        })
        .collect();
    let slope = |idx: &[usize]| {
        let xs: Vec<f64> = idx.iter().map(|&i| points[i].dt.ln()).collect();
        let ys: Vec<f64> = idx.iter().map(|&i| points[i].error.ln()).collect();
        let n = xs.len() as f64;
        let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
        let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
        sxy / sxx
    };
    let order = (best.len() >= 2).then(|| slope(&best));
    let finite: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].status != PointStatus::Diverged)
        .collect();
    let floor = points.iter().any(|p| p.status == PointStatus::Floor);
    let spread = successive.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - successive.iter().copied().fold(f64::INFINITY, f64::min);
    let status = match order {
        None if finite.len() < 2 => CurveStatus::Diverged,
        None if floor => CurveStatus::Floor,
        // Only large errors: falling (pre-asymptotic) or not at all.
        None if slope(&finite) < 0.3 => CurveStatus::NoConvergence,
        None => CurveStatus::PreAsymptotic,
        Some(p) if p < 0.3 => CurveStatus::NoConvergence,
        Some(_) if spread > ERRATIC_SPREAD => CurveStatus::Erratic,
        Some(_) => CurveStatus::Measured,
    };
    Fit {
        order,
        successive,
        fitted: best,
        status,
    }
}

/// One integrator and precision over a sweep.
#[derive(Debug, Clone, Serialize)]
pub struct Curve {
    /// The problem's name.
    pub problem: String,
    /// Integrator.
    pub integrator: &'static str,
    /// Storage precision.
    pub precision: StatePrecision,
    /// Order theory expects.
    pub expected: Option<f64>,
    /// Points, coarsest dt first.
    pub points: Vec<Point>,
    /// The fit.
    pub fit: Fit,
}

impl Curve {
    /// Whether the measured order matches the expected one: status `measured` and every
    /// successive order within `tolerance`.
    pub fn matches_expected(&self, tolerance: f64) -> bool {
        match self.expected {
            Some(p) => {
                self.fit.status == CurveStatus::Measured
                    && self
                        .fit
                        .successive
                        .iter()
                        .all(|o| (o - p).abs() <= tolerance)
            }
            None => false,
        }
    }
}

fn scene(
    problem: &Problem,
    integrator: Integrator,
    precision: StatePrecision,
    dt: f64,
    side: u32,
) -> Result<SceneFile> {
    let name = format!("convergence-{}", problem.name());
    let src = format!(
        "name = \"{name}\"\nintegrator = \"{}\"\n[particles]\nsize = [{side}, {side}]\n{}\n\
         [time]\ndt = {dt:?}\n[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\n\
         speed = [0.0, 0.0]\n{}",
        integrator_name(integrator),
        precision.toml(),
        problem.scene_toml()
    );
    file::parse(&name, &src)
}

fn xyz(v: &[f32]) -> Vec<DVec3> {
    v.chunks_exact(4)
        .map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64))
        .collect()
}

/// Velocities for the energy: the velocity texture, or for Verlet the central difference
/// (x_{n+1} − x_{n−1}) / 2dt, second order (one extra step, taken here).
fn sample_state(sim: &mut ParticleSim, dt: f64) -> Result<(Vec<DVec3>, Vec<DVec3>)> {
    let x = xyz(&sim.read_positions()?);
    if let Some(v) = sim.velocities() {
        return Ok((x, xyz(&v.read_f32()?)));
    }
    let prev = xyz(&sim.previous().expect("Verlet").read_f32()?);
    sim.integrate_only();
    let next = xyz(&sim.read_positions()?);
    let v = next
        .iter()
        .zip(&prev)
        .map(|(a, b)| (*a - *b) / (2.0 * dt))
        .collect();
    Ok((x, v))
}

fn twin_sample(t: &Twin, s: &mut TwinState) -> (DVec3, DVec3) {
    if t.integrator != Integrator::Verlet {
        return (s.x, s.v);
    }
    let (x, prev) = (s.x, s.prev);
    t.step(s);
    (x, (s.x - prev) / (2.0 * t.dt))
}

fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Runs one point of a curve.
pub fn run_point(
    ctx: &Context,
    sweep: &Sweep,
    integrator: Integrator,
    precision: StatePrecision,
    dt: f64,
    timer: &PassTimer,
) -> Result<Point> {
    let problem = &sweep.problem;
    let s = scene(problem, integrator, precision, dt, sweep.side)?;
    let mut sim = ParticleSim::new(ctx, &s, 1)?;
    let n = (sweep.side * sweep.side) as usize;
    let ics: Vec<(DVec3, DVec3)> = (0..n).map(|i| problem.initial(i, n)).collect();
    let mut pos = vec![0f32; n * 4];
    let mut vel = vec![0f32; n * 4];
    let mut st = vec![0f32; n * 4];
    for (i, (x, v)) in ics.iter().enumerate() {
        pos[i * 4..i * 4 + 4].copy_from_slice(&x.as_vec3().extend(1.0).to_array());
        vel[i * 4..i * 4 + 3].copy_from_slice(&v.as_vec3().to_array());
        st[i * 4 + 3] = 0.5;
    }
    sim.set_state(&pos, &vel, &st)?;
    let twin = problem.twin(integrator, dt);
    // Particles start alike except in the bouncing ball: twin the distinct ones only.
    let distinct = if problem.metric() == Metric::Apex {
        n
    } else {
        1
    };
    let mut tw: Vec<TwinState> = ics[..distinct]
        .iter()
        .map(|(x, v)| twin.start(*x, *v))
        .collect();
    let which = |i: usize| if distinct == 1 { 0 } else { i };
    let steps = sweep.steps(dt);
    let end = steps as f64 * dt;
    let (mut error, mut scheme_error, mut deviation) = (0.0f64, 0.0f64, 0.0f64);
    match problem.metric() {
        Metric::FinalPosition => {
            for _ in 0..steps {
                sim.integrate_only();
            }
            for _ in 0..steps {
                for t in &mut tw {
                    twin.step(t);
                }
            }
            let x = xyz(&sim.read_positions()?);
            let (x0, v0) = ics[0];
            let exact = problem.exact(x0, v0, end).0;
            scheme_error = (tw[0].x - exact).length();
            for p in &x {
                error = nan_max(error, (*p - exact).length());
                deviation = nan_max(deviation, (*p - tw[0].x).length());
            }
        }
        Metric::MaxEnergy => {
            let stride = ((problem.sample_interval() / dt).round() as u64).max(1);
            let e0 = problem.energy(ics[0].0, ics[0].1);
            let mut n_done = 0u64;
            let mut sample = stride;
            while sample <= steps {
                while n_done < sample {
                    sim.integrate_only();
                    twin.step(&mut tw[0]);
                    n_done += 1;
                }
                let (x, v) = sample_state(&mut sim, dt)?;
                let (tx, tv) = twin_sample(&twin, &mut tw[0]);
                if integrator == Integrator::Verlet {
                    n_done += 1;
                }
                let et = problem.energy(tx, tv);
                scheme_error = scheme_error.max(((et - e0) / e0).abs());
                for (p, u) in x.iter().zip(&v) {
                    let e = problem.energy(*p, *u);
                    error = nan_max(error, ((e - e0) / e0).abs());
                    deviation = nan_max(deviation, ((e - et) / e0).abs());
                }
                sample += stride;
            }
        }
        Metric::Apex => {
            let bounces = problem.bounces();
            let windows: Vec<Vec<(f64, f64)>> = ics
                .iter()
                .map(|(x, _)| {
                    (1..=bounces)
                        .map(|k| {
                            let (t, rise) = problem.apex_time(x.y, k);
                            (t - 0.5 * rise, t + 0.5 * rise)
                        })
                        .collect()
                })
                .collect();
            let mut apex = vec![vec![f64::NEG_INFINITY; bounces as usize]; n];
            let mut apex_twin = apex.clone();
            for step in 1..=steps {
                sim.integrate_only();
                for t in &mut tw {
                    twin.step(t);
                }
                let t = step as f64 * dt;
                let y: Vec<f32> = sim.read_positions()?;
                for i in 0..n {
                    for (k, w) in windows[i].iter().enumerate() {
                        if t >= w.0 && t <= w.1 {
                            apex[i][k] = nan_max(apex[i][k], y[i * 4 + 1] as f64);
                            apex_twin[i][k] = apex_twin[i][k].max(tw[i].x.y);
                        }
                    }
                }
            }
            let e = match problem {
                Problem::Bounce { resilience, .. } => *resilience,
                _ => 1.0,
            };
            for i in 0..n {
                let h0 = ics[i].0.y;
                for k in 0..bounces as usize {
                    let exact = e.powi(2 * (k as i32 + 1)) * h0;
                    error = nan_max(error, (apex[i][k] - exact).abs());
                    scheme_error = scheme_error.max((apex_twin[which(i)][k] - exact).abs());
                }
            }
            // Contacts are decisions: rounding can move one into the next step and change a
            // particle's bounce by O(dt) without changing the statistics, so the measured error
            // is compared with the scheme's, not particle by particle.
            deviation = (error - scheme_error).abs();
        }
    }
    let counter = NonFiniteCounter::for_sim(ctx, &sim)?;
    let non_finite = counter.count_sim(&sim)?.non_finite;
    let mut times = Vec::with_capacity(sweep.repeats);
    for _ in 0..sweep.repeats {
        let ms = timer.time(|| {
            for _ in 0..sweep.batch {
                sim.integrate_only();
            }
        })?;
        times.push(ms / sweep.batch as f64);
    }
    ctx.check_error("convergence run")?;
    let ms = median(&times);
    let status = if non_finite > 0 || !error.is_finite() {
        PointStatus::Diverged
    } else if deviation > FLOOR_FRACTION * error {
        PointStatus::Floor
    } else if error > LARGE_FRACTION * problem.scale() {
        PointStatus::Large
    } else {
        PointStatus::Ok
    };
    Ok(Point {
        dt,
        steps,
        error,
        scheme_error,
        deviation,
        status,
        gpu_ms_per_step: ms,
        gpu_ms_per_sim_s: ms / dt,
        non_finite,
    })
}

/// Runs one curve: every dt of `sweep` for one integrator and precision. Refuses sweeps whose
/// measurement would be meaningless (see the module documentation).
pub fn run_curve(
    ctx: &Context,
    sweep: &Sweep,
    integrator: Integrator,
    precision: StatePrecision,
    timer: &PassTimer,
) -> Result<Curve> {
    sweep.check()?;
    if !precision.applies_to(integrator) {
        return Err(Error::InvalidInput(format!(
            "{} keeps no velocity texture: {} does not apply",
            integrator_name(integrator),
            precision.name()
        )));
    }
    let points = sweep
        .dts(integrator)
        .into_iter()
        .map(|dt| run_point(ctx, sweep, integrator, precision, dt, timer))
        .collect::<Result<Vec<_>>>()?;
    let fit = fit(&points);
    Ok(Curve {
        problem: sweep.problem.name().to_owned(),
        integrator: integrator_name(integrator),
        precision,
        expected: sweep.problem.expected_order(integrator),
        points,
        fit,
    })
}

/// The whole measurement.
#[derive(Debug, Clone, Serialize)]
pub struct ConvergenceReport {
    /// The GL renderer.
    pub device: String,
    /// How passes were timed.
    pub clock: Clock,
    /// The sweeps.
    pub sweeps: Vec<Sweep>,
    /// Every curve.
    pub curves: Vec<Curve>,
}

/// Runs every sweep for every integrator and precision that applies.
pub fn run(
    ctx: &Context,
    sweeps: &[Sweep],
    precisions: &[StatePrecision],
    progress: Progress<'_>,
) -> Result<ConvergenceReport> {
    let timer = PassTimer::new(ctx, Clock::for_context(ctx))?;
    let mut curves = Vec::new();
    for sweep in sweeps {
        sweep.check()?;
        for &integrator in &INTEGRATORS {
            for &precision in precisions {
                if !precision.applies_to(integrator) {
                    continue;
                }
                progress(&format!(
                    "{} {} {}",
                    sweep.problem.name(),
                    integrator_name(integrator),
                    precision.name()
                ));
                curves.push(run_curve(ctx, sweep, integrator, precision, &timer)?);
            }
        }
    }
    Ok(ConvergenceReport {
        device: ctx.limits().renderer.clone(),
        clock: timer.clock(),
        sweeps: sweeps.to_vec(),
        curves,
    })
}

fn fmt_order(o: Option<f64>) -> String {
    // `+ 0.0` turns a -0.00 into 0.00.
    o.map_or("-".into(), |p| {
        format!("{:.2}", (p * 100.0).round() / 100.0 + 0.0)
    })
}

/// The orders as a markdown table.
pub fn table(r: &ConvergenceReport) -> String {
    let mut s = String::from(
        "| problem | integrator | precision | expected | observed | successive orders | status | error range |\n\
         |---|---|---|---:|---:|---|---|---|\n",
    );
    for c in &r.curves {
        let errs: Vec<f64> = c.points.iter().map(|p| p.error).collect();
        let lo = errs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = errs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.1e} … {:.1e} |\n",
            c.problem,
            c.integrator,
            c.precision.name(),
            fmt_order(c.expected),
            fmt_order(c.fit.order),
            if c.fit.successive.is_empty() {
                "-".into()
            } else {
                c.fit
                    .successive
                    .iter()
                    .map(|o| fmt_order(Some(*o)))
                    .collect::<Vec<_>>()
                    .join(", ")
            },
            c.fit.status.name(),
            lo,
            hi
        );
    }
    s
}

/// Writes `convergence.csv` (every point), `convergence_orders.csv` (every curve) and, per
/// problem, `wp_<problem>.png` (error against GPU time per simulated second) and
/// `dt_<problem>.png` (error against dt). Returns the files.
pub fn write_files(r: &ConvergenceReport, out: &Path) -> Result<Vec<std::path::PathBuf>> {
    let mut files = Vec::new();
    let mut points = Csv::new(&[
        "problem",
        "integrator",
        "precision",
        "dt_s",
        "steps",
        "error",
        "error_unit",
        "scheme_error",
        "rounding_deviation",
        "status",
        "gpu_ms_per_step",
        "gpu_ms_per_simulated_s",
        "non_finite",
    ]);
    let mut orders = Csv::new(&[
        "problem",
        "integrator",
        "precision",
        "expected_order",
        "observed_order",
        "successive_orders",
        "status",
        "points_fitted",
    ]);
    for c in &r.curves {
        let unit = if c.problem == "kepler" { "1" } else { "m" };
        for p in &c.points {
            points.row([
                c.problem.clone(),
                c.integrator.into(),
                c.precision.name().into(),
                num(Some(p.dt)),
                p.steps.to_string(),
                num(Some(p.error)),
                unit.into(),
                num(Some(p.scheme_error)),
                num(Some(p.deviation)),
                format!("{:?}", p.status).to_lowercase(),
                num(Some(p.gpu_ms_per_step)),
                num(Some(p.gpu_ms_per_sim_s)),
                p.non_finite.to_string(),
            ]);
        }
        orders.row([
            c.problem.clone(),
            c.integrator.into(),
            c.precision.name().into(),
            num(c.expected),
            num(c.fit.order),
            c.fit
                .successive
                .iter()
                .map(|o| format!("{o:.4}"))
                .collect::<Vec<_>>()
                .join(" "),
            c.fit.status.name().replace(' ', "_"),
            c.fit.fitted.len().to_string(),
        ]);
    }
    let f = out.join("convergence.csv");
    points.write(&f)?;
    files.push(f);
    let f = out.join("convergence_orders.csv");
    orders.write(&f)?;
    files.push(f);
    for sweep in &r.sweeps {
        let name = sweep.problem.name();
        let curves: Vec<&Curve> = r.curves.iter().filter(|c| c.problem == name).collect();
        // Errors fall with work (free corner: upper right) and rise with dt (upper left).
        for (file, xlabel, x, legend) in [
            (
                format!("wp_{name}.png"),
                "GPU time per simulated second (ms)",
                (|p: &Point| p.gpu_ms_per_sim_s) as fn(&Point) -> f64,
                Legend::UpperRight,
            ),
            (
                format!("dt_{name}.png"),
                "time step dt (s)",
                |p: &Point| p.dt,
                Legend::UpperLeft,
            ),
        ] {
            let series: Vec<Series> = curves
                .iter()
                .map(|c| Series {
                    label: format!(
                        "{} {}: p = {}{}",
                        c.integrator,
                        c.precision.name(),
                        fmt_order(c.fit.order),
                        match c.fit.status {
                            CurveStatus::Measured => String::new(),
                            s => format!(" ({})", s.name()),
                        }
                    ),
                    points: c.points.iter().map(|p| (x(p), p.error)).collect(),
                    hollow: c
                        .points
                        .iter()
                        .map(|p| p.status != PointStatus::Ok)
                        .collect(),
                    color: match c.integrator {
                        "euler" => (200, 40, 40),
                        "uberflow" => (30, 90, 200),
                        _ => (20, 140, 60),
                    },
                    marker: match c.precision {
                        StatePrecision::Fp32 => Marker::Circle,
                        StatePrecision::Fp16Velocity => Marker::Triangle,
                        StatePrecision::Fp24 => Marker::Cross,
                    },
                    dashed: c.precision != StatePrecision::Fp32,
                })
                .collect();
            let path = out.join(file);
            plot::loglog(
                &path,
                &format!("{} ({})", sweep.problem.title(), r.device),
                (xlabel, sweep.problem.error_label()),
                &series,
                (1000, 720),
                legend,
            )?;
            files.push(path);
        }
    }
    let f = out.join("convergence.json");
    super::write_json(&f, r)?;
    files.push(f);
    Ok(files)
}

/// The markdown of the section.
pub fn markdown(r: &ConvergenceReport) -> String {
    format!(
        "## Error against run time\n\n\
         Work-precision diagrams: `wp_<problem>.png` (error against GPU time per simulated \
         second, {}), `dt_<problem>.png` (error against dt); hollow, ringed markers are points \
         that take no part in the fit: at the rounding floor (the GPU differs from the \
         rounding-free twin by more than {:.0}% of the error), outside the asymptotic range \
         (error above {:.0}% of the problem's scale) or diverged. Every point: `convergence.csv`; every \
         curve: `convergence_orders.csv`.\n\n{}",
        r.clock.name(),
        FLOOR_FRACTION * 100.0,
        LARGE_FRACTION * 100.0,
        table(r)
    )
}

/// `texflow report all`'s convergence section.
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let r = run(
        ctx,
        &default_sweeps(opts.size),
        &StatePrecision::ALL,
        progress,
    )?;
    Ok(SectionOutput {
        files: write_files(&r, out)?,
        markdown: markdown(&r),
        warnings: Vec::new(),
    })
}
