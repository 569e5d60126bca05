//! `texflow bench step`: the fire's simulation pass and render pass per state size, each next to
//! its floor measured in the same run.

use super::stats::{median, Clock, PassTimer, RenderFloor, WriteFloor};
use crate::engine::{timed, GpuEngine};
use crate::error::Result;
use crate::gl::Context;
use crate::scene::SceneFile;
use crate::sim::{FireSim, Simulation};

/// One row of `texflow bench step`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StepRecord {
    /// Scene name.
    pub scene: String,
    /// State texture side (size × size particles).
    pub size: u32,
    /// Number of particles.
    pub particles: u64,
    /// Median GPU time of one simulation pass, ms.
    pub sim_ms: f64,
    /// Median GPU time of a write-only pass into the same targets, ms.
    pub sim_floor_ms: f64,
    /// sim_ms / sim_floor_ms.
    pub sim_ratio: f64,
    /// Simulated particles per second (particles / sim_ms).
    pub particles_per_s: f64,
    /// Median GPU time of one render pass (clear + points), ms.
    pub render_ms: f64,
    /// Median GPU time of the render floor ([`RenderFloor`]: the clear and as many one-pixel
    /// points through the same target and blend, fetching no texture), ms.
    pub render_floor_ms: f64,
    /// render_ms / render_floor_ms.
    pub render_ratio: f64,
    /// Frame size the render pass drew.
    pub resolution: [u32; 2],
    /// Timed repetitions behind each median.
    pub repeats: usize,
    /// The clock the times come from.
    pub clock: Clock,
}

/// The records of [`bench_step`] as a markdown table.
pub fn step_markdown(records: &[StepRecord]) -> String {
    let mut out = format!(
        "frame {}; column names are the JSON keys\n\n| size | particles | sim_ms | sim_floor_ms | \
         sim_ratio | particles_per_s | render_ms | render_floor_ms | render_ratio |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        records
            .first()
            .map(|r| format!("{}x{}", r.resolution[0], r.resolution[1]))
            .unwrap_or_default()
    );
    for r in records {
        out.push_str(&format!(
            "| {0} | {1} | {2:.3} | {3:.3} | {4} | {5:.3e} | {6:.3} | {7:.3} | {8} |\n",
            r.size,
            r.particles,
            r.sim_ms,
            r.sim_floor_ms,
            crate::bench::stats::ratio_cell(r.sim_ratio),
            r.particles_per_s,
            r.render_ms,
            r.render_floor_ms,
            crate::bench::stats::ratio_cell(r.render_ratio)
        ));
    }
    out
}

/// Options of [`bench_step`].
#[derive(Debug, Clone)]
pub struct StepOptions {
    /// Timed repetitions per size.
    pub repeats: usize,
    /// Simulation steps before timing, so that the state is in its steady state.
    pub warmup_steps: usize,
    /// The clock; `None` picks [`Clock::for_context`].
    pub clock: Option<Clock>,
}

impl Default for StepOptions {
    fn default() -> Self {
        StepOptions {
            repeats: 21,
            warmup_steps: 120,
            clock: None,
        }
    }
}

/// Times the simulation and render passes of `scene` at each square state size.
pub fn bench_step(
    ctx: &Context,
    scene: &SceneFile,
    sizes: &[u32],
    opts: &StepOptions,
    mut progress: impl FnMut(u32),
) -> Result<Vec<StepRecord>> {
    let sim_floor = WriteFloor::new(ctx, 2)?;
    let render_floor = RenderFloor::new(ctx)?;
    let blend = Some(super::scene::FIRE_BLEND);
    let timer = PassTimer::new(ctx, opts.clock.unwrap_or_else(|| Clock::for_context(ctx)))?;
    let mut records = Vec::new();
    for &size in sizes {
        let mut s = scene.clone();
        s.particles.size = [size, size];
        let mut engine = GpuEngine::<FireSim>::new(ctx, &s, 1)?;
        for _ in 0..opts.warmup_steps {
            engine.advance_frame()?;
        }
        let mut t = [vec![], vec![], vec![], vec![]];
        for _ in 0..opts.repeats {
            t[0].push(timer.time(|| sim_floor.draw(engine.sim().state().back()))?);
            // The step's one pass and its swap (which costs nothing).
            t[1].push(timed(&timer, || engine.sim_mut().step())?);
            let points = engine.sim().particle_count();
            let fb = engine.target().framebuffer();
            t[2].push(timer.time(|| render_floor.draw(fb, [0.0, 0.0, 0.0, 1.0], blend, points))?);
            t[3].push(timed(&timer, || engine.draw())?);
        }
        ctx.check_error("benchmark")?;
        let [floor, sim_ms, rfloor, render] = t.map(|v| median(&v));
        let particles = size as u64 * size as u64;
        records.push(StepRecord {
            scene: scene.name.clone(),
            size,
            particles,
            sim_ms,
            sim_floor_ms: floor,
            sim_ratio: sim_ms / floor,
            particles_per_s: particles as f64 / (sim_ms * 1e-3),
            render_ms: render,
            render_floor_ms: rfloor,
            render_ratio: render / rfloor,
            resolution: scene.render.resolution,
            repeats: opts.repeats,
            clock: timer.clock(),
        });
        progress(size);
    }
    Ok(records)
}
