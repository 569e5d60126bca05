//! Timing GL work: two clocks and a pass timer.
//!
//! On a hardware GPU, `GL_TIME_ELAPSED` timer queries; on Mesa's llvmpipe, wall time between two
//! `glFinish` calls. llvmpipe bins draws and rasterizes them only when the scene is flushed (at
//! the next framebuffer change, say), so its timer queries charge a pass's work to whatever query
//! is open at the flush; the CPU is its GPU, so finished wall time is exact there.

use std::time::Instant;

use super::{Context, TimerQuery};
use crate::error::Result;

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
            Clock::Gpu => "GPU timer queries",
            Clock::Wall => "wall clock, waiting for the GL to finish",
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
