//! Timing GL work: two clocks and a pass timer.
//!
//! On a hardware GPU, `GL_TIME_ELAPSED` timer queries; on Mesa's llvmpipe, wall time between two
//! `glFinish` calls. llvmpipe bins draws and rasterizes them only when the scene is flushed (at
//! the next framebuffer change, say), so its timer queries charge a pass's work to whatever query
//! is open at the flush; the CPU is its GPU, so finished wall time is exact there.

use std::time::Instant;

use super::{
    Context, Defines, Draw, DrawState, Framebuffer, Primitive, Program, Texture, TextureDesc,
    TextureFormat, TimerQuery, Uniform, VertexArray, FULLSCREEN_VERTEX,
};
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
    lead: Option<Lead>,
}

/// GPU work queued before a timer query begins. A query's range runs from when the GPU reaches
/// its start; with nothing queued ahead it starts at once, and the draws after it arrive as the
/// driver submits them, so the CPU's submission (slow on a draw state's first uses) is timed
/// as GPU time. Behind this pass the draws are queued before the GPU reaches the range.
#[derive(Debug)]
struct Lead {
    program: Program,
    vertices: VertexArray,
    target: Framebuffer,
}

/// The lead pass's target: 8 MB of RGBA32F, about 0.15 ms of writes on an H200.
const LEAD_SIZE: [u32; 2] = [1024, 512];

impl Lead {
    fn new(ctx: &Context) -> Result<Self> {
        let d: Defines = vec![("TARGETS".into(), "1".into())];
        let texture = Texture::new(
            ctx,
            TextureDesc {
                width: LEAD_SIZE[0],
                height: LEAD_SIZE[1],
                format: TextureFormat::Rgba32F,
                label: "timer lead",
            },
        )?;
        Ok(Lead {
            program: Program::new(ctx, FULLSCREEN_VERTEX, "common/write_floor.frag", &d)?,
            vertices: VertexArray::empty(ctx, "timer lead")?,
            target: Framebuffer::new(ctx, "timer lead", vec![texture])?,
        })
    }

    fn draw(&self, ctx: &Context) {
        let value = [("u_value", Uniform::Vec4(glam::Vec4::ONE))];
        ctx.draw_unseen(&Draw {
            program: &self.program,
            target: &self.target,
            viewport: None,
            vertices: &self.vertices,
            primitive: Primitive::Triangles,
            count: 3,
            state: &DrawState::REPLACE,
            textures: &[],
            uniforms: &value,
        });
    }
}

impl PassTimer {
    /// A timer on `ctx` using `clock`.
    pub fn new(ctx: &Context, clock: Clock) -> Result<Self> {
        Ok(PassTimer {
            ctx: ctx.clone(),
            clock,
            query: TimerQuery::new(ctx)?,
            lead: match clock {
                Clock::Gpu => Some(Lead::new(ctx)?),
                Clock::Wall => None,
            },
        })
    }

    /// The clock in use.
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// Milliseconds the GL commands issued by `f` take.
    pub fn time(&self, f: impl FnOnce()) -> Result<f64> {
        match self.clock {
            Clock::Gpu => {
                if let Some(lead) = &self.lead {
                    lead.draw(&self.ctx);
                }
                Ok(self.query.time(f)?.1)
            }
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
