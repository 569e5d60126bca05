//! The one GPU engine: a [`Simulation`] (the particle pipeline of UberFlow and Latta, or the
//! thesis's fire), the sort alpha blending needs, and the one particle renderer, on one context.

use super::shader_seed;
use crate::error::Result;
use crate::gl::Context;
use crate::render::FrameTarget;
use crate::scene::SortKey;
use crate::sim::state::{POSITION, SPIN, STATIC};
use crate::sim::{ParticleSim, Simulation};

// The `Engine` trait over any simulation, in a file of its own.
mod engine_impl;
// The sort stage in its parts, and the stages the measuring floor times.
mod passes;
mod stages;

/// The sorted motion texture (velocities or Verlet's previous positions) stretched quads read.
const MOTION: crate::gl::Attachment = crate::gl::Attachment::named("motion");

/// The GPU engine of the particle pipeline (UberFlow, Latta).
pub type ParticleEngine = GpuEngine<ParticleSim>;

/// Runs a scene on the GPU: its simulation `S`, the sort alpha blending needs, rendering.
///
/// ```
/// use texflow::{gl::Context, scene, ParticleEngine};
/// let ctx = Context::new(0)?;
/// let mut smoke = scene::load("smoke-unlit")?;      // alpha blending: sorted on the GPU
/// smoke.particles.size = [16, 16];
/// smoke.render.resolution = [32, 32];
/// let mut engine = ParticleEngine::new(&ctx, &smoke, 1)?;
/// for _ in 0..10 {
///     engine.advance_frame()?;
/// }
/// assert!(engine.order_for_drawing()?, "smoke sorts back to front");
/// let frame = engine.render()?;
/// assert_eq!(frame.dimensions(), (32, 32));
/// # Ok::<(), texflow::Error>(())
/// ```
#[derive(Debug)]
pub struct GpuEngine<S: Simulation> {
    sim: S,
    renderer: crate::render::ParticleRenderer,
    /// Half-angle slicing, which draws the sorted particles instead of `renderer`.
    lit: Option<crate::render::HalfAngleRenderer>,
    sort: Option<SortStage>,
    target: FrameTarget,
    camera: crate::render::Camera,
    /// The camera at time 0; `camera` is it turned by `orbit` degrees per simulated second.
    camera_start: crate::render::Camera,
    orbit: f32,
    /// A viewer's change to the camera (the live window); the identity by default.
    view: crate::render::ViewOffset,
    /// Scene name, for the pass list.
    name: String,
    /// The simulation's model, as benchmark records name it: `fire` or `particles`.
    model: &'static str,
    /// The sort's passes of a frame, as the plan words them.
    sort_passes: Vec<String>,
    /// With drawn geometry that moves: the triangles that do not, and the scene whose moving
    /// colliders are drawn at each frame's time.
    moving_geometry: Option<(crate::render::Mesh, Box<crate::scene::SceneFile>)>,
    /// Each particle type's emitter, by scene key.
    emitter_keys: Vec<String>,
    ctx: Context,
}

/// The sort of an alpha-blended scene and the textures it gathers into.
#[derive(Debug)]
struct SortStage {
    sorter: crate::sort::Sorter,
    sorted: crate::gl::Framebuffer,
    back_to_front: bool,
    key: SortKey,
    spread: bool,
    keyed: bool,
    /// Latta §3.4.4's index lookup (`render.lookup = "index"`): no gather.
    lookup: bool,
    /// The simulation step the sorted textures were made at: a draw at the same step reuses
    /// them, so drawing a frame never advances the sort spread over frames a second time.
    ordered_at: Option<u64>,
}

impl SortStage {
    /// The sort `scene`'s blending needs (none but for alpha blending) and the textures it
    /// gathers into: those `renderer` draws from.
    fn new(
        ctx: &Context,
        scene: &crate::scene::SceneFile,
        renderer: &crate::render::ParticleRenderer,
    ) -> Result<Option<Self>> {
        let Some((sorter, p)) = sorter_for(ctx, scene)? else {
            return Ok(None);
        };
        // In the order of the gather's sources (order_for_drawing_observed).
        let mut names = vec![POSITION, STATIC];
        if renderer.needs_motion() {
            names.push(MOTION);
        }
        if renderer.needs_spins() {
            names.push(SPIN);
        }
        Ok(Some(SortStage {
            sorter,
            sorted: gather_target(ctx, scene, "sorted", &names)?,
            back_to_front: scene.render.order == crate::scene::DrawOrder::BackToFront,
            key: scene.render.sort.key,
            spread: p.passes_per_frame.is_some(),
            keyed: false,
            lookup: scene.render.lookup == crate::scene::Lookup::Index,
            ordered_at: None,
        }))
    }
}

/// The sorter of `scene`'s alpha blending, as the engine runs it (`None` for other blendings):
/// built from [`sort_plan`](crate::engine::plan::sort_plan), and for `fp24` scenes with the
/// 2004 hardware's 24-bit floats and the paper's identifier table (UberFlow §4.3.1). The
/// benchmarks time the engine's own (through [`Stages`](crate::engine::Stages)).
pub fn sorter_for(
    ctx: &Context,
    scene: &crate::scene::SceneFile,
) -> Result<Option<(crate::sort::Sorter, crate::engine::plan::SortPlan)>> {
    let Some(p) = crate::engine::plan::sort_plan(scene) else {
        return Ok(None);
    };
    let fp24 = scene.particles.precision == crate::scene::Precision::Fp24;
    let options = crate::sort::SortOptions {
        passes_per_frame: p.passes_per_frame.map(|n| n as usize),
        spread: scene.render.sort.spread,
        precision: fp24.then_some(crate::sort::precision::R300),
        id_table: fp24,
        blocked: p.shape,
        ..Default::default()
    };
    let sorter = crate::sort::Sorter::new(ctx, p.variant, p.size[0], p.size[1], options)?;
    Ok(Some((sorter, p)))
}

/// The layout of `sorter`'s texture, for the renderer's index lookup (Latta §3.4.4).
pub fn sort_layout(sorter: &crate::sort::Sorter) -> crate::render::SortLayout {
    let o = sorter.options();
    crate::render::SortLayout {
        width: sorter.width(),
        packed: sorter.variant().packed(),
        id_mantissa: o.precision.filter(|_| o.id_table).map(|f| f.mantissa_bits),
    }
}

/// A framebuffer of `scene`'s state size with one RGBA32F attachment per name: where a sort
/// gathers the state in drawing order.
pub fn gather_target(
    ctx: &Context,
    scene: &crate::scene::SceneFile,
    label: &str,
    names: &[crate::gl::Attachment],
) -> Result<crate::gl::Framebuffer> {
    use crate::gl::{Texture, TextureDesc, TextureFormat};
    let [width, height] = scene.particles.size;
    let textures = (names.iter())
        .map(|&name| {
            let desc = TextureDesc {
                width,
                height,
                format: TextureFormat::Rgba32F,
                label: &format!("{label} {}", name.name()),
            };
            Ok((name, Texture::new(ctx, desc)?))
        })
        .collect::<Result<Vec<_>>>()?;
    crate::gl::Framebuffer::named(ctx, label, textures)
}

/// The model a scene runs, as benchmark records name it.
fn model_of(scene: &crate::scene::SceneFile) -> &'static str {
    match scene.fire {
        Some(_) => "fire",
        None => "particles",
    }
}

/// The surface's colour: the first of `render.keyframes` (a constraint layout's particles are
/// permanent, at relative age 0), light grey without any.
fn surface_color(scene: &crate::scene::SceneFile) -> [f32; 3] {
    match scene.render.keyframes.first() {
        Some(k) => [k.rgba[0], k.rgba[1], k.rgba[2]],
        None => [0.8; 3],
    }
}

impl<S: Simulation> GpuEngine<S> {
    /// Validates the scene against the device and builds everything.
    pub fn new(ctx: &Context, scene: &crate::scene::SceneFile, seed: u64) -> Result<Self> {
        let [rw, rh] = scene.render.resolution;
        crate::gl::check_size(ctx, "frame (render.resolution)", rw, rh)?;
        let sim = S::from_scene(ctx, scene, shader_seed(seed))?;
        let [w, h] = scene.particles.size;
        let style = crate::render::ParticleStyle::from_scene(scene);
        let lit = super::lit_renderer(ctx, scene, &style)?;
        let mut renderer = crate::render::ParticleRenderer::new(ctx, style, w, h)?;
        let mut moving_geometry = None;
        if scene.render.geometry {
            let terrain = sim.height_field().map(|f| crate::render::Terrain {
                extent: f.extent(),
                size: f.resolution(),
                texels: f.texels(),
            });
            // A field from a file is drawn as its zero surface (analytic shapes and meshes are
            // drawn as themselves).
            let surface = (sim.distance_field())
                .filter(|_| scene.colliders.sdf.iter().any(|d| d.distances.is_some()))
                .map(|f| crate::render::Surface {
                    bounds: f.bounds(),
                    size: f.resolution(),
                    texels: f.texels(),
                });
            let fixed = crate::render::Mesh::fixed(scene, terrain.as_ref(), surface.as_ref())?;
            let mut mesh = fixed.clone();
            mesh.vertices
                .extend(crate::render::Mesh::moving(scene, sim.time()).vertices);
            renderer.set_geometry(crate::render::GeometryRenderer::new(ctx, &mesh)?);
            let moves = scene.colliders.sphere.iter().any(|s| s.orbit.is_some());
            moving_geometry = moves.then(|| (fixed, Box::new(scene.clone())));
        }
        let surface = scene.render.mode == crate::scene::DrawMode::Surface;
        if let (true, Some(layout)) = (surface, crate::sim::constraints::Layout::of(scene)) {
            renderer.set_connected(crate::render::ConnectedRenderer::new(
                ctx,
                layout.kind,
                layout.size,
                surface_color(scene),
            )?);
        }
        if scene.render.trails == crate::scene::Trails::Ribbon {
            let ribbons = crate::render::RibbonRenderer::new(
                ctx,
                &scene.child_layout(),
                renderer.style(),
                scene.time.dt,
                scene.render.ribbon_width,
            )?;
            renderer.set_ribbons(ribbons);
        }
        let sort = SortStage::new(ctx, scene, &renderer)?;
        if let Some(s) = sort.as_ref().filter(|s| s.lookup) {
            renderer.set_lookup(sort_layout(&s.sorter))?;
        }
        let camera = crate::render::Camera::from(&scene.render.camera);
        Ok(GpuEngine {
            target: if scene.render.geometry || surface {
                FrameTarget::with_depth(ctx, rw, rh)?
            } else {
                FrameTarget::new(ctx, rw, rh)?
            },
            camera,
            camera_start: camera,
            orbit: scene.render.camera.orbit,
            view: crate::render::ViewOffset::default(),
            sim,
            renderer,
            lit,
            sort,
            name: scene.name.clone(),
            model: model_of(scene),
            sort_passes: crate::engine::plan::sort_lines(scene),
            moving_geometry,
            emitter_keys: (0..scene.emitters.len())
                .filter_map(|k| scene.emitters.key(k))
                .collect(),
            ctx: ctx.clone(),
        })
    }

    /// Advances the simulation by one frame: `substeps` steps of `dt`.
    pub fn advance_frame(&mut self) -> Result<()> {
        for _ in 0..self.sim.substeps() {
            self.sim.step()?;
        }
        Ok(())
    }

    /// One frame of collisionless motion ([`Simulation::step_without_collisions`]): births,
    /// forces, colliders, no collisions between particles. Benchmarks warm up with it.
    pub fn advance_frame_without_collisions(&mut self) -> Result<()> {
        for _ in 0..self.sim.substeps() {
            self.sim.step_without_collisions()?;
        }
        Ok(())
    }

    /// Draws the current state into the frame target, after the sort of this frame (alpha
    /// blending only) if [`order_for_drawing`](Self::order_for_drawing) has not run at this step.
    pub fn draw(&mut self) -> Result<()> {
        if let Some((fixed, scene)) = &self.moving_geometry {
            // The colliders where the passes of the last step had them.
            let mut mesh = fixed.clone();
            let moving = crate::render::Mesh::moving(scene, self.sim.time());
            mesh.vertices.extend(moving.vertices);
            self.renderer.replace_geometry(&mesh)?;
        }
        let steps = self.sim.steps();
        let sorts = match &self.sort {
            Some(s) if s.ordered_at == Some(steps) => {
                self.turn_camera();
                true
            }
            _ => self.order_for_drawing()?,
        };
        self.render_pass(sorts)
    }

    /// The render pass alone: clears the frame target and draws, from the state the last
    /// [`order_for_drawing`](Self::order_for_drawing) gathered when `sorted` (the scene has a
    /// sort stage), else from the simulation's state. `bench scene` times this, so the phase it
    /// reports is the pass [`draw`](Self::draw) runs.
    pub fn render_pass(&self, sorted: bool) -> Result<()> {
        self.render_pass_with(&self.renderer, sorted)
    }

    /// [`render_pass`](Self::render_pass) drawn by `renderer` instead of the engine's own (a
    /// benchmark's fill floor: the same renderer with a constant fragment stage).
    pub fn render_pass_with(
        &self,
        renderer: &crate::render::ParticleRenderer,
        sorted: bool,
    ) -> Result<()> {
        let count = self.sim.drawn().count;
        renderer.clear(&self.target);
        let [w, h] = self.sim.size();
        let texels = w as usize * h as usize;
        let user = self.sim.user_states();
        let unsorted = |count| {
            let d = self.sim.drawn();
            crate::render::FrameState {
                positions: d.positions,
                statics: d.statics,
                motion: self.motion(),
                time: self.sim.time() as f32,
                spins: d.spins,
                count,
                user: &user,
            }
        };
        match self.sort.as_ref().filter(|_| sorted) {
            // Latta §3.4.4: every texel drawn through the sorted index (dead ones sort last).
            Some(s) if s.lookup => renderer.draw_frame_sorted(
                &self.target,
                &unsorted(texels),
                &self.camera,
                s.sorter.keys(),
            )?,
            Some(s) => {
                // Dead particles sort last (+inf keys), so the live ones are a prefix.
                let motion = self.motion().map(|m| match m {
                    crate::render::Motion::Velocity(_) => {
                        crate::render::Motion::Velocity(s.sorted.texture(MOTION))
                    }
                    crate::render::Motion::Previous { dt, .. } => crate::render::Motion::Previous {
                        positions: s.sorted.texture(MOTION),
                        dt,
                    },
                });
                // The spins, when drawn, are the last texture gathered.
                let spins = renderer.needs_spins().then(|| s.sorted.texture(SPIN));
                let state = crate::render::FrameState {
                    positions: s.sorted.texture(POSITION),
                    statics: s.sorted.texture(STATIC),
                    motion,
                    time: self.sim.time() as f32,
                    spins,
                    count: texels,
                    user: &[],
                };
                // The engine's own renderer draws a lit scene through its slices; another
                // renderer (a benchmark's fill floor) draws the same state plainly.
                match &self.lit {
                    Some(l) if std::ptr::eq(renderer, &self.renderer) => {
                        // Slices of equal count over the sorted entries that can be live (the
                        // simulation's drawn rows: dead ones sort last), not over every texel,
                        // or the last slices would hold only the dead.
                        let live = crate::render::FrameState { count, ..state };
                        l.draw(&self.target, &live, &self.camera, renderer.atlas())?
                    }
                    _ => renderer.draw_frame(&self.target, &state, &self.camera)?,
                }
            }
            None => renderer.draw_frame(&self.target, &unsorted(count), &self.camera)?,
        }
        self.ctx.check_error("drawing a frame")
    }

    /// The sort stage of a frame, without drawing: turns the camera to the current time, and for
    /// alpha blending writes the viewer-distance keys (refreshed in place when the sort is spread
    /// over frames), runs this frame's share of the sort and gathers positions and statics into
    /// [`sorted`](Self::sorted). Returns whether the scene sorts at all. The frame loop runs it
    /// once every frame, drawn or not, so that the sort spread over frames (Latta §3.4.4)
    /// advances with the simulation and a frame's pixels do not depend on which frames were
    /// written; [`draw`](Self::draw) runs it when it has not run at this step. It is public so
    /// that the sort's cost and quality can be measured alone.
    pub fn order_for_drawing(&mut self) -> Result<bool> {
        self.order_for_drawing_observed(&mut |_, _| Ok(()))
    }

    /// [`order_for_drawing`](Self::order_for_drawing), handing the sorter to `seen` after the
    /// key pass (`"keys"`) and after this frame's network passes (`"network"`), before the
    /// gather: what `texflow trace` draws.
    pub fn order_for_drawing_observed(
        &mut self,
        seen: &mut dyn FnMut(&str, &crate::sort::Sorter) -> Result<()>,
    ) -> Result<bool> {
        if self.sort_keys()?.is_none() {
            return Ok(false);
        }
        if let Some(s) = &self.sort {
            seen("keys", &s.sorter)?;
        }
        self.sort_network();
        if let Some(s) = &self.sort {
            seen("network", &s.sorter)?;
        }
        self.sort_gather()?;
        Ok(true)
    }

    /// Turns the camera to the current simulated time (`render.camera.orbit`), then by the
    /// viewer's offset.
    fn turn_camera(&mut self) {
        let camera = self
            .camera_start
            .orbited(self.orbit, self.sim.time() as f32);
        self.camera = self.view.apply(camera);
    }

    /// Sets the viewer's change to the scene's camera; the next sort stage sorts for it, so
    /// alpha blending stays in order however the viewer turns.
    pub fn set_view(&mut self, view: crate::render::ViewOffset) {
        self.view = view;
        self.turn_camera();
    }

    /// What stretched quads stretch along (only they need it): the velocities, or Verlet's
    /// previous positions one step back.
    fn motion(&self) -> Option<crate::render::Motion<'_>> {
        if !self.renderer.needs_motion() {
            return None;
        }
        let d = self.sim.drawn();
        match (d.velocities, d.previous) {
            (Some(v), _) => Some(crate::render::Motion::Velocity(v)),
            (None, Some(prev)) => Some(crate::render::Motion::Previous {
                positions: prev,
                dt: self.sim.time_step(),
            }),
            (None, None) => None,
        }
    }

    /// The sorter of an alpha-blended scene (its entries are the last frame's keys and ids).
    pub fn sorter(&self) -> Option<&crate::sort::Sorter> {
        self.sort.as_ref().map(|s| &s.sorter)
    }

    /// Draws the current state and reads the frame back.
    pub fn render(&mut self) -> Result<image::RgbImage> {
        self.draw()?;
        self.target.read_rgb()
    }

    /// The simulation.
    pub fn sim(&self) -> &S {
        &self.sim
    }

    /// The simulation, mutable (to set a state).
    pub fn sim_mut(&mut self) -> &mut S {
        &mut self.sim
    }

    /// The positions and statics in drawing order after the last [`draw`](Self::draw) (alpha
    /// blending with the gather only: the index lookup gathers nothing).
    pub fn sorted(&self) -> Option<&crate::gl::Framebuffer> {
        self.sort.as_ref().filter(|s| !s.lookup).map(|s| &s.sorted)
    }

    /// The camera.
    pub fn camera(&self) -> &crate::render::Camera {
        &self.camera
    }

    /// The frame target.
    pub fn target(&self) -> &FrameTarget {
        &self.target
    }

    /// The renderer.
    pub fn renderer(&self) -> &crate::render::ParticleRenderer {
        &self.renderer
    }

    /// Half-angle slicing, when the scene is lit.
    pub fn lit(&self) -> Option<&crate::render::HalfAngleRenderer> {
        self.lit.as_ref()
    }
}

/// The depths the compact sort spreads its levels over: from the eye out to three times the
/// distance of what it looks at (farther particles share the last level; what is drawn there
/// is small).
pub fn compact_depth_range(distance: f32) -> (f32, f32) {
    (0.0, 3.0 * distance.max(1e-3))
}

/// What the key pass computes for a scene's `render.sort.key`, seen from `eye`.
pub fn key_mode(key: SortKey, eye: glam::Vec3, back_to_front: bool) -> crate::sort::KeyMode {
    match key {
        SortKey::Distance => crate::sort::KeyMode::ViewerDistance { eye, back_to_front },
        SortKey::YoungestOnTop | SortKey::OldestOnTop => crate::sort::KeyMode::Age {
            youngest_on_top: key == SortKey::YoungestOnTop,
            back_to_front,
        },
    }
}
