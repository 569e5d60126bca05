//! Work-precision diagrams (docs/numerics.md): for each problem with an exact solution,
//! each integrator (Latta's Euler, UberFlow's update, Verlet, and the thesis's Heun, fourth-order
//! Runge-Kutta and leapfrog, §2.1) and each storage precision (fp32,
//! half-float velocities, emulated 24-bit floats), a sweep of time steps run on the GPU through
//! [`ParticleSim`](crate::sim::ParticleSim); the error at a fixed end time (or its maximum over
//! the run) against the GPU time per simulated second, and the observed convergence order from
//! successive halvings.
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
//! - **Divergence.** Points with non-finite state (counted on the GPU by
//!   [`NonFiniteCounter`](crate::sim::nonfinite::NonFiniteCounter)) are `diverged` and never
//!   fitted.
//! - **Large errors.** A point whose error exceeds [`LARGE_FRACTION`] of the problem's scale is
//!   outside the asymptotic range and not fitted either; a curve with no two such points left is
//!   `pre-asymptotic` (or `no convergence` if its errors do not fall at all).
//!
//! Orders are fitted on the longest run of consecutive valid points: successive orders
//! log(e_i / e_{i+1}) / log(dt_i / dt_{i+1}) and their least-squares slope. A spread of the
//! successive orders over [`ERRATIC_SPREAD`] marks the curve `erratic` (not in the asymptotic
//! range, or an error that depends on where in the step an event falls).

use std::path::Path;

use super::{Progress, ReportOptions, SectionOutput};
use crate::error::Result;
use crate::gl::Context;
use crate::scene::Integrator;

// The problems and their exact solutions, the rounding-free twins, the sweeps of dt, the fits,
// the GPU runs, and the tables and plots: one file each, re-exported here.
mod curve;
mod measure;
mod output;
mod problem;
mod sweep;
mod twin;

pub use curve::{fit, Curve, CurveStatus, Fit, Point, PointStatus};
pub use measure::{run, run_curve, run_point, ConvergenceReport};
pub use output::{markdown, table, write_files};
pub use problem::{Metric, Problem, StatePrecision};
pub use sweep::{default_sweeps, Sweep};

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

/// The papers' three integrators (Latta, UberFlow), in table order.
pub const INTEGRATORS: [Integrator; 3] =
    [Integrator::Euler, Integrator::Uberflow, Integrator::Verlet];

/// The thesis's other three (§2.1), which the work-precision study measures beside them.
pub const THESIS_INTEGRATORS: [Integrator; 3] =
    [Integrator::Heun, Integrator::Rk4, Integrator::Leapfrog];

fn integrator_index(i: Integrator) -> usize {
    Integrator::ALL
        .iter()
        .position(|&j| j == i)
        .expect("every integrator is in Integrator::ALL")
}

/// The scene-file name of an integrator.
pub fn integrator_name(i: Integrator) -> &'static str {
    i.name()
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
