//! The full-screen pass: one attribute-less triangle covering the viewport, so that every texel
//! of the target runs the fragment program once (the papers' full-screen quad, thesis §3.5).

use super::{Context, Draw, DrawState, Framebuffer, Primitive, Program, Rect, VertexArray};
use crate::error::Result;

/// The vertex shader every full-screen pass uses.
pub const FULLSCREEN_VERTEX: &str = "common/fullscreen.vert";

/// Draws full-screen passes.
#[derive(Debug)]
pub struct FullscreenPass {
    ctx: Context,
    vao: VertexArray,
}

impl FullscreenPass {
    /// Makes the (empty) vertex array the triangle needs.
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(FullscreenPass {
            ctx: ctx.clone(),
            vao: VertexArray::empty(ctx, "fullscreen")?,
        })
    }

    /// Runs `program` (already bound, uniforms set) over every texel of `target`.
    pub fn draw(&self, program: &Program, target: &Framebuffer) {
        self.draw_rows(program, target, 0, target.height());
    }

    /// Runs `program` over rows `y0..y0+rows` of `target` only (live-row restriction).
    /// Blending is off: every texel written is the program's output.
    pub fn draw_rows(&self, program: &Program, target: &Framebuffer, y0: u32, rows: u32) {
        self.ctx.draw(&Draw {
            program,
            target,
            viewport: Some(Rect {
                x: 0,
                y: y0,
                width: target.width(),
                height: rows,
            }),
            vertices: &self.vao,
            primitive: Primitive::Triangles,
            count: 3,
            state: &DrawState::REPLACE,
        });
    }
}
