//! Connected geometry over the state texture (`render.mode = "surface"`): a cloth sheet drawn as
//! a lit surface, hair as strands of line segments. The connectivity is the constraint layout's
//! grid (`sim::constraints::Layout`): an index buffer of texel numbers built once on the CPU;
//! the vertex stage fetches each vertex's position from the position texture by that number
//! (vertex texture fetch, as the particle renderer does), and the cloth's normals from its grid
//! neighbours (`glsl/render/cloth.vert`).

use glam::Vec3;

use super::{Camera, FrameTarget};
use crate::error::{Error, Result};
use crate::gl::{
    Buffer, BufferKind, BufferUsage, Context, Defines, Depth, Draw, DrawState, Primitive, Program,
    Texture, Uniform, VertexArray,
};
use crate::scene::ConstraintKind;

/// The fixed light of the surface (unit vector towards it): the colliders' light
/// (`render::geometry`), so that the cloth and the sphere under it are lit alike.
pub const SURFACE_LIGHT: [f32; 3] = [-0.70, 0.60, 0.35];

/// The ambient share of the surface's shading: a texel lit at grazing (or, for a strand, along
/// the light) keeps this fraction of the colour; one facing the light gets all of it.
pub const SURFACE_AMBIENT: f32 = 0.25;

/// The light direction, normalised.
pub fn surface_light() -> Vec3 {
    Vec3::from(SURFACE_LIGHT).normalize()
}

/// The texel numbers a grid of `size` texels draws, row-major (texel `(i, j)` is `j·w + i`).
/// Cloth: two triangles per cell, `(i, j) (i+1, j) (i+1, j+1)` and `(i, j) (i+1, j+1)
/// (i, j+1)`. Hair: one segment per pair of consecutive texels of a row (a row is a strand).
pub fn indices(kind: ConstraintKind, size: [u32; 2]) -> Vec<u32> {
    let [w, h] = size;
    let at = |i: u32, j: u32| j * w + i;
    let mut out = Vec::new();
    match kind {
        ConstraintKind::Cloth => {
            for j in 0..h.saturating_sub(1) {
                for i in 0..w.saturating_sub(1) {
                    let q = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                    out.extend_from_slice(&[q[0], q[1], q[2], q[0], q[2], q[3]]);
                }
            }
        }
        ConstraintKind::Hair => {
            for j in 0..h {
                for i in 0..w.saturating_sub(1) {
                    out.extend_from_slice(&[at(i, j), at(i + 1, j)]);
                }
            }
        }
    }
    out
}

/// Draws a constraint layout's particles as connected geometry.
pub struct ConnectedRenderer {
    ctx: Context,
    kind: ConstraintKind,
    size: [u32; 2],
    program: Program,
    vao: VertexArray,
    // Kept alive: the vertex array reads it.
    _indices: Buffer,
    count: u32,
    color: [f32; 3],
}

impl std::fmt::Debug for ConnectedRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ConnectedRenderer({:?}, {:?})", self.kind, self.size)
    }
}

impl ConnectedRenderer {
    /// The program each draw runs, for the pass list.
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// Builds the program and the index buffer for a `kind` layout of `size` texels, drawn in
    /// `color`.
    pub fn new(
        ctx: &Context,
        kind: ConstraintKind,
        size: [u32; 2],
        color: [f32; 3],
    ) -> Result<Self> {
        let list = indices(kind, size);
        if list.is_empty() {
            return Err(Error::InvalidInput(format!(
                "a {size:?} {kind:?} layout has no cell or segment to draw as a surface: give \
                 the state at least 2 texels a side, or use render.mode = \"points\""
            )));
        }
        let bytes: Vec<u8> = list.iter().flat_map(|i| i.to_ne_bytes()).collect();
        let buffer = Buffer::with_data(
            ctx,
            "surface indices",
            BufferKind::Vertex,
            &bytes,
            BufferUsage::StaticDraw,
        )?;
        let vao = VertexArray::with_indices(ctx, "surface", &[], &buffer)?;
        let (vert, frag) = shaders(kind);
        let program = Program::new(ctx, vert, frag, &Defines::new())?;
        Ok(ConnectedRenderer {
            ctx: ctx.clone(),
            kind,
            size,
            program,
            vao,
            _indices: buffer,
            count: list.len() as u32,
            color,
        })
    }

    /// The same layout drawn with `fragment` (a benchmark's fill floor: the same vertex stage
    /// and depth write, fragments that write a constant), compiled with `CONNECTED` defined: it
    /// should drop the fragments the surface drops (`v_ok` below 1).
    pub fn with_fragment(&self, fragment: &str) -> Result<Self> {
        let mut r = Self::new(&self.ctx, self.kind, self.size, self.color)?;
        let (vert, _) = shaders(self.kind);
        let defines: Defines = vec![("CONNECTED".into(), "1".into())];
        r.program = Program::new(&self.ctx, vert, fragment, &defines)?;
        Ok(r)
    }

    /// The pass's name in the scene's pass list.
    pub fn pass_name(&self) -> String {
        match self.kind {
            ConstraintKind::Cloth => "render cloth surface (texture fetch over an index buffer: \
                 2 triangles a grid cell, normals from the grid neighbours, Lambert + ambient, \
                 opaque, depth written)"
                .to_owned(),
            ConstraintKind::Hair => "render hair strands (texture fetch over an index buffer: \
                 a line segment between consecutive texels of a row, opaque, depth written)"
                .to_owned(),
        }
    }

    /// Draws the layout at `positions` (the state texture the layout was made for) into
    /// `target`, which needs a depth attachment (the surface hides itself).
    pub fn draw(&self, target: &FrameTarget, positions: &Texture, camera: &Camera) -> Result<()> {
        if [positions.width(), positions.height()] != self.size {
            return Err(Error::InvalidInput(format!(
                "position texture is {}x{}, the surface was made for {}x{}",
                positions.width(),
                positions.height(),
                self.size[0],
                self.size[1]
            )));
        }
        if !target.has_depth() {
            return Err(Error::InvalidInput(
                "a surface needs a frame target with depth (FrameTarget::with_depth)".into(),
            ));
        }
        let p = &self.program;
        let aspect = target.width() as f32 / target.height() as f32;
        // The camera changes from frame to frame: it travels with the draw.
        let mut per_frame = vec![("u_view_proj", Uniform::Mat4(camera.view_projection(aspect)))];
        if self.kind == ConstraintKind::Cloth {
            per_frame.push(("u_eye", Uniform::Vec3(camera.eye())));
        }
        per_frame.extend([
            ("u_light", Uniform::Vec3(surface_light())),
            ("u_color", Uniform::Vec3(Vec3::from(self.color))),
            ("u_ambient", Uniform::F32(SURFACE_AMBIENT)),
        ]);
        // A floor's constant fragment stage declares none of the shading's uniforms.
        per_frame.retain(|(name, _)| p.declares(name));
        let primitive = match self.kind {
            ConstraintKind::Cloth => Primitive::Triangles,
            ConstraintKind::Hair => Primitive::Lines,
        };
        self.ctx.draw(&Draw {
            program: p,
            target: target.framebuffer(),
            viewport: None,
            vertices: &self.vao,
            primitive,
            count: self.count,
            state: &DrawState {
                depth: Depth::Write,
                color_writes: true,
                ..DrawState::REPLACE
            },
            textures: &[("u_position", positions.into())],
            uniforms: &per_frame,
        });
        self.ctx.check_error("drawing the surface")
    }
}

/// The vertex and fragment shaders that draw a `kind` layout.
fn shaders(kind: ConstraintKind) -> (&'static str, &'static str) {
    match kind {
        ConstraintKind::Cloth => ("render/cloth.vert", "render/cloth.frag"),
        ConstraintKind::Hair => ("render/strand.vert", "render/strand.frag"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn indices_cover_each_cell_and_segment_once() {
        let c = indices(ConstraintKind::Cloth, [3, 2]);
        assert_eq!(c, vec![0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4]);
        let h = indices(ConstraintKind::Hair, [3, 2]);
        assert_eq!(h, vec![0, 1, 1, 2, 3, 4, 4, 5]);
    }
}
