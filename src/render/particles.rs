//! The general particle renderer: points or rotated, textured point sprites (Latta §3.4.6), or
//! camera-facing quads and velocity-stretched quads built by vertex replication (Latta §3.4.5:
//! six vertices per particle fetch the same texel), fed either by vertex texture fetch (thesis
//! Listing 3) or, for points, by a vertex buffer the state textures are copied into on the GPU
//! (UberFlow §4.7, Latta §3.4.5), coloured by keyframes of relative age per particle type,
//! blended additively, multiplicatively, or with the over / under operator.
//!
//! State layout (fixed by the simulation): particle `i` is texel `(i % width, i / width)` of every
//! state texture.
//! - positions (RGBA32F): xyz position, w remaining life in seconds. Drawn only if w > 0 and xyz
//!   is finite (dead: w <= 0 and xyz = +inf; unborn: w < 0).
//! - statics (RGBA32F): x birth time, y type (0..3), z total life (0 or +inf: permanent, relative
//!   age 0), w a random number in [0, 1) (the sprite's angle; hashed, its rotation speed).
//! - motion (stretched quads only): velocities (xyz), or the previous positions of Verlet.
//!
//! Relative age = clamp(1 − position.w / statics.z, 0, 1).

use super::atlas;

// The pass list, in the papers' words, beside the code that draws it.
mod names;
// The benchmarks' fill floor: this renderer with a constant fragment stage.
mod floor;
use super::vertex_path::{vertex_path, VertexPath};
use super::{
    Camera, ConnectedRenderer, FrameTarget, GeometryRenderer, ParticleStyle, RenderParams,
};
use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Depth, Draw, DrawState, Primitive, Program, Sampled, Texture, Uniform,
    VertexArray,
};
use crate::scene::{DrawMode, DrawPrimitive, RenderPath, Rotate, MAX_USER_STATES};

/// What a particle draw reads: its vertices, textures, and the uniforms that go with them.
type Inputs<'a> = (
    &'a VertexArray,
    Vec<(&'a str, Sampled<'a>)>,
    Vec<(&'static str, Uniform)>,
);

/// Vertices per particle of quads and stretched quads: two triangles.
pub const QUAD_VERTICES: usize = 6;

/// The samplers `render.color` reads the user states through (`u_user_state_i` is state `i`,
/// as src/render/user_color.rs declares them), one per state the scene may have.
const USER_STATE_SAMPLERS: [&str; MAX_USER_STATES] = [
    "u_user_state_0",
    "u_user_state_1",
    "u_user_state_2",
    "u_user_state_3",
];

/// What the stretched quads stretch along (Latta's state: a velocity texture for explicit
/// integrators, the previous positions for Verlet).
#[derive(Debug, Clone, Copy)]
pub enum Motion<'a> {
    /// Velocities (xyz) in the state layout.
    Velocity(&'a Texture),
    /// Verlet's previous positions, one step of `dt` seconds back: v = (x − x_prev) / dt.
    Previous {
        /// The previous positions.
        positions: &'a Texture,
        /// The step between them and the current positions.
        dt: f32,
    },
}

impl<'a> Motion<'a> {
    fn texture(&self) -> &'a Texture {
        match *self {
            Motion::Velocity(t) => t,
            Motion::Previous { positions, .. } => positions,
        }
    }
}

/// One frame's state for [`ParticleRenderer::draw_frame`].
#[derive(Debug, Clone, Copy)]
pub struct FrameState<'a> {
    /// Positions and remaining life.
    pub positions: &'a Texture,
    /// Birth time, type, total life, random number.
    pub statics: &'a Texture,
    /// Velocities or previous positions (stretched quads need them).
    pub motion: Option<Motion<'a>>,
    /// Simulation time in seconds (the age of permanent particles, for their rotation).
    pub time: f32,
    /// Spinning spheres' spins (angular velocity, angle about z), in the same order as
    /// `positions`: sprites with `rotate = "spin"` take their angle from them.
    pub spins: Option<&'a Texture>,
    /// Particles `0..count` are drawn.
    pub count: usize,
    /// The user states (`[[state]]`) in the order of `positions`, for `render.color`.
    pub user: &'a [&'a Texture],
}

/// Draws particles from their state textures.
pub struct ParticleRenderer {
    ctx: Context,
    style: ParticleStyle,
    /// The numbers its uniforms carry ([`RenderParams::of`] the style).
    params: RenderParams,
    width: u32,
    height: u32,
    program: Program,
    background: Program,
    empty: VertexArray,
    vertex: Option<VertexPath>,
    /// Shared with a benchmark's shading floor, which fetches the same tiles.
    atlas: Option<std::rc::Rc<Texture>>,
    /// Shared with a benchmark's floor renderer, which draws the colliders where they are now.
    geometry: Option<std::rc::Rc<GeometryRenderer>>,
    connected: Option<ConnectedRenderer>,
    ribbons: Option<super::RibbonRenderer>,
    /// The index lookup's program variant and the sort texture's layout (Latta §3.4.4).
    lookup: Option<(Program, super::SortLayout)>,
    /// The geometry's view depth, for soft particles (`render.soft`).
    soft: super::soft::SoftDepth,
}

impl std::fmt::Debug for ParticleRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (w, h) = (self.width, self.height);
        write!(f, "ParticleRenderer({w}x{h}, {:?})", self.pass_names())
    }
}

impl ParticleRenderer {
    /// Builds the program variant for `style` and, for the vertex-buffer path, two buffers of
    /// `state_width`×`state_height` RGBA float vertices; for sprites, the atlas.
    pub fn new(
        ctx: &Context,
        style: ParticleStyle,
        state_width: u32,
        state_height: u32,
    ) -> Result<Self> {
        crate::gl::check_size(ctx, "particle state", state_width, state_height)?;
        let defines = super::style::style_defines(ctx, &style)?;
        let program = match &style.user_color {
            None => Program::new(
                ctx,
                "render/particle.vert",
                "render/particle.frag",
                &defines,
            )?,
            Some(u) => Program::new(ctx, &u.root(), "render/particle.frag", &defines)
                .map_err(|e| u.error(e))?,
        };
        let background = Program::new(
            ctx,
            crate::gl::FULLSCREEN_VERTEX,
            "render/background.frag",
            &Defines::new(),
        )?;
        let vertex = if style.path == RenderPath::VertexBuffer {
            Some(vertex_path(ctx, state_width, state_height)?)
        } else {
            None
        };
        let atlas = if style.mode == DrawMode::Sprites {
            Some(std::rc::Rc::new(atlas::upload(
                ctx,
                &atlas::generate(atlas::DEFAULT_TILE),
            )?))
        } else {
            None
        };
        Ok(ParticleRenderer {
            ctx: ctx.clone(),
            params: RenderParams::of(&style),
            style,
            width: state_width,
            height: state_height,
            program,
            background,
            empty: VertexArray::empty(ctx, "particles")?,
            vertex,
            atlas,
            geometry: None,
            connected: None,
            ribbons: None,
            lookup: None,
            soft: Default::default(),
        })
    }

    /// Whether it draws the particles as connected geometry (a surface, strands), not one
    /// point or sprite each.
    pub fn draws_connected(&self) -> bool {
        self.connected.is_some()
    }

    /// Draws `geometry` (the scene's colliders) with every frame, opaque, and the particles
    /// depth-tested against it (the style's `depth_test`); the target needs a depth attachment
    /// ([`FrameTarget::with_depth`]).
    pub fn set_geometry(&mut self, geometry: GeometryRenderer) {
        self.style.depth_test = true;
        self.geometry = Some(std::rc::Rc::new(geometry));
    }

    /// Draws `ribbons` between trail children after the particles, in their blend.
    pub fn set_ribbons(&mut self, ribbons: super::RibbonRenderer) {
        self.ribbons = Some(ribbons);
    }

    /// Draws the particles as `connected` geometry (a cloth surface, hair strands) instead of
    /// points; the target needs a depth attachment.
    pub fn set_connected(&mut self, connected: ConnectedRenderer) {
        self.connected = Some(connected);
    }

    /// Replaces the geometry's triangles (colliders that moved), if it draws geometry.
    pub fn replace_geometry(&mut self, mesh: &super::Mesh) -> Result<()> {
        match &self.geometry {
            Some(g) => g.replace(mesh),
            None => Ok(()),
        }
    }

    /// The style.
    pub fn style(&self) -> &ParticleStyle {
        &self.style
    }

    /// Its passes' numbers (blend, clear, point size...): the benchmarks' floors read them too.
    pub fn params(&self) -> &RenderParams {
        &self.params
    }

    /// Replaces the sprite atlas (sprites only) by `image`, e.g. a scene's own tiles.
    pub fn set_atlas(&mut self, image: &atlas::AtlasImage) -> Result<()> {
        if self.style.mode != DrawMode::Sprites {
            return Err(Error::InvalidInput(
                "only sprites have an atlas: use mode = \"sprites\"".into(),
            ));
        }
        self.atlas = Some(std::rc::Rc::new(atlas::upload(&self.ctx, image)?));
        Ok(())
    }

    /// The sprite atlas (sprites only).
    pub fn atlas(&self) -> Option<&Texture> {
        self.atlas.as_deref()
    }

    /// Clears `target` to the background (transparent black for the under operator, whose
    /// background is composited at the end of [`draw`](Self::draw)).
    pub fn clear(&self, target: &FrameTarget) {
        target.clear_to(self.params.clear_color);
    }

    fn check_state(&self, what: &str, t: &Texture) -> Result<()> {
        if t.width() != self.width || t.height() != self.height {
            return Err(Error::InvalidInput(format!(
                "{what} texture is {}x{}, the renderer was made for {}x{}",
                t.width(),
                t.height(),
                self.width,
                self.height
            )));
        }
        if !t.format().is_float() || t.format().channels() != 4 {
            return Err(Error::InvalidInput(format!(
                "{what} texture is {}: the renderer reads RGBA floats",
                t.format().name()
            )));
        }
        Ok(())
    }

    /// Draws particles `0..count` in index order into `target` at time 0, without motion (see
    /// [`draw_frame`](Self::draw_frame)).
    pub fn draw(
        &self,
        target: &FrameTarget,
        positions: &Texture,
        statics: &Texture,
        camera: &Camera,
        count: usize,
    ) -> Result<()> {
        let state = FrameState {
            positions,
            statics,
            motion: None,
            time: 0.0,
            spins: None,
            count,
            user: &[],
        };
        self.draw_frame(target, &state, camera)
    }

    /// Whether [`draw_frame`](Self::draw_frame) needs [`FrameState::spins`] (sprites turned by
    /// the spin).
    pub fn needs_spins(&self) -> bool {
        self.style.rotate == Rotate::Spin
    }

    /// Whether [`draw_frame`](Self::draw_frame) needs [`FrameState::motion`] (stretched quads).
    pub fn needs_motion(&self) -> bool {
        self.style.primitive == DrawPrimitive::Stretched
    }

    /// Draws particles `0..state.count` in index order into `target` (not cleared first; see
    /// [`clear`](Self::clear)). Alpha blending needs them already in the style's order (a GPU
    /// sort rearranges the state, the motion texture with it). With the under operator the
    /// background is composited under the particles at the end, which leaves the frame opaque.
    pub fn draw_frame(
        &self,
        target: &FrameTarget,
        state: &FrameState<'_>,
        camera: &Camera,
    ) -> Result<()> {
        self.draw_through(target, state, camera, None)
    }

    /// Builds the index lookup's program for sort textures of `layout` (texture fetch only):
    /// see [`draw_frame_sorted`](Self::draw_frame_sorted).
    pub fn set_lookup(&mut self, layout: super::SortLayout) -> Result<()> {
        if self.style.path != RenderPath::TextureFetch || self.connected.is_some() {
            return Err(Error::InvalidInput(
                "the index lookup fetches each particle's texel at its id: use path = \"texture_fetch\" \
                 and points or sprites"
                    .into(),
            ));
        }
        let mut d = super::style::style_defines(&self.ctx, &self.style)?;
        d.extend(layout.defines());
        let p = Program::new(
            &self.ctx,
            "render/particle.vert",
            "render/particle.frag",
            &d,
        )?;
        self.lookup = Some((p, layout));
        Ok(())
    }

    /// [`draw_frame`](Self::draw_frame) in the order of the sort texture `sorted` (Latta §3.4.4):
    /// vertex k draws the particle whose id is at sorted position k, fetched from the unsorted
    /// `state`; needs [`set_lookup`](Self::set_lookup).
    pub fn draw_frame_sorted(
        &self,
        target: &FrameTarget,
        state: &FrameState<'_>,
        camera: &Camera,
        sorted: &Texture,
    ) -> Result<()> {
        self.draw_through(target, state, camera, Some(sorted))
    }

    fn draw_through(
        &self,
        target: &FrameTarget,
        state: &FrameState<'_>,
        camera: &Camera,
        sorted: Option<&Texture>,
    ) -> Result<()> {
        let count = state.count;
        let motion = self.frame_motion(state)?;
        let s = &self.style;
        let scene_depth = self.draw_geometry_first(target, camera)?;
        if let Some(c) = &self.connected {
            return c.draw(target, state.positions, camera);
        }
        let p = match (sorted, &self.lookup) {
            (None, _) => &self.program,
            (Some(_), Some((p, _))) => p,
            (Some(_), None) => {
                return Err(Error::InvalidInput(
                    "drawing through the sorted index needs set_lookup first".into(),
                ))
            }
        };
        let (vertices, textures, inputs) =
            self.bind_inputs(p, state, motion, [sorted, scene_depth])?;
        let size = glam::Vec2::new(target.width() as f32, target.height() as f32);
        // The camera and the clock change from frame to frame: they travel with the draw.
        let mut per_frame = vec![
            (
                "u_view_proj",
                Uniform::Mat4(camera.view_projection(size.x / size.y)),
            ),
            ("u_viewport", Uniform::Vec2(size)),
            ("u_time", Uniform::F32(state.time)),
        ];
        per_frame.extend(inputs);
        per_frame.extend(self.params.sprite_uniforms());
        let (primitive, per_particle) = match s.primitive {
            DrawPrimitive::Points => (Primitive::Points, 1),
            DrawPrimitive::Triangles => (Primitive::Triangles, 3),
            DrawPrimitive::Quads | DrawPrimitive::Stretched => {
                (Primitive::Triangles, QUAD_VERTICES)
            }
        };
        let draw_state = self.params.draw_state(s.depth_test);
        let gl = &self.ctx;
        gl.draw(&Draw {
            program: p,
            target: target.framebuffer(),
            viewport: None,
            vertices,
            primitive,
            count: (count * per_particle) as u32,
            state: &draw_state,
            textures: &textures,
            uniforms: &per_frame,
        });
        self.draw_under(target, state, camera, &draw_state)?;
        gl.check_error("drawing particles")
    }

    /// The geometry's first pass (opaque, or depth only under the under operator), and for soft
    /// particles the scene's depth it leaves.
    fn draw_geometry_first(
        &self,
        target: &FrameTarget,
        camera: &Camera,
    ) -> Result<Option<&Texture>> {
        if let Some(g) = &self.geometry {
            if !target.has_depth() {
                return Err(Error::InvalidInput(
                    "drawing geometry needs a frame target with depth (FrameTarget::with_depth)"
                        .into(),
                ));
            }
            let first = super::geometry::first_pass_state(self.style.under());
            g.draw(target, camera, &first);
        }
        match (self.style.soft > 0.0, &self.geometry) {
            (false, _) => Ok(None),
            (true, Some(g)) => Ok(Some(self.soft.draw(&self.ctx, g, target, camera)?)),
            (true, None) => Err(Error::InvalidInput(
                "soft particles fade against the drawn geometry: render.geometry = true".into(),
            )),
        }
    }

    /// Checks the frame's textures and particle count; the motion texture when stretched quads
    /// need it.
    fn frame_motion<'s>(&self, state: &FrameState<'s>) -> Result<Option<Motion<'s>>> {
        let (positions, statics, count) = (state.positions, state.statics, state.count);
        self.check_state("position", positions)?;
        self.check_state("statics", statics)?;
        let motion = match (self.needs_motion(), state.motion) {
            (true, None) => {
                return Err(Error::InvalidInput(
                    "stretched quads need the velocities (or Verlet's previous positions)".into(),
                ))
            }
            (true, Some(m)) => {
                self.check_state("motion", m.texture())?;
                Some(m)
            }
            (false, _) => None,
        };
        let texels = self.width as usize * self.height as usize;
        if count > texels {
            return Err(Error::InvalidInput(format!(
                "{count} particles to draw from a state of {texels}"
            )));
        }
        Ok(motion)
    }

    /// Packs the state the program reads into the vertex buffers (or lists it as textures) and
    /// gives the vertices to draw with the textures the draw reads (the state, the atlas, spins,
    /// motion and the user states) and the uniforms that go with them.
    fn bind_inputs<'a>(
        &'a self,
        p: &Program,
        state: &FrameState<'a>,
        motion: Option<Motion<'a>>,
        [sorted, scene_depth]: [Option<&'a Texture>; 2],
    ) -> Result<Inputs<'a>> {
        let (positions, statics, count) = (state.positions, state.statics, state.count);
        if let (Some(v), true) = (&self.vertex, count > 0) {
            let rows = count.div_ceil(self.width as usize) as u32;
            v.pack.copy_rows(positions, &v.positions, rows)?;
            v.pack.copy_rows(statics, &v.statics, rows)?;
        }
        let mut textures: Vec<(&str, Sampled)> = Vec::new();
        let mut uniforms = Vec::new();
        let vertices = match &self.vertex {
            Some(v) => &v.vao,
            None => {
                textures.push(("u_position", positions.into()));
                textures.push(("u_static", statics.into()));
                uniforms.push(("u_width", Uniform::I32(self.width as i32)));
                &self.empty
            }
        };
        if let (Some(_), Some((_, layout))) = (sorted, &self.lookup) {
            uniforms.push(("u_sort_width", Uniform::I32(layout.width as i32)));
        }
        if let Some(atlas) = &self.atlas {
            textures.push(("u_atlas", atlas.as_ref().into()));
        }
        textures.extend(sorted.map(|t| ("u_sorted", t.into())));
        if let Some(t) = scene_depth {
            textures.push(("u_scene_depth", t.into()));
            uniforms.push(("u_soft", Uniform::F32(self.params.soft)));
        }
        if self.needs_spins() {
            let Some(spins) = state.spins else {
                return Err(Error::InvalidInput(
                    "sprites turned by the spin need the spin texture (collisions.spin)".into(),
                ));
            };
            self.check_state("spin", spins)?;
            textures.push(("u_spin", spins.into()));
        }
        if let Some(m) = motion {
            textures.push(("u_motion", m.texture().into()));
            let (previous, dt) = match m {
                Motion::Velocity(_) => (0, 1.0),
                Motion::Previous { dt, .. } => (1, dt),
            };
            uniforms.extend([
                ("u_motion_previous", Uniform::I32(previous)),
                ("u_motion_dt", Uniform::F32(dt)),
                ("u_stretch", Uniform::F32(self.params.stretch)),
            ]);
        }
        if self.style.user_color.is_some() {
            for (&n, t) in USER_STATE_SAMPLERS.iter().zip(state.user) {
                if p.declares(n) {
                    self.check_state("user state", t)?;
                    textures.push((n, (*t).into()));
                }
            }
        }
        Ok((vertices, textures, uniforms))
    }

    /// The ribbons after the particles, then the under operator's last passes: the geometry's
    /// colour behind the particles, then the background behind everything.
    fn draw_under(
        &self,
        target: &FrameTarget,
        state: &FrameState<'_>,
        camera: &Camera,
        draw_state: &DrawState,
    ) -> Result<()> {
        let s = &self.style;
        let gl = &self.ctx;
        if let Some(r) = &self.ribbons {
            r.draw(target, state, camera, &self.params, draw_state)?;
        }
        if let (Some(g), true) = (&self.geometry, s.under()) {
            // Behind the particles accumulated so far, on the depth the first pass wrote.
            g.draw(
                target,
                camera,
                &DrawState {
                    depth: Depth::Equal,
                    color_writes: true,
                    ..*draw_state
                },
            );
        }
        if s.under() {
            let b = &self.background;
            // The same blend state: the under operator composites the background last, behind
            // everything (no depth test).
            gl.draw(&Draw {
                program: b,
                target: target.framebuffer(),
                viewport: None,
                vertices: &self.empty,
                primitive: Primitive::Triangles,
                count: 3,
                state: &DrawState {
                    depth: Depth::Off,
                    color_writes: true,
                    ..*draw_state
                },
                textures: &[],
                uniforms: &[("u_background", Uniform::Vec3(self.params.background))],
            });
        }
        Ok(())
    }
}
