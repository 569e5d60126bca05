//! The vertex-texture-fetch point renderer (thesis Listing 3): one vertex per particle, position
//! fetched from the position texture in the vertex shader, additive blending.

use super::{Camera, FrameTarget};
use crate::error::Result;
use crate::gl::{
    Blend, BlendComponent, BlendFactor, Context, Defines, Draw, DrawState, PointSize, Primitive,
    Program, Texture, VertexArray,
};

/// Additive colour; the destination alpha stays as cleared (opaque).
const ADDITIVE: Blend = Blend {
    color: BlendComponent::add(BlendFactor::SrcAlpha, BlendFactor::One),
    alpha: BlendComponent::add(BlendFactor::Zero, BlendFactor::One),
};

/// How points look.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PointStyle {
    /// Point diameter in pixels.
    pub point_size: f32,
    /// Opacity of a newborn particle; additive, so many overlapping particles add up.
    pub intensity: f32,
    /// The fire cycle length, to derive each particle's age from its state (see fire.frag).
    pub max_age: f32,
    /// Soft round sprites (opacity falling to 0 at the rim) instead of square points: the
    /// thesis draws points and names their look a flaw (§4.1, §4.5.1).
    pub soft: bool,
}

impl From<&crate::scene::PointStyleSection> for PointStyle {
    fn from(s: &crate::scene::PointStyleSection) -> PointStyle {
        PointStyle {
            point_size: s.point_size,
            intensity: s.intensity,
            max_age: s.max_age,
            soft: s.soft,
        }
    }
}

/// Draws particles as points straight from the state textures.
#[derive(Debug)]
pub struct PointRenderer {
    ctx: Context,
    program: Program,
    vao: VertexArray,
}

impl PointRenderer {
    /// Builds the program.
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(PointRenderer {
            ctx: ctx.clone(),
            program: Program::new(
                ctx,
                "render/points.vert",
                "render/points.frag",
                &Defines::new(),
            )?,
            vao: VertexArray::empty(ctx, "points")?,
        })
    }

    /// Draws every particle of `positions`/`velocities` into `target` (not cleared first).
    pub fn draw(
        &self,
        target: &FrameTarget,
        positions: &Texture,
        velocities: &Texture,
        camera: &Camera,
        style: &PointStyle,
    ) {
        let p = &self.program;
        p.bind();
        p.textures(&[
            ("u_position", positions.into()),
            ("u_velocity", velocities.into()),
        ]);
        p.set_i32("u_width", positions.width() as i32);
        let aspect = target.width() as f32 / target.height() as f32;
        p.set_mat4("u_view_proj", &camera.view_projection(aspect));
        p.set_f32("u_point_size", style.point_size);
        p.set_f32("u_intensity", style.intensity);
        p.set_f32("u_max_age", style.max_age);
        p.set_i32("u_soft", style.soft as i32);
        self.ctx.draw(&Draw {
            program: p,
            target: target.framebuffer(),
            viewport: None,
            vertices: &self.vao,
            primitive: Primitive::Points,
            count: positions.texels() as u32,
            state: &DrawState {
                blend: Some(ADDITIVE),
                point_size: PointSize::Program,
                ..DrawState::REPLACE
            },
        });
    }
}
