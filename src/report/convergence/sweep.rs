//! The sweeps of time steps: which dt each integrator runs on each problem.

use serde::Serialize;

use super::{integrator_index, Problem};
use crate::error::{Error, Result};
use crate::report::Size;
use crate::scene::Integrator;

/// A sweep of time steps on one problem. As in the work-precision diagrams of ODE benchmark
/// suites, each method gets its own range of steps: where it is in its asymptotic range and
/// above its rounding floor.
#[derive(Debug, Clone, Serialize)]
pub struct Sweep {
    /// The problem.
    pub problem: Problem,
    /// Per integrator (in [`Integrator::ALL`] order): the coarsest time step is 2^-k s. Powers
    /// of two are exact in f32, so the end time is exactly n·dt.
    pub coarsest: [i32; 6],
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
    /// Run the thesis's integrators ([`super::THESIS_INTEGRATORS`]) in every storage precision
    /// asked for; when false, in fp32 alone (the quick report, which CI runs).
    pub thesis_in_every_precision: bool,
}

impl Sweep {
    /// A sweep of `count` time steps from dt = 2^-`coarsest` s down, for every integrator.
    pub fn new(problem: Problem, coarsest: i32, count: usize, side: u32) -> Self {
        Sweep {
            problem,
            coarsest: [coarsest; 6],
            count,
            side,
            repeats: 9,
            batch: 10,
            check_turning_points: true,
            thesis_in_every_precision: true,
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
            for &i in &Integrator::ALL {
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
/// Fourth-order Runge-Kutta reaches the f32 floor within a few halvings from the others' start,
/// so it starts at dt = 1 s (ω·dt = 1, inside its stability region) on the oscillator and the
/// drag, and coarser on the orbit.
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
        .with_coarsest(Integrator::Verlet, 4)
        .with_coarsest(Integrator::Rk4, 1),
        Sweep::new(
            Problem::Oscillator {
                omega: 1.0,
                end: 2.0,
            },
            2,
            n,
            side,
        )
        .with_coarsest(Integrator::Rk4, 0),
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
        .with_coarsest(Integrator::Verlet, 4)
        .with_coarsest(Integrator::Heun, 5)
        .with_coarsest(Integrator::Rk4, 4)
        .with_coarsest(Integrator::Leapfrog, 4),
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
        w.thesis_in_every_precision = size == Size::Full;
    }
    s
}
