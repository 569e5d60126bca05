//! Draws described as data: what a pass draws, where, and with which fixed-function state.
//!
//! [`Context::draw`] sets every piece of [`DrawState`] on every draw, so no pass depends on what
//! the previous one left behind (the shape follows wgpu-hal's `ColorTargetDesc { blend:
//! Option<BlendDesc> }`). The factors and operations are this layer's own enums, so code above
//! `gl` never names a GL constant.

use glow::HasContext;

use super::{Context, Framebuffer, Program, Sampled, Uniform, VertexArray};

/// A blend factor: what the source or the destination colour is multiplied by.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BlendFactor {
    /// 0.
    Zero,
    /// 1.
    One,
    /// The source colour.
    SrcColor,
    /// 1 − the source colour.
    OneMinusSrcColor,
    /// The source alpha.
    SrcAlpha,
    /// 1 − the source alpha.
    OneMinusSrcAlpha,
    /// The destination colour.
    DstColor,
    /// 1 − the destination colour.
    OneMinusDstColor,
    /// The destination alpha.
    DstAlpha,
    /// 1 − the destination alpha.
    OneMinusDstAlpha,
}

impl BlendFactor {
    fn gl(self) -> u32 {
        match self {
            BlendFactor::Zero => glow::ZERO,
            BlendFactor::One => glow::ONE,
            BlendFactor::SrcColor => glow::SRC_COLOR,
            BlendFactor::OneMinusSrcColor => glow::ONE_MINUS_SRC_COLOR,
            BlendFactor::SrcAlpha => glow::SRC_ALPHA,
            BlendFactor::OneMinusSrcAlpha => glow::ONE_MINUS_SRC_ALPHA,
            BlendFactor::DstColor => glow::DST_COLOR,
            BlendFactor::OneMinusDstColor => glow::ONE_MINUS_DST_COLOR,
            BlendFactor::DstAlpha => glow::DST_ALPHA,
            BlendFactor::OneMinusDstAlpha => glow::ONE_MINUS_DST_ALPHA,
        }
    }
}

/// How the weighted source and destination are combined.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum BlendOperation {
    /// source · src_factor + destination · dst_factor.
    #[default]
    Add,
    /// source · src_factor − destination · dst_factor.
    Subtract,
    /// destination · dst_factor − source · src_factor.
    ReverseSubtract,
    /// The smaller of source and destination (factors ignored).
    Min,
    /// The larger of source and destination (factors ignored).
    Max,
}

impl BlendOperation {
    fn gl(self) -> u32 {
        match self {
            BlendOperation::Add => glow::FUNC_ADD,
            BlendOperation::Subtract => glow::FUNC_SUBTRACT,
            BlendOperation::ReverseSubtract => glow::FUNC_REVERSE_SUBTRACT,
            BlendOperation::Min => glow::MIN,
            BlendOperation::Max => glow::MAX,
        }
    }
}

/// The blend equation of the colour or of the alpha channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct BlendComponent {
    /// Factor of the fragment's value.
    pub src_factor: BlendFactor,
    /// Factor of the value already in the target.
    pub dst_factor: BlendFactor,
    /// How the two are combined.
    pub operation: BlendOperation,
}

impl BlendComponent {
    /// `src · src_factor + dst · dst_factor`.
    pub const fn add(src_factor: BlendFactor, dst_factor: BlendFactor) -> Self {
        BlendComponent {
            src_factor,
            dst_factor,
            operation: BlendOperation::Add,
        }
    }
}

/// Blending of colour and alpha.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Blend {
    /// The RGB channels.
    pub color: BlendComponent,
    /// The alpha channel.
    pub alpha: BlendComponent,
}

impl Blend {
    /// `src + dst` in every channel: a sum added into a tally, an additive probe.
    pub const SUM: Blend = Blend {
        color: BlendComponent::add(BlendFactor::One, BlendFactor::One),
        alpha: BlendComponent::add(BlendFactor::One, BlendFactor::One),
    };
}

/// Where a point's size comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PointSize {
    /// `gl_PointSize` written by the vertex shader (`GL_PROGRAM_POINT_SIZE`).
    Program,
    /// One pixel: GL's initial `glPointSize`, which nothing changes (glow does not expose it).
    One,
}

/// Depth testing against the target's depth attachment (see [`Framebuffer::with_depth`]);
/// only the frame target of a scene that draws its geometry has one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Depth {
    /// No test, no write: every simulation and sort pass, and every frame without geometry.
    #[default]
    Off,
    /// Nearer fragments pass (`GL_LESS`) and write their depth: opaque geometry.
    Write,
    /// Nearer fragments pass (`GL_LESS`); the depth is kept: blended particles in front of the
    /// geometry, none of which hides another.
    Test,
    /// Fragments at or before the stored depth pass (`GL_LEQUAL`), the depth is kept: the
    /// same geometry drawn a second time onto the depth it wrote.
    Equal,
}

/// The fixed-function state of a draw, all of it set by [`Context::draw`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DrawState {
    /// `None`: fragments replace what is in the target.
    pub blend: Option<Blend>,
    /// Point size (points only).
    pub point_size: PointSize,
    /// Depth test and write (a target without a depth attachment passes every test).
    pub depth: Depth,
    /// Whether fragments write the colour attachments (`glColorMask`): off only for a
    /// benchmark floor that times a draw's vertices and rasterization alone.
    pub color_writes: bool,
}

impl DrawState {
    /// No blending, points one pixel wide, no depth test: what every simulation and sort pass
    /// draws with.
    pub const REPLACE: DrawState = DrawState {
        blend: None,
        point_size: PointSize::One,
        depth: Depth::Off,
        color_writes: true,
    };
}

impl Default for DrawState {
    fn default() -> Self {
        DrawState::REPLACE
    }
}

/// What the vertices are assembled into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Primitive {
    /// One point per vertex.
    Points,
    /// One triangle per three vertices.
    Triangles,
    /// One line segment per two vertices.
    Lines,
}

/// A rectangle of a target in texels, origin at the bottom left.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Rect {
    /// Left edge.
    pub x: u32,
    /// Bottom edge.
    pub y: u32,
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

/// One draw call, described in full: what it draws, where, with which state, and what it reads
/// (its textures and per-draw uniforms).
#[derive(Debug, Clone, Copy)]
pub struct Draw<'a> {
    /// The program. Every uniform it reads goes in [`uniforms`](Self::uniforms).
    pub program: &'a Program,
    /// The framebuffer drawn into.
    pub target: &'a Framebuffer,
    /// The viewport; `None`: all of the target.
    pub viewport: Option<Rect>,
    /// The vertex array (an empty one for draws that use only `gl_VertexID`).
    pub vertices: &'a VertexArray,
    /// What the vertices make.
    pub primitive: Primitive,
    /// Number of vertices, from the first (of indices, for an indexed vertex array).
    pub count: u32,
    /// Blending and point size.
    pub state: &'a DrawState,
    /// The textures the program reads, by sampler name: the k-th goes to texture unit k. Every
    /// active sampler of the program must be listed (see [`Context::draw`]).
    pub textures: &'a [(&'a str, Sampled<'a>)],
    /// Every uniform this draw reads, set after the textures; a value the program holds already
    /// is not uploaded again (see [`Context::set_uniform_cache`]).
    pub uniforms: &'a [(&'a str, Uniform)],
}

impl Context {
    /// Runs one draw: binds its program, gives its textures units 0.. in order and sets their
    /// samplers, sets its uniforms, binds its target (with its viewport) and vertices, sets all
    /// of its state, draws, and unbinds the vertex array. A count of 0 draws nothing.
    ///
    /// Panics if the program reads a sampler that [`Draw::textures`] does not list (it would
    /// read whatever an earlier draw left on that unit), and, in debug builds, if a listed
    /// texture or uniform names nothing the program declares.
    pub fn draw(&self, d: &Draw<'_>) {
        super::record::note(d.program.name());
        d.program.bind();
        d.program.bind_textures(d.textures);
        for (name, value) in d.uniforms {
            d.program.set(name, value);
        }
        // After the uniforms: a shape keeps the values the draw read.
        super::record::note_shape(d);
        match d.viewport {
            Some(r) => d.target.bind_rect(r.x, r.y, r.width, r.height),
            None => d.target.bind(),
        }
        d.vertices.bind();
        self.set_state(d.state);
        let texels = match d.viewport {
            Some(r) => r.width as u64 * r.height as u64,
            None => d.target.width() as u64 * d.target.height() as u64,
        };
        let bytes = match d.primitive {
            Primitive::Triangles => texels * d.target.bytes_per_texel() as u64,
            Primitive::Points | Primitive::Lines => 0,
        };
        let n = d.count as u64;
        let to = (d.target, d.textures);
        match d.primitive {
            Primitive::Triangles => self.count_draw(to, true, bytes, (0, n)),
            Primitive::Points => self.count_draw(to, false, 0, (n, n)),
            Primitive::Lines => self.count_draw(to, false, 0, (0, n)),
        }
        let profiled = super::profile::before(self);
        let mode = match d.primitive {
            Primitive::Points => glow::POINTS,
            Primitive::Triangles => glow::TRIANGLES,
            Primitive::Lines => glow::LINES,
        };
        // SAFETY: a linked program, a complete framebuffer and a vertex array whose buffers hold
        // `count` vertices (the caller's contract) are bound.
        unsafe {
            if d.count > 0 && d.vertices.indexed() {
                self.gl()
                    .draw_elements(mode, d.count as i32, glow::UNSIGNED_INT, 0);
            } else if d.count > 0 {
                self.gl().draw_arrays(mode, 0, d.count as i32);
            }
            self.gl().bind_vertex_array(None);
            // glClear obeys the colour mask: no later clear may inherit a floor's.
            if !d.state.color_writes {
                self.gl().color_mask(true, true, true, true);
            }
        }
        if profiled {
            super::profile::after(self, d.program.name(), d.target.label(), bytes);
        }
    }

    fn set_state(&self, s: &DrawState) {
        // SAFETY: plain state changes on the current context.
        unsafe {
            match s.depth {
                Depth::Off => self.gl().disable(glow::DEPTH_TEST),
                Depth::Write | Depth::Test | Depth::Equal => {
                    self.gl().enable(glow::DEPTH_TEST);
                    let func = if s.depth == Depth::Equal {
                        glow::LEQUAL
                    } else {
                        glow::LESS
                    };
                    self.gl().depth_func(func);
                    self.gl().depth_mask(s.depth == Depth::Write);
                }
            }
            match s.point_size {
                PointSize::Program => self.gl().enable(glow::PROGRAM_POINT_SIZE),
                PointSize::One => self.gl().disable(glow::PROGRAM_POINT_SIZE),
            }
            let w = s.color_writes;
            self.gl().color_mask(w, w, w, w);
            match s.blend {
                None => self.gl().disable(glow::BLEND),
                Some(b) => {
                    self.gl().enable(glow::BLEND);
                    self.gl()
                        .blend_equation_separate(b.color.operation.gl(), b.alpha.operation.gl());
                    self.gl().blend_func_separate(
                        b.color.src_factor.gl(),
                        b.color.dst_factor.gl(),
                        b.alpha.src_factor.gl(),
                        b.alpha.dst_factor.gl(),
                    );
                }
            }
        }
    }
}
