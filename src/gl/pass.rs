//! The full-screen pass: one attribute-less triangle covering the viewport, so that every texel
//! of the target runs the fragment program once (the papers' full-screen quad, thesis §3.5).

use super::{
    Context, Defines, Draw, DrawState, Framebuffer, PingPong, Primitive, Program, Rect, Sampled,
    VertexArray,
};
use std::rc::Rc;

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

    /// Runs `program` over every texel of `target`, reading `textures` (by sampler name, every
    /// one the program reads) with `uniforms` set on this draw (see [`Draw`]).
    pub fn draw(
        &self,
        program: &Program,
        textures: &[(&str, Sampled<'_>)],
        uniforms: &[(&str, Uniform)],
        target: &Framebuffer,
    ) {
        self.draw_rows(program, textures, uniforms, target, 0, target.height());
    }

    /// As [`draw`](Self::draw), with the fixed-function `state` given: a blend (a sum added into
    /// a tally).
    pub fn draw_with(
        &self,
        program: &Program,
        textures: &[(&str, Sampled<'_>)],
        uniforms: &[(&str, Uniform)],
        target: &Framebuffer,
        state: &DrawState,
    ) {
        self.ctx.draw(&Draw {
            program,
            target,
            viewport: None,
            vertices: &self.vao,
            primitive: Primitive::Triangles,
            count: 3,
            state,
            textures,
            uniforms,
        });
    }

    /// As [`draw`](Self::draw), over rows `y0..y0+rows` of `target` only (live-row restriction).
    /// Blending is off: every texel written is the program's output.
    pub fn draw_rows(
        &self,
        program: &Program,
        textures: &[(&str, Sampled<'_>)],
        uniforms: &[(&str, Uniform)],
        target: &Framebuffer,
        y0: u32,
        rows: u32,
    ) {
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
            textures,
            uniforms,
        });
    }
}

/// A uniform value: of a [`Draw`]'s uniforms, of [`StatePass::run`], of a [`UniformList`](super::UniformList).
#[derive(Debug, Clone, PartialEq)]
pub enum Uniform {
    /// `float`.
    F32(f32),
    /// `int` (or a sampler's unit, which only this layer sets).
    I32(i32),
    /// `uint`.
    U32(u32),
    /// `vec2`.
    Vec2(glam::Vec2),
    /// `vec3`.
    Vec3(glam::Vec3),
    /// `vec4`.
    Vec4(glam::Vec4),
    /// `ivec2`.
    IVec2(glam::IVec2),
    /// `ivec3`.
    IVec3(glam::IVec3),
    /// `ivec4`.
    IVec4(glam::IVec4),
    /// `mat4` (column-major, as glam stores it).
    Mat4(glam::Mat4),
    /// `int[]`, from its first element on (the name without `[0]`); empty sets nothing.
    I32s(Rc<[i32]>),
    /// `float[]`, likewise.
    F32s(Rc<[f32]>),
    /// `vec2[]`, likewise.
    Vec2s(Rc<[glam::Vec2]>),
    /// `vec3[]`, likewise.
    Vec3s(Rc<[glam::Vec3]>),
    /// `vec4[]`, likewise (orbiting spheres, emitters' curves: arrays that change between draws).
    Vec4s(Rc<[glam::Vec4]>),
    /// `ivec4[]`, likewise.
    IVec4s(Rc<[[i32; 4]]>),
}

impl Uniform {
    /// Whether it is one of the array variants.
    pub fn is_array(&self) -> bool {
        self.array_len().is_some()
    }

    /// Whether it holds the same value as `other`: the same shared array at once, else by value.
    pub(super) fn same_as(&self, other: &Uniform) -> bool {
        let shared = match (self.shared(), other.shared()) {
            (Some(a), Some(b)) => a == b,
            (Some(_), None) | (None, Some(_)) | (None, None) => false,
        };
        shared || self == other
    }

    /// An array's allocation and length (arrays of no element are never set).
    fn shared(&self) -> Option<(*const u8, usize)> {
        fn at<T>(a: &Rc<[T]>) -> Option<(*const u8, usize)> {
            Some((a.as_ptr() as *const u8, a.len()))
        }
        match self {
            Uniform::I32s(a) => at(a),
            Uniform::F32s(a) => at(a),
            Uniform::Vec2s(a) => at(a),
            Uniform::Vec3s(a) => at(a),
            Uniform::Vec4s(a) => at(a),
            Uniform::IVec4s(a) => at(a),
            Uniform::F32(_)
            | Uniform::I32(_)
            | Uniform::U32(_)
            | Uniform::Vec2(_)
            | Uniform::Vec3(_)
            | Uniform::Vec4(_)
            | Uniform::IVec2(_)
            | Uniform::IVec3(_)
            | Uniform::IVec4(_)
            | Uniform::Mat4(_) => None,
        }
    }

    /// An array of no element (which sets nothing).
    pub fn is_empty_array(&self) -> bool {
        self.array_len() == Some(0)
    }

    fn array_len(&self) -> Option<usize> {
        self.shared().map(|(_, n)| n)
    }
}

/// The samplers a [`StatePass`] reads its state through, one per texture.
const STATE_SAMPLERS: [&str; 4] = ["u_state0", "u_state1", "u_state2", "u_state3"];

/// A fragment pass of your own over a [`PingPong`] state: the public ping-pong pass API (what
/// three.js's `GPUComputationRenderer.addVariable` does, here in Rust; thesis §3.4-3.5).
///
/// Your fragment shader reads the state's front textures through `uniform sampler2D u_state0`,
/// `u_state1`, ... (one per texture, in the state's order, fetched with `texelFetch` at
/// `ivec2(gl_FragCoord.xy)`) and writes the back textures through
/// `layout(location = k) out vec4`, one output per texture. It is compiled like the crate's
/// own passes: no `#version` line (`#version 330 core` is prepended), `#include "common/rng.glsl"`
/// and the other files under `glsl/` work, and a compile error names your `name` and line.
/// [`run`](Self::run) draws the full-screen pass into the back and swaps, so that what was
/// written is the new front. State changes only by drawing, reads only by texel fetch.
///
/// ```
/// use texflow::gl::{Context, PingPong, StatePass, TextureFormat, Uniform};
///
/// let ctx = Context::new(0)?;
/// let formats = [TextureFormat::Rgba32F; 2];
/// let mut state = PingPong::new(&ctx, "mine", &["x", "v"], &formats, 4, 4)?;
/// state.front().texture(1).upload_f32(&[1.0; 4 * 16])?; // v = 1 everywhere, x = 0
/// let pass = StatePass::new(
///     &ctx,
///     "euler.frag",
///     "uniform sampler2D u_state0; uniform sampler2D u_state1; uniform float u_dt;
///      layout(location = 0) out vec4 o_x; layout(location = 1) out vec4 o_v;
///      void main() {
///          ivec2 t = ivec2(gl_FragCoord.xy);
///          vec4 v = texelFetch(u_state1, t, 0);
///          o_x = texelFetch(u_state0, t, 0) + v * u_dt;
///          o_v = v;
///      }",
///     state.front().textures().len(),
/// )?;
/// for _ in 0..10 {
///     pass.run(&mut state, &[("u_dt", Uniform::F32(0.25))]);
/// }
/// let x = state.front().texture(0).read_f32()?;
/// assert!(x.iter().all(|&x| (x - 2.5).abs() < 1e-6)); // x = v·t = 1 · 10 · 0.25
/// ctx.check_error("the example")?;
/// # Ok::<(), texflow::Error>(())
/// ```
#[derive(Debug)]
pub struct StatePass {
    program: Program,
    pass: FullscreenPass,
    targets: usize,
}

impl StatePass {
    /// Compiles `source` (a fragment shader, named `name` in errors) for a state of `targets`
    /// textures (1 to 4, the state's count: the pass writes every one).
    pub fn new(ctx: &Context, name: &str, source: &str, targets: usize) -> Result<Self> {
        if !(1..=4).contains(&targets) {
            return Err(crate::error::Error::InvalidInput(format!(
                "a state pass writes 1 to 4 textures, not {targets}"
            )));
        }
        Ok(StatePass {
            program: Program::with_fragment_source(
                ctx,
                FULLSCREEN_VERTEX,
                name,
                source,
                &Defines::new(),
            )?,
            pass: FullscreenPass::new(ctx)?,
            targets,
        })
    }

    /// The linked program (to set uniforms that stay the same between runs).
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// Runs the pass once: draws every texel of the back with the front's textures as
    /// `u_state0`.. and `uniforms` set, and swaps. Uniforms the shader does not use are
    /// ignored, as GL ignores them. Panics if `state` has another number of textures than the
    /// pass was made for (a programming error, like a wrong index).
    pub fn run(&self, state: &mut PingPong, uniforms: &[(&str, Uniform)]) {
        let n = state.front().textures().len();
        assert_eq!(
            n, self.targets,
            "the state has {n} textures; this pass was made for {}",
            self.targets
        );
        let p = &self.program;
        // The state's textures and the caller's uniforms that the shader declares; the others
        // are ignored, as GL ignores them.
        let textures: Vec<(&str, Sampled<'_>)> = STATE_SAMPLERS
            .iter()
            .zip(state.front().textures())
            .filter(|(name, _)| p.declares(name))
            .map(|(&name, t)| (name, t.into()))
            .collect();
        let uniforms: Vec<(&str, Uniform)> = uniforms
            .iter()
            .filter(|(name, _)| p.declares(name))
            .cloned()
            .collect();
        self.pass.draw(p, &textures, &uniforms, state.back());
        state.swap();
    }
}
