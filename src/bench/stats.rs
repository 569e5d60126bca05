//! Shared measuring tools: the median, the two clocks, a pass timer and the write-only floor pass.
//!
//! Two clocks: on a hardware GPU, `GL_TIME_ELAPSED` timer queries; on Mesa's llvmpipe, wall time
//! between two `glFinish` calls. llvmpipe bins draws and rasterizes them only when the scene is
//! flushed (at the next framebuffer change, say), so its timer queries charge a pass's work to
//! whatever query is open at the flush; the CPU is its GPU, so finished wall time is exact there.

use std::time::Instant;

use glam::Vec4;

use crate::error::Result;
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, Program, TimerQuery, FULLSCREEN_VERTEX,
};

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
