//! The test problems with exact solutions, and how the state is stored.

use std::f64::consts::PI;

use glam::DVec3;
use serde::Serialize;

use super::{G, TURNING_POINT};
use crate::error::{Error, Result};
use crate::scene::Integrator;

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

    pub(super) fn toml(self) -> &'static str {
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
            Metric::FinalPosition | Metric::Apex => "error (m)",
        }
    }

    /// The order theory expects (docs/numerics.md, docs/pipeline.md); `None` where
    /// there is none to expect (exact schemes). Verlet's bounce is first order like the others
    /// since its contact takes Latta eq. 4-5 on the implied velocity.
    pub fn expected_order(&self, i: Integrator) -> Option<f64> {
        use Integrator::*;
        match (self, i) {
            // Exact for constant acceleration: errors are rounding only.
            (Problem::Drag { drag, .. }, Uberflow | Verlet | Heun | Rk4 | Leapfrog)
                if *drag == 0.0 =>
            {
                None
            }
            // The Runge-Kutta schemes keep their order for velocity-dependent forces.
            (Problem::Drag { .. }, Heun) => Some(2.0),
            (Problem::Drag { .. }, Rk4) => Some(4.0),
            // Velocity-dependent force: Euler's velocity update (all), Verlet's
            // backward-difference velocity, and leapfrog's second kick with the half-step
            // velocity, are first order.
            (Problem::Drag { .. }, _) => Some(1.0),
            (Problem::Oscillator { .. } | Problem::Kepler { .. }, Rk4) => Some(4.0),
            (Problem::Oscillator { .. } | Problem::Kepler { .. }, Verlet | Heun | Leapfrog) => {
                Some(2.0)
            }
            (Problem::Oscillator { .. } | Problem::Kepler { .. }, _) => Some(1.0),
            (Problem::Bounce { .. }, _) => Some(1.0),
        }
    }

    /// The forces and colliders in scene-file TOML.
    pub(super) fn scene_toml(&self) -> String {
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

    pub(super) fn bounces(&self) -> u32 {
        match self {
            Problem::Bounce { bounces, .. } => *bounces,
            Problem::Drag { .. } | Problem::Oscillator { .. } | Problem::Kepler { .. } => 0,
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
            Problem::Kepler { .. } | Problem::Bounce { .. } => (x0, v0),
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
            Problem::Drag { .. } | Problem::Oscillator { .. } | Problem::Kepler { .. } => 1.0,
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
pub(super) const KEPLER_SOFTENING: f64 = 1e-6;
