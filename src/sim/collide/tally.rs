//! How often the exact search hit its bound, or a path its bound on bounces at colliders: a count
//! kept on the GPU over a whole run and read back once, so that `render` can warn about
//! collisions the search could not see and bounces the colliders did not make.
//!
//! After each exact count pass, one point per particle is drawn into a 1×1 R32F target with
//! additive blending, where the count pass flagged the particle's search as truncated (a run of
//! three cells held more than [`EXACT_SCAN`](super::EXACT_SCAN) particles); the others are
//! clipped away in the vertex shader. Exact up to 2^24 flagged searches. The colliders' count
//! reads the velocity's w after each integration pass instead (`glsl/sim/integrate.frag`).

use crate::error::Result;
use crate::gl::{
    Blend, BlendComponent, BlendFactor, Context, Depth, Draw, DrawState, Framebuffer, PointSize,
    Primitive, Program, Texture, TextureDesc, TextureFormat, Uniform, VertexArray,
};

/// The running count of truncated searches.
#[derive(Debug)]
pub(crate) struct TruncationTally {
    ctx: Context,
    program: Program,
    target: Framebuffer,
    empty: VertexArray,
}

impl TruncationTally {
    /// The program each tally draws, for the pass list.
    pub(crate) fn program(&self) -> &Program {
        &self.program
    }

    /// A tally at 0.
    pub(crate) fn new(ctx: &Context) -> Result<Self> {
        let texture = Texture::new(
            ctx,
            TextureDesc {
                width: 1,
                height: 1,
                format: TextureFormat::R32F,
                label: "truncated searches",
            },
        )?;
        let target = Framebuffer::new(ctx, "truncated searches", vec![texture])?;
        target.clear([0.0; 4]);
        Ok(TruncationTally {
            ctx: ctx.clone(),
            program: Program::new(ctx, "collide/tally.vert", "collide/tally.frag", &Vec::new())?,
            target,
            empty: VertexArray::empty(ctx, "truncation tally")?,
        })
    }

    /// Adds the particles that `counts` (the exact count pass's output, `width` wide, `n`
    /// texels) flags as truncated.
    pub(super) fn add(&self, counts: &Texture, n: usize) {
        self.add_flags(counts, 1, n);
    }

    /// Adds the first `n` texels of `flags` whose component `component` is above 1/2.
    pub(crate) fn add_flags(&self, flags: &Texture, component: i32, n: usize) {
        let p = &self.program;
        let add = BlendComponent::add(BlendFactor::One, BlendFactor::One);
        self.ctx.draw(&Draw {
            program: p,
            target: &self.target,
            viewport: None,
            vertices: &self.empty,
            primitive: Primitive::Points,
            count: n as u32,
            state: &DrawState {
                blend: Some(Blend {
                    color: add,
                    alpha: add,
                }),
                point_size: PointSize::One,
                depth: Depth::Off,
            },
            textures: &[("u_counts", flags.into())],
            uniforms: &[
                ("u_width", Uniform::I32(flags.width() as i32)),
                ("u_component", Uniform::I32(component)),
            ],
        });
    }

    /// The count so far (one read-back of one texel).
    pub(crate) fn total(&self) -> Result<u64> {
        Ok(self.target.only_texture().read_f32()?[0].round() as u64)
    }
}
