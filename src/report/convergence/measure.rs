//! Running the curves on the GPU: one scene per point, the twin beside it, the error, the
//! deviation from the twin, and the GPU time per step.

use glam::DVec3;
use serde::Serialize;

use super::twin::{twin_sample, Twin, TwinState};
use super::{fit, integrator_name, Curve, Metric, Point, PointStatus, Problem, StatePrecision};
use super::{Sweep, FLOOR_FRACTION, LARGE_FRACTION};
use crate::bench::{median, Clock, PassTimer};
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::report::Progress;
use crate::scene::{self, Integrator, SceneFile};
use crate::sim::nonfinite::NonFiniteCounter;
use crate::sim::ParticleSim;

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
    scene::parse(&name, &src)
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
    sim.run(crate::sim::Stage::Integrate)?;
    let next = xyz(&sim.read_positions()?);
    let v = next
        .iter()
        .zip(&prev)
        .map(|(a, b)| (*a - *b) / (2.0 * dt))
        .collect();
    Ok((x, v))
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
    let ics = start_state(&mut sim, problem, n)?;
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
    let r = Run {
        sim: &mut sim,
        problem,
        twin: &twin,
        tw: &mut tw,
        ics: &ics,
        steps,
        dt,
    };
    let (error, scheme_error, deviation) = match problem.metric() {
        Metric::FinalPosition => r.final_position()?,
        Metric::MaxEnergy => r.max_energy(integrator)?,
        Metric::Apex => r.apex(which)?,
    };
    let counter = NonFiniteCounter::for_sim(ctx, &sim)?;
    let non_finite = counter.count_sim(&sim)?.non_finite;
    let times = time_steps(timer, &mut sim, sweep)?;
    ctx.check_error("convergence run")?;
    let ms = median(&times);
    let status = point_status(non_finite, error, deviation, problem.scale());
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

/// The problem's initial conditions for `n` particles, loaded into `sim` (static: birth 0, the
/// random 0.5); returns them for the twins.
fn start_state(sim: &mut ParticleSim, problem: &Problem, n: usize) -> Result<Vec<(DVec3, DVec3)>> {
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
    Ok(ics)
}

/// `sweep.repeats` timings of `sweep.batch` integration steps, each per step (ms).
fn time_steps(timer: &PassTimer, sim: &mut ParticleSim, sweep: &Sweep) -> Result<Vec<f64>> {
    let mut times = Vec::with_capacity(sweep.repeats);
    for _ in 0..sweep.repeats {
        let ms = crate::engine::timed(timer, || {
            for _ in 0..sweep.batch {
                sim.run(crate::sim::Stage::Integrate)?;
            }
            Ok(())
        })?;
        times.push(ms / sweep.batch as f64);
    }
    Ok(times)
}

/// A point's verdict: diverged, at the rounding floor, too large for the problem's `scale`,
/// or fine.
fn point_status(non_finite: u64, error: f64, deviation: f64, scale: f64) -> PointStatus {
    if non_finite > 0 || !error.is_finite() {
        PointStatus::Diverged
    } else if deviation > FLOOR_FRACTION * error {
        PointStatus::Floor
    } else if error > LARGE_FRACTION * scale {
        PointStatus::Large
    } else {
        PointStatus::Ok
    }
}

/// One point's GPU simulation beside its CPU twins, run to the end of the sweep's time.
struct Run<'a> {
    sim: &'a mut ParticleSim,
    problem: &'a Problem,
    twin: &'a Twin,
    tw: &'a mut Vec<TwinState>,
    ics: &'a [(DVec3, DVec3)],
    steps: u64,
    dt: f64,
}

/// (error, the twin's error, the GPU's deviation from the twin).
type Errors = (f64, f64, f64);

impl Run<'_> {
    /// The position at the end against the closed form.
    fn final_position(self) -> Result<Errors> {
        let Run {
            sim,
            problem,
            twin,
            tw,
            ics,
            steps,
            dt,
        } = self;
        let (mut error, mut deviation) = (0.0f64, 0.0f64);
        for _ in 0..steps {
            sim.run(crate::sim::Stage::Integrate)?;
        }
        for _ in 0..steps {
            for t in tw.iter_mut() {
                twin.step(t);
            }
        }
        let x = xyz(&sim.read_positions()?);
        let (x0, v0) = ics[0];
        let exact = problem.exact(x0, v0, steps as f64 * dt).0;
        let scheme_error = (tw[0].x - exact).length();
        for p in &x {
            error = nan_max(error, (*p - exact).length());
            deviation = nan_max(deviation, (*p - tw[0].x).length());
        }
        Ok((error, scheme_error, deviation))
    }

    /// The largest relative energy error over the samples.
    fn max_energy(self, integrator: Integrator) -> Result<Errors> {
        let Run {
            sim,
            problem,
            twin,
            tw,
            ics,
            steps,
            dt,
        } = self;
        let (mut error, mut scheme_error, mut deviation) = (0.0f64, 0.0f64, 0.0f64);
        let stride = ((problem.sample_interval() / dt).round() as u64).max(1);
        let e0 = problem.energy(ics[0].0, ics[0].1);
        let mut n_done = 0u64;
        let mut sample = stride;
        while sample <= steps {
            while n_done < sample {
                sim.run(crate::sim::Stage::Integrate)?;
                twin.step(&mut tw[0]);
                n_done += 1;
            }
            let (x, v) = sample_state(sim, dt)?;
            let (tx, tv) = twin_sample(twin, &mut tw[0]);
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
        Ok((error, scheme_error, deviation))
    }

    /// The apex heights of every bounce against the closed form.
    fn apex(self, which: impl Fn(usize) -> usize) -> Result<Errors> {
        let Run {
            sim,
            problem,
            twin,
            tw,
            ics,
            steps,
            dt,
        } = self;
        let (mut error, mut scheme_error) = (0.0f64, 0.0f64);
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
        let n = ics.len();
        let mut apex = vec![vec![f64::NEG_INFINITY; bounces as usize]; n];
        let mut apex_twin = apex.clone();
        for step in 1..=steps {
            sim.run(crate::sim::Stage::Integrate)?;
            for t in tw.iter_mut() {
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
            Problem::Drag { .. } | Problem::Oscillator { .. } | Problem::Kepler { .. } => 1.0,
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
        let deviation = (error - scheme_error).abs();
        Ok((error, scheme_error, deviation))
    }
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

/// Runs every sweep for every integrator (the papers' and the thesis's, [`Integrator::ALL`]) and
/// precision that applies.
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
        for &integrator in &Integrator::ALL {
            for &precision in precisions {
                let thesis_skipped = !sweep.thesis_in_every_precision
                    && integrator.multistage()
                    && precision != StatePrecision::Fp32;
                if !precision.applies_to(integrator) || thesis_skipped {
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
