//! The baseline the papers open with: the stateless particle system (Latta §2.1, thesis §2.2.5)
//! against the stateful engine, on a motion with a closed form (gravity, linear damping and a
//! constant wind through drag, `a = A - lambda v`). For each way of computing it, the error of
//! every particle's position at the end against the closed form in `f64`
//! ([`crate::sim::ClosedForm`]), and the GPU time of one step, which is the cost of a
//! frame at one step per frame.
//!
//! The stateless pass evaluates the solution itself, so its error is rounding alone and does not
//! grow with the number of steps; the stateful integrators carry their truncation error (order 1
//! for Latta's Euler, 2 for Heun, 4 for RK4, 1 for leapfrog and UberFlow's update under this
//! velocity-dependent force) plus the rounding of every step. What the stateless form gives up is
//! everything without a closed form: colliders, fields, attractors (the scene validation refuses
//! them).

use std::path::{Path, PathBuf};

use glam::DVec3;
use serde::Serialize;

use super::{num, Csv, Progress, ReportOptions, SectionOutput, Size};
use crate::bench::{median, Clock, PassTimer};
use crate::error::Result;
use crate::gl::Context;
use crate::scene::{self, Integrator};
use crate::sim::{ClosedForm, ParticleSim};

/// The forces and emitter of the measured scene.
const SCENE: &str = "[[emitters.initial]]\nshape = \"sphere\"\ncenter = [0.0, 1.0, 0.0]\n\
radius = 0.5\ndirection = [0.2, 1.0, 0.1]\ncone_degrees = 35.0\nspeed = [2.0, 6.0]\n\
[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n[[forces.damping]]\nrate = 0.3\n\
[[forces.wind]]\nvelocity = [3.0, 0.0, -1.0]\nturbulence = 0.0\nresolution = 2\n\
bounds = [[-50.0, -50.0, -50.0], [50.0, 50.0, 50.0]]\ndrag = 0.8\n";

/// End time of every run, s.
pub const END: f64 = 2.0;

/// One way of computing the motion at one time step.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// `stateless`, or the integrator of the stateful engine.
    pub mode: String,
    /// Time step, s.
    pub dt: f64,
    /// Steps to [`END`].
    pub steps: u64,
    /// Largest position error over the particles at [`END`] against the closed form, m.
    pub error: f64,
    /// Median GPU time of one step, ms.
    pub gpu_ms_per_step: f64,
}

fn scene_source(mode: &str, side: u32, dt: f64) -> String {
    let head = if mode == "stateless" {
        "simulation = \"stateless\"".to_owned()
    } else {
        format!("integrator = \"{mode}\"")
    };
    format!(
        "name = \"baseline\"\n{head}\n[particles]\nsize = [{side}, {side}]\n[time]\ndt = {dt:?}\n\
         {SCENE}"
    )
}

fn xyz(v: &[f32]) -> Vec<DVec3> {
    v.chunks_exact(4)
        .map(|c| DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64))
        .collect()
}

/// Runs one mode at one time step.
pub fn run_row(
    ctx: &Context,
    timer: &PassTimer,
    mode: &str,
    side: u32,
    dt: f64,
    repeats: usize,
) -> Result<Row> {
    let s = scene::parse("baseline", &scene_source(mode, side, dt))?;
    let closed = ClosedForm::of(&s);
    let im = 1.0 / s.particles.mass as f64;
    let mut sim = ParticleSim::new(ctx, &s, 5)?;
    let (x0, v0) = (xyz(&sim.read_positions()?), xyz(&sim.read_velocities()?));
    let steps = (END / dt).round() as u64;
    for _ in 0..steps {
        sim.step()?;
    }
    let x = xyz(&sim.read_positions()?);
    let error = x
        .iter()
        .zip(x0.iter().zip(&v0))
        .map(|(x, (x0, v0))| (*x - closed.at(*x0, *v0, steps as f64 * dt, im).0).length())
        .fold(0.0, f64::max);
    let mut times = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        times.push(crate::engine::timed(timer, || {
            sim.run(crate::sim::Stage::Integrate)
        })?);
    }
    ctx.check_error("baseline run")?;
    Ok(Row {
        mode: mode.to_owned(),
        dt,
        steps,
        error,
        gpu_ms_per_step: median(&times),
    })
}

/// Every mode at two time steps.
pub fn run(ctx: &Context, size: Size, progress: Progress<'_>) -> Result<Vec<Row>> {
    let timer = PassTimer::new(ctx, Clock::for_context(ctx))?;
    let (side, repeats) = match size {
        Size::Full => (128, 15),
        Size::Quick => (16, 3),
    };
    let mut modes = vec!["stateless"];
    modes.extend(
        [
            Integrator::Euler,
            Integrator::Uberflow,
            Integrator::Heun,
            Integrator::Rk4,
            Integrator::Leapfrog,
        ]
        .map(Integrator::name),
    );
    let mut rows = Vec::new();
    for dt in [1.0 / 60.0, 1.0 / 240.0] {
        for mode in &modes {
            progress(&format!("baselines {mode} dt = {dt:.5} s"));
            rows.push(run_row(ctx, &timer, mode, side, dt, repeats)?);
        }
    }
    Ok(rows)
}

/// The markdown table.
pub fn markdown(rows: &[Row], device: &str) -> String {
    let mut md = format!(
        "## Stateless against stateful (Latta §2.1, thesis §2.2.5)\n\nGravity, damping 0.3/s and \
         a constant wind through drag 0.8/s: the largest position error over the particles at \
         t = {END} s against the closed form in f64, and the GPU time of one step (a frame at \
         one step per frame), {device}.\n\n\
         | mode | dt (s) | steps | error at t = {END} s (m) | GPU ms per step |\n\
         | --- | --- | --- | --- | --- |\n"
    );
    for r in rows {
        md += &format!(
            "| {} | {:.5} | {} | {:.2e} | {:.4} |\n",
            r.mode, r.dt, r.steps, r.error, r.gpu_ms_per_step
        );
    }
    md
}

/// `texflow report all`'s baselines section.
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let rows = run(ctx, opts.size, progress)?;
    let mut csv = Csv::new(&["mode", "dt_s", "steps", "error_m", "gpu_ms_per_step"]);
    for r in &rows {
        csv.row([
            r.mode.clone(),
            num(Some(r.dt)),
            r.steps.to_string(),
            num(Some(r.error)),
            num(Some(r.gpu_ms_per_step)),
        ]);
    }
    let path: PathBuf = out.join("baselines.csv");
    csv.write(&path)?;
    Ok(SectionOutput {
        files: vec![path],
        markdown: markdown(&rows, &ctx.limits().renderer),
        warnings: Vec::new(),
    })
}
