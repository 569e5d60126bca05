//! Benchmarks: time of passes, medians over many runs after warm-up, each pass next to its floor
//! measured in the same run (a write-only pass of the same size and formats: on a GPU whose
//! fragment path is bound by the bytes it writes, no pass that writes those targets can be
//! faster).
//!
//! Two clocks: on a hardware GPU, `GL_TIME_ELAPSED` timer queries; on Mesa's llvmpipe, wall time
//! between two `glFinish` calls. llvmpipe bins draws and rasterizes them only when the scene is
//! flushed (at the next framebuffer change, say), so its timer queries charge a pass's work to
//! whatever query is open at the flush; the CPU is its GPU, so finished wall time is exact there.

use std::time::Instant;

use glam::Vec4;

use crate::engine::Engine;
use crate::error::Result;
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, Program, TimerQuery, FULLSCREEN_VERTEX,
};
use crate::scene::Scene;

/// A write-only pass into `targets` render targets: the floor of any pass writing them.
#[derive(Debug)]
pub struct WriteFloor {
    program: Program,
    pass: FullscreenPass,
}

impl WriteFloor {
    /// Builds the floor pass for framebuffers of `targets` attachments.
    pub fn new(ctx: &Context, targets: usize) -> Result<Self> {
        let defines: Defines = vec![("TARGETS".into(), targets.to_string())];
        Ok(WriteFloor {
            program: Program::new(ctx, FULLSCREEN_VERTEX, "common/write_floor.frag", &defines)?,
            pass: FullscreenPass::new(ctx)?,
        })
    }

    /// Writes a constant into every texel of every attachment of `fb`.
    pub fn draw(&self, fb: &Framebuffer) {
        self.program.bind();
        self.program
            .set_vec4("u_value", Vec4::new(0.25, 0.5, 0.75, 1.0));
        self.pass.draw(&self.program, fb);
    }
}

/// The median of `v` (mean of the two middle values for an even count); NaN for none.
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// How passes are timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Clock {
    /// `GL_TIME_ELAPSED` queries around the pass (hardware GPUs).
    Gpu,
    /// Wall time from one `glFinish` to another around the pass (software rasterizers).
    Wall,
}

impl Clock {
    /// The right clock for a context: wall time on software renderers, timer queries otherwise.
    pub fn for_context(ctx: &Context) -> Clock {
        let r = ctx.limits().renderer.to_ascii_lowercase();
        if r.contains("llvmpipe") || r.contains("softpipe") || r.contains("swrast") {
            Clock::Wall
        } else {
            Clock::Gpu
        }
    }

    /// The clock's name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Clock::Gpu => "GPU timer query",
            Clock::Wall => "glFinish wall time",
        }
    }
}

/// Times GL work with one [`Clock`].
#[derive(Debug)]
pub struct PassTimer {
    ctx: Context,
    clock: Clock,
    query: TimerQuery,
}

impl PassTimer {
    /// A timer on `ctx` using `clock`.
    pub fn new(ctx: &Context, clock: Clock) -> Result<Self> {
        Ok(PassTimer {
            ctx: ctx.clone(),
            clock,
            query: TimerQuery::new(ctx)?,
        })
    }

    /// The clock in use.
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// Milliseconds the GL commands issued by `f` take.
    pub fn time(&self, f: impl FnOnce()) -> Result<f64> {
        match self.clock {
            Clock::Gpu => Ok(self.query.time(f)?.1),
            Clock::Wall => {
                self.ctx.finish();
                let t0 = Instant::now();
                f();
                self.ctx.finish();
                Ok(t0.elapsed().as_secs_f64() * 1e3)
            }
        }
    }
}

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
    /// Median GPU time of a write-only full-screen pass into the frame target, ms.
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
    scene: &Scene,
    sizes: &[u32],
    opts: &StepOptions,
    mut progress: impl FnMut(u32),
) -> Result<Vec<StepRecord>> {
    let sim_floor = WriteFloor::new(ctx, 2)?;
    let render_floor = WriteFloor::new(ctx, 1)?;
    let timer = PassTimer::new(ctx, opts.clock.unwrap_or_else(|| Clock::for_context(ctx)))?;
    let mut records = Vec::new();
    for &size in sizes {
        let mut s = scene.clone();
        s.particles = [size, size];
        let mut engine = Engine::new(ctx, s, 1)?;
        let dt = scene.dt;
        for _ in 0..opts.warmup_steps {
            engine.advance_frame();
        }
        let mut t = [vec![], vec![], vec![], vec![]];
        for _ in 0..opts.repeats {
            let sim = engine.sim();
            t[0].push(timer.time(|| sim_floor.draw(sim.state().back()))?);
            sim.bind_step(dt);
            t[1].push(timer.time(|| sim.draw_step_only())?);
            // The timed pass wrote the back without swapping; advancing redoes it and swaps, so
            // the state keeps evolving between repetitions.
            engine.advance_frame();
            t[2].push(timer.time(|| render_floor.draw(engine.target().framebuffer()))?);
            t[3].push(timer.time(|| engine.draw())?);
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
            resolution: scene.resolution,
            repeats: opts.repeats,
            clock: timer.clock(),
        });
        progress(size);
    }
    Ok(records)
}
