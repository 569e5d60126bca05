//! `texflow bench step`: any scene's simulation step and render pass per state size, each next
//! to its floor measured in the same run, on the engine `render` runs
//! ([`crate::engine::build_gpu`]).

use super::stats::{median, Clock, PassTimer, RenderFloor, WriteFloor};
use crate::engine::timed;
use crate::error::Result;
use crate::gl::Context;
use crate::scene::SceneFile;

/// One row of `texflow bench step`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StepRecord {
    /// Scene name.
    pub scene: String,
    /// State texture side (size × size particles).
    pub size: u32,
    /// Number of particles.
    pub particles: u64,
    /// Median GPU time of one simulation step (the fire's one pass; every stage of the particle
    /// pipeline's step), ms.
    pub sim_ms: f64,
    /// Median GPU time of a write-only pass into the same targets as the state's, ms.
    pub sim_floor_ms: f64,
    /// sim_ms / sim_floor_ms.
    pub sim_ratio: f64,
    /// Simulated particles per second (particles / sim_ms).
    pub particles_per_s: f64,
    /// Median GPU time of one render pass (clear + points or sprites; after the frame's sort,
    /// untimed, for alpha blending), ms.
    pub render_ms: f64,
    /// Median GPU time of the render floor ([`RenderFloor`]: the clear and as many one-pixel
    /// points as the pass draws through the same target and blend, fetching no texture), ms.
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

/// Times the simulation step and the render pass of `scene` at each square state size.
pub fn bench_step(
    ctx: &Context,
    scene: &SceneFile,
    sizes: &[u32],
    opts: &StepOptions,
    mut progress: impl FnMut(u32),
) -> Result<Vec<StepRecord>> {
    let render_floor = RenderFloor::new(ctx)?;
    let timer = PassTimer::new(ctx, opts.clock.unwrap_or_else(|| Clock::for_context(ctx)))?;
    let mut records = Vec::new();
    for &size in sizes {
        let mut s = scene.clone();
        s.particles.size = [size, size];
        let mut engine = crate::engine::build_gpu(ctx, &s, 1)?;
        let e = engine.as_mut();
        for _ in 0..opts.warmup_steps {
            e.advance_frame()?;
        }
        // The step's floor writes a scratch framebuffer of the state's formats and size.
        let scratch = super::scene::scratch_like(ctx, e.sim().state_target())?;
        let sim_floor = WriteFloor::for_target(ctx, &scratch)?;
        // Drawn once untimed: a new program's first draw pays for its code.
        sim_floor.draw(&scratch);
        let (blend, clear) = e.frame_blend();
        let blend = Some(blend);
        let mut t = [vec![], vec![], vec![], vec![]];
        for _ in 0..opts.repeats {
            t[0].push(timer.time(|| sim_floor.draw(&scratch))?);
            // One step: every stage of it (the fire's one pass and its swap).
            t[1].push(timed(&timer, || e.sim_mut().step())?);
            // The frame's sort (alpha blending), untimed; then the render pass alone, drawing
            // every texel when sorted (dead ones sort last), else the live rows.
            let sorted = e.order_for_drawing_observed(&mut |_, _| Ok(()))?;
            let [w, h] = e.sim().size();
            let points = match sorted {
                true => w as usize * h as usize,
                false => e.sim().drawn().count,
            };
            let fb = e.target().framebuffer();
            t[2].push(timer.time(|| render_floor.draw(fb, clear, blend, points))?);
            t[3].push(timed(&timer, || e.render_pass(sorted))?);
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
