//! The renderer of the colliders' triangles ([`GeometryRenderer`]): one vertex buffer, the
//! opaque pass before the particles, the soft particles' depth pass.

use glam::Vec3;

use super::super::{Camera, FrameTarget};
use super::{Mesh, FLOATS};
use crate::error::{Error, Result};
use crate::gl::{
    Attribute, Blend, BlendComponent, BlendFactor, Buffer, BufferKind, BufferUsage, Context,
    Defines, Depth, Draw, DrawState, Primitive, Program, Uniform, VertexArray,
};

/// The soft particles' depth pass: the geometry's vertices, their view depth.
const GEOMETRY_VERTEX: &str = "render/geometry.vert";
const GEOMETRY_DEPTH: &str = "render/geometry_depth.frag";

/// Draws a scene's colliders.
pub struct GeometryRenderer {
    program: Program,
    /// The view-depth program of soft particles, built at its first use.
    depth_program: std::cell::OnceCell<Program>,
    buffer: Buffer,
    vao: VertexArray,
    count: u32,
    ctx: Context,
}

impl std::fmt::Debug for GeometryRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "GeometryRenderer({} vertices)", self.count)
    }
}

impl GeometryRenderer {
    /// The program each draw runs, for the pass list.
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// The soft particles' depth program (built at its first use), for the pass list.
    pub fn depth_program_name() -> String {
        format!("{GEOMETRY_VERTEX}+{GEOMETRY_DEPTH}")
    }

    /// Uploads `mesh` (not empty) and builds the program.
    pub fn new(ctx: &Context, mesh: &Mesh) -> Result<Self> {
        if mesh.is_empty() {
            return Err(Error::InvalidInput(
                "render.geometry = true draws the scene's colliders, and it has none: add a \
                 collider or remove the key"
                    .into(),
            ));
        }
        let bytes: Vec<u8> = mesh.vertices.iter().flat_map(|v| v.to_ne_bytes()).collect();
        let buffer = Buffer::with_data(
            ctx,
            "geometry vertices",
            BufferKind::Vertex,
            &bytes,
            BufferUsage::StreamDraw,
        )?;
        let stride = (FLOATS * 4) as i32;
        let attribute = |location, components, offset| Attribute {
            buffer: &buffer,
            location,
            components,
            stride,
            offset,
        };
        let vao = VertexArray::with_attributes(
            ctx,
            "geometry",
            &[attribute(0, 3, 0), attribute(1, 3, 12), attribute(2, 4, 24)],
        )?;
        let program = Program::new(
            ctx,
            "render/geometry.vert",
            "render/geometry.frag",
            &Defines::new(),
        )?;
        Ok(GeometryRenderer {
            program,
            depth_program: std::cell::OnceCell::new(),
            count: mesh.len() as u32,
            buffer,
            vao,
            ctx: ctx.clone(),
        })
    }

    /// Replaces the triangles with `mesh`, which must have as many (the colliders moved).
    pub fn replace(&self, mesh: &Mesh) -> Result<()> {
        if mesh.len() as u32 != self.count {
            return Err(Error::InvalidInput(format!(
                "geometry of {} vertices replaced by {}: a moved collider keeps its triangles",
                self.count,
                mesh.len()
            )));
        }
        let bytes: Vec<u8> = mesh.vertices.iter().flat_map(|v| v.to_ne_bytes()).collect();
        self.buffer.replace(&bytes)
    }

    /// Draws the triangles into `target` with `state` (the caller picks the depth and blend:
    /// opaque with a depth write, a depth-only pass, or composited under).
    pub fn draw(&self, target: &FrameTarget, camera: &Camera, state: &DrawState) {
        let p = &self.program;
        let aspect = target.width() as f32 / target.height() as f32;
        self.ctx.draw(&Draw {
            program: p,
            target: target.framebuffer(),
            viewport: None,
            vertices: &self.vao,
            primitive: Primitive::Triangles,
            count: self.count,
            state,
            textures: &[],
            // The camera changes from frame to frame: it travels with the draw.
            uniforms: &[
                ("u_view_proj", Uniform::Mat4(camera.view_projection(aspect))),
                ("u_eye", Uniform::Vec3(camera.eye())),
                (
                    "u_light",
                    Uniform::Vec3(Vec3::new(-0.7, 0.6, 0.35).normalize()),
                ),
            ],
        });
    }

    /// Draws the triangles' view depth into `fb` (R32F with depth, cleared by the caller) for
    /// soft particles: render/geometry_depth.frag.
    pub fn draw_depth(&self, fb: &crate::gl::Framebuffer, view_proj: &glam::Mat4) -> Result<()> {
        if self.depth_program.get().is_none() {
            let (v, f) = (GEOMETRY_VERTEX, GEOMETRY_DEPTH);
            let p = Program::new(&self.ctx, v, f, &Defines::new())?;
            let _ = self.depth_program.set(p);
        }
        let Some(p) = self.depth_program.get() else {
            return Err(Error::InvalidInput("the geometry's depth program".into()));
        };
        self.ctx.draw(&Draw {
            program: p,
            target: fb,
            viewport: None,
            vertices: &self.vao,
            primitive: Primitive::Triangles,
            count: self.count,
            state: &DrawState {
                depth: crate::gl::Depth::Write,
                color_writes: true,
                ..DrawState::REPLACE
            },
            textures: &[],
            uniforms: &[("u_view_proj", Uniform::Mat4(*view_proj))],
        });
        Ok(())
    }
}

/// The state of the geometry's first pass: opaque with a depth write, before the particles. For
/// the under operator (front to back, the target cleared transparent) an opaque surface drawn
/// first would hide everything composited after it, so the first pass writes only depth (the
/// colour blended with factors 0 and 1 stays as it is); the geometry's colour is composited
/// under the particles after them, at the depth it wrote.
pub(in crate::render) fn first_pass_state(under: bool) -> DrawState {
    let keep = BlendComponent::add(BlendFactor::Zero, BlendFactor::One);
    DrawState {
        blend: under.then_some(Blend {
            color: keep,
            alpha: keep,
        }),
        depth: Depth::Write,
        color_writes: true,
        ..DrawState::REPLACE
    }
}
