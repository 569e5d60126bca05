//! UberFlow's E5 (Table 2): the CPU-based particle engine the paper compares its GPU engine with,
//! "an implementation optimized for CPU processing that uses data-dependent sorting (quick-sort)
//! for front-to-back rendering and is thus equivalent to the GPU experiment (E3)" (§5).
//!
//! The same scene file, the same physics, the same random streams as the GPU engine, on the CPU:
//!
//! - [`CpuSim`]: the particle state in three arrays in main memory (position and remaining life,
//!   velocity, static data), stepped in parallel on every core with rayon. The step of one
//!   particle is [`Reference::step_explicit`](crate::sim::reference::Reference::step_explicit), the CPU twin of `glsl/sim/integrate.frag`; the
//!   time-stamp birth, respawn and death around it (UberFlow §4.1, the `TIMESTAMP` block of the
//!   shader) and the initial fill (`glsl/sim/init.frag`) are twinned here with the GPU's spawn
//!   streams ([`Rng`](crate::sim::emit::Rng), [`EmitterUniforms`](crate::sim::emit::EmitterUniforms)), so that the same seed gives the same particles as
//!   [`crate::Engine`], up to rounding.
//! - [`CpuEngine`]: a [`CpuSim`] and what a CPU engine does every frame to draw it: the viewer
//!   distance of every live particle, a quicksort of them (rayon's parallel pattern-defeating
//!   quicksort, `par_sort_unstable`, on (distance, index) keys: data-dependent, unlike the GPU's
//!   sorting networks) into the scene's order (nearest first for E3's under operator), then the
//!   live particles gathered in that order as vertices (position, relative age), uploaded into a
//!   vertex buffer with `glBufferSubData` and drawn as points with the scene's keyframe colours
//!   and blending (`glsl/render/cpu_points.vert`, `.frag`). Dead and unborn particles are neither
//!   sorted nor uploaded.
//!
//! Covered: explicit integrators (Euler, UberFlow), time-stamp and initial emitters, every force
//! and collider of the reference, points. Not covered (rejected by [`CpuSim::new`] /
//! [`CpuEngine::new`]): Verlet, allocator emission, `fp24` precision, `rgba16f` velocities,
//! sprites, collisions between particles, the fluid, the fire scene.

mod sim;

use rayon::prelude::*;

pub use sim::CpuSim;
use sim::{live, unsupported, CHUNK};

use crate::error::{Error, Result};
use crate::gl::{
    Attribute, Buffer, BufferKind, BufferUsage, Context, Defines, Draw, Primitive, Program,
    Uniform, VertexArray, FULLSCREEN_VERTEX,
};
use crate::render::{relative_age, Camera, FrameTarget, ParticleStyle, RenderParams};
use crate::scene::{Blending, DrawMode, DrawOrder, SceneFile, SortKey};

/// Where the time of one CPU-engine frame goes ([`CpuEngine::timed_frame`]), in milliseconds.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct FramePhases {
    /// The frame's simulation steps on all cores.
    pub simulate_ms: f64,
    /// Viewer distances of the live particles, the quicksort and the gather of the vertices.
    pub sort_ms: f64,
    /// `glBufferSubData` of the vertices, until the driver has them (`glFinish`).
    pub upload_ms: f64,
    /// Clear, point draw and background, until finished.
    pub draw_ms: f64,
}

/// The CPU engine: [`CpuSim`], then every frame a quicksort by viewer distance, the upload of the
/// live particles' vertices in drawing order and a point draw (see the module documentation).
pub struct CpuEngine {
    ctx: Context,
    sim: CpuSim,
    style: ParticleStyle,
    /// The render block the point draw uploads, packed once from the style (as the GPU
    /// renderer's).
    params: RenderParams,
    camera: Camera,
    /// The camera at time 0, turned by `render.camera.orbit` as the GPU engine turns it.
    camera_start: Camera,
    /// A viewer's change to the camera (the live window).
    view: crate::render::ViewOffset,
    target: FrameTarget,
    program: Program,
    background: Option<Program>,
    empty: VertexArray,
    vertex_buffer: Buffer,
    vao: VertexArray,
    /// (distance key << 32 | index) of the live particles, in drawing order after a draw.
    keys: Vec<u64>,
    /// (x, y, z, relative age) of the live particles in drawing order.
    vertices: Vec<[f32; 4]>,
}

impl std::fmt::Debug for CpuEngine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "CpuEngine({} {}x{})",
            self.sim.scene.name, self.sim.width, self.sim.height
        )
    }
}

impl CpuEngine {
    /// The CPU simulation of `scene` and the GL objects to draw it on `ctx`.
    pub fn new(ctx: &Context, scene: &SceneFile, seed: u64) -> Result<Self> {
        let sim = CpuSim::new(scene, seed)?;
        drawable(scene)?;
        let [rw, rh] = scene.render.resolution;
        crate::gl::check_size(ctx, "frame (render.resolution)", rw, rh)?;
        let style = ParticleStyle::from_render(&scene.render, [1.0; 4]);
        let mut defines = Defines::new();
        match style.blending {
            Blending::Multiplicative => defines.push(("MULTIPLY".into(), "1".into())),
            Blending::Alpha if style.under() => defines.push(("PREMULTIPLIED".into(), "1".into())),
            Blending::Alpha | Blending::Additive => {}
        }
        let program = Program::new(
            ctx,
            "render/cpu_points.vert",
            "render/cpu_points.frag",
            &defines,
        )?;
        let background = if style.under() {
            Some(Program::new(
                ctx,
                FULLSCREEN_VERTEX,
                "render/background.frag",
                &Defines::new(),
            )?)
        } else {
            None
        };
        let n = sim.positions.len();
        let bytes = n as u64 * 16;
        if bytes > i32::MAX as u64 {
            return Err(Error::InvalidInput(format!(
                "{n} particles need a vertex buffer of {bytes} bytes, over GL's limit of {} for \
                 one buffer",
                i32::MAX
            )));
        }
        let vertex_buffer = Buffer::with_size(
            ctx,
            "cpu engine vertices",
            BufferKind::Vertex,
            bytes as usize,
            BufferUsage::StreamDraw,
        )?;
        let vao = VertexArray::with_attributes(
            ctx,
            "cpu engine vertices",
            &[Attribute {
                buffer: &vertex_buffer,
                location: 0,
                components: 4,
                stride: 16,
                offset: 0,
            }],
        )?;
        let camera = crate::render::Camera::from(&scene.render.camera);
        Ok(CpuEngine {
            camera,
            camera_start: camera,
            view: crate::render::ViewOffset::default(),
            target: FrameTarget::new(ctx, rw, rh)?,
            empty: VertexArray::empty(ctx, "cpu engine background")?,
            keys: Vec::with_capacity(n),
            vertices: Vec::with_capacity(n),
            ctx: ctx.clone(),
            sim,
            params: RenderParams::of(&style),
            style,
            program,
            background,
            vertex_buffer,
            vao,
        })
    }

    /// Advances the simulation by one frame (`substeps` steps on all cores).
    pub fn advance_frame(&mut self) {
        self.sim.advance_frame();
    }

    /// Draws the current state into the frame target, as a CPU engine does: keys, quicksort
    /// (alpha blending), gather, upload, draw. Returns once the commands are issued; the caller
    /// waits for them (`glFinish`) where it times a frame.
    pub fn draw(&mut self) -> Result<()> {
        self.sort_and_gather();
        self.upload()?;
        self.draw_points()
    }

    /// One whole frame: [`advance_frame`](Self::advance_frame) then [`draw`](Self::draw).
    pub fn frame(&mut self) -> Result<()> {
        self.advance_frame();
        self.draw()
    }

    /// One whole frame with `glFinish` between its parts, timed on the wall clock: where the
    /// time of a frame goes (the finishes remove what overlap there is, so the parts add up to a
    /// little more than a [`frame`](Self::frame)).
    pub fn timed_frame(&mut self) -> Result<FramePhases> {
        let ms = |t: std::time::Instant| t.elapsed().as_secs_f64() * 1e3;
        self.ctx.finish();
        let t = std::time::Instant::now();
        self.advance_frame();
        let simulate_ms = ms(t);
        let t = std::time::Instant::now();
        self.sort_and_gather();
        let sort_ms = ms(t);
        let t = std::time::Instant::now();
        self.upload()?;
        self.ctx.finish();
        let upload_ms = ms(t);
        let t = std::time::Instant::now();
        self.draw_points()?;
        self.ctx.finish();
        let draw_ms = ms(t);
        Ok(FramePhases {
            simulate_ms,
            sort_ms,
            upload_ms,
            draw_ms,
        })
    }

    /// Draws the current state and reads the frame back.
    pub fn render(&mut self) -> Result<image::RgbImage> {
        self.draw()?;
        self.target.read_rgb()
    }

    /// Keys of the live particles, the quicksort (alpha blending only; other blendings need no
    /// order and draw in index order) and the vertices in drawing order.
    fn sort_and_gather(&mut self) {
        self.turn_camera();
        let eye = self.camera.eye();
        let positions = &self.sim.positions;
        let sort = self.style.blending == Blending::Alpha;
        let back_to_front = self.style.order == DrawOrder::BackToFront;
        let by = self.sim.scene.render.sort.key;
        let statics = &self.sim.statics;
        self.keys.clear();
        self.keys.par_extend(
            positions
                .par_iter()
                .enumerate()
                .with_min_len(CHUNK)
                .filter(|(_, p)| live(**p))
                .map(|(i, p)| {
                    if !sort {
                        return i as u64;
                    }
                    // m: smaller is more on top. Squared distance: the order of the distance,
                    // without the root; the age (as the GPU's key pass computes it), negated
                    // for the oldest on top. Inverted: the least on top drawn first.
                    let bits = match by {
                        SortKey::Distance => p.truncate().distance_squared(eye).to_bits(),
                        SortKey::YoungestOnTop => ordered_bits(statics[i].z - p.w),
                        SortKey::OldestOnTop => ordered_bits(-(statics[i].z - p.w)),
                    };
                    let key = if back_to_front { !bits } else { bits };
                    ((key as u64) << 32) | i as u64
                }),
        );
        if sort {
            self.keys.par_sort_unstable();
        }
        self.keys
            .par_iter()
            .with_min_len(CHUNK)
            .map(|&k| {
                let i = (k & 0xffff_ffff) as usize;
                let p = positions[i];
                [p.x, p.y, p.z, relative_age(p.w, statics[i].z)]
            })
            .collect_into_vec(&mut self.vertices);
    }

    /// Turns the camera to the current simulated time, then by the viewer's offset (as the GPU
    /// engine does).
    fn turn_camera(&mut self) {
        let orbit = self.sim.scene.render.camera.orbit;
        let camera = self.camera_start.orbited(orbit, self.sim.time() as f32);
        self.camera = self.view.apply(camera);
    }

    /// Uploads the vertices into the vertex buffer: the buffer's storage is orphaned (so a draw
    /// still reading the last frame's data does not stall the upload) and refilled with
    /// `glBufferSubData`.
    fn upload(&self) -> Result<()> {
        self.vertex_buffer
            .replace(bytemuck::cast_slice(&self.vertices))?;
        self.ctx.check_error("uploading the CPU engine's vertices")
    }

    /// The point draw with the scene's blending, as `ParticleRenderer::draw` sets it up.
    fn draw_points(&self) -> Result<()> {
        let s = &self.style;
        let block = &self.params;
        self.target.clear_to(block.clear_color);
        let p = &self.program;
        let aspect = self.target.width() as f32 / self.target.height() as f32;
        // The camera turns from frame to frame; the look is the renderer's, given the same way.
        let mut uniforms = vec![(
            "u_view_proj",
            Uniform::Mat4(self.camera.view_projection(aspect)),
        )];
        uniforms.extend(block.size_uniforms());
        uniforms.extend(block.keyframe_uniforms());
        let gl = &self.ctx;
        let state = block.draw_state(s.depth_test);
        gl.draw(&Draw {
            program: p,
            target: self.target.framebuffer(),
            viewport: None,
            vertices: &self.vao,
            primitive: Primitive::Points,
            count: self.vertices.len() as u32,
            state: &state,
            textures: &[],
            uniforms: &uniforms,
        });
        if let Some(b) = &self.background {
            // The same blend state: the under operator composites the background last.
            gl.draw(&Draw {
                program: b,
                target: self.target.framebuffer(),
                viewport: None,
                vertices: &self.empty,
                primitive: Primitive::Triangles,
                count: 3,
                state: &state,
                textures: &[],
                uniforms: &[("u_background", Uniform::Vec3(block.background))],
            });
        }
        gl.check_error("drawing the CPU engine's points")
    }

    /// The indices of the particles the last [`draw`](Self::draw) drew, in drawing order (for
    /// E3's scene: nearest first).
    pub fn draw_order(&self) -> Vec<u32> {
        self.keys
            .iter()
            .map(|&k| (k & 0xffff_ffff) as u32)
            .collect()
    }

    /// The vertices the last draw uploaded: (x, y, z, relative age), in drawing order.
    pub fn vertices(&self) -> &[[f32; 4]] {
        &self.vertices
    }

    /// The simulation.
    pub fn sim(&self) -> &CpuSim {
        &self.sim
    }

    /// The simulation, mutable.
    pub fn sim_mut(&mut self) -> &mut CpuSim {
        &mut self.sim
    }

    /// The camera (the scene's).
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// The frame target.
    pub fn target(&self) -> &FrameTarget {
        &self.target
    }

    /// The context.
    pub fn context(&self) -> &Context {
        &self.ctx
    }
}

impl super::Engine for CpuEngine {
    fn advance_frame(&mut self) -> Result<()> {
        CpuEngine::advance_frame(self);
        Ok(())
    }

    fn draw(&mut self) -> Result<()> {
        CpuEngine::draw(self)
    }

    fn target(&self) -> &FrameTarget {
        &self.target
    }

    fn set_view(&mut self, view: crate::render::ViewOffset) {
        self.view = view;
    }

    fn steps(&self) -> u64 {
        self.sim.steps()
    }

    fn state_size(&self) -> [u32; 2] {
        self.sim.size()
    }

    /// Counted where the state lives, in main memory.
    fn non_finite(
        &self,
        _counter: &crate::sim::nonfinite::NonFiniteCounter,
    ) -> Result<crate::sim::nonfinite::NonFiniteCount> {
        let (p, v) = self.state_arrays();
        Ok(crate::sim::nonfinite::NonFiniteCount::of_slices(&p, &v))
    }

    fn dump(&self) -> Result<super::StateDump> {
        let (p, v) = self.state_arrays();
        let statics = self
            .sim
            .statics()
            .iter()
            .flat_map(|s| s.to_array())
            .collect();
        Ok(super::StateDump::of_live_with(
            &p,
            &v,
            &[("statics", statics)],
        ))
    }

    fn live(&self) -> Result<u64> {
        Ok(self.sim.live_count() as u64)
    }

    fn emitter_keys(&self) -> Vec<String> {
        let e = &self.sim.scene().emitters;
        (0..e.len()).filter_map(|k| e.key(k)).collect()
    }

    fn timed_frame(&mut self, _timer: &crate::gl::PassTimer) -> Result<Vec<(&'static str, f64)>> {
        // The CPU's parts are timed on the wall clock, each finished before the next.
        let p = CpuEngine::timed_frame(self)?;
        Ok(vec![
            ("simulate", p.simulate_ms),
            ("keys, quicksort and gather", p.sort_ms),
            ("upload", p.upload_ms),
            ("draw", p.draw_ms),
        ])
    }

    fn plan(&self) -> super::plan::Plan {
        use crate::gl::PassInfo;
        let sort = if self.style.blending == Blending::Alpha {
            "keys (viewer distance) and a parallel quicksort of the live particles on every core"
        } else {
            "the live particles in index order (no sort: the blending needs none)"
        };
        // The CPU's work draws nothing: only the points (and the background under) are draws.
        let mut passes = vec![
            PassInfo::new(
                "integrate",
                "CPU step of every particle on every core (rayon): the GPU pass's physics, \
                 time-stamp birth, respawn and death (UberFlow E5)",
            ),
            PassInfo::new("sort", sort),
            PassInfo::new(
                "gather",
                "gather (position, relative age) in drawing order, upload with glBufferSubData",
            ),
            PassInfo::new(
                "render",
                format!("render points (vertex buffer, {})", self.style.blend_name()),
            )
            .draws(&self.program, 1),
        ];
        if let Some(b) = &self.background {
            passes.push(PassInfo::new("render", "composite background under").draws(b, 1));
        }
        super::plan::Plan::new(&self.sim.scene.name, self.sim.scene.time.substeps, passes)
    }
}

impl CpuEngine {
    /// The state as RGBA arrays (position and life; velocity and 0).
    fn state_arrays(&self) -> (Vec<f32>, Vec<f32>) {
        let p = self
            .sim
            .positions()
            .iter()
            .flat_map(|p| p.to_array())
            .collect();
        let v = (self.sim.velocities().iter())
            .flat_map(|v| [v.x, v.y, v.z, 0.0])
            .collect();
        (p, v)
    }
}

/// Refuses what the CPU engine's point draw does not cover (it draws points of one size, with
/// one set of keyframes), naming it.
fn drawable(scene: &SceneFile) -> Result<()> {
    if scene.render.mode == DrawMode::Sprites {
        return Err(unsupported(scene, "sprites (it draws points)"));
    }
    if scene.render.mode == DrawMode::Surface {
        return Err(unsupported(
            scene,
            "render.mode = \"surface\" (it draws points; set render.mode = \"points\")",
        ));
    }
    if scene.render.primitive != crate::scene::DrawPrimitive::Points {
        return Err(unsupported(scene, "quads and triangles (it draws points)"));
    }
    if scene.render.geometry {
        return Err(unsupported(scene, "render.geometry (it draws points only)"));
    }
    if scene.render.lighting != crate::scene::Lighting::None {
        return Err(unsupported(
            scene,
            "render.lighting (it draws unlit points)",
        ));
    }
    if scene.emitters.all().any(|e| e.size_range.is_some()) {
        return Err(unsupported(
            scene,
            "size_range (it draws points of one size)",
        ));
    }
    if scene.emitters.all().any(|e| e.tint != [1.0; 4].into()) {
        return Err(unsupported(
            scene,
            "tint (it draws one set of keyframes, untinted)",
        ));
    }
    if scene.emitters.all().any(|e| !e.keyframes.is_empty()) {
        return Err(unsupported(
            scene,
            "keyframes per emitter (it draws one set)",
        ));
    }
    Ok(())
}

/// The bits of a finite float, mapped so that they order as the numbers do (negative ones too).
fn ordered_bits(x: f32) -> u32 {
    let b = x.to_bits();
    if b >> 31 == 1 {
        !b
    } else {
        b | 0x8000_0000
    }
}
