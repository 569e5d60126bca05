//! The engine: a scene's simulation, its renderer and its frame target on one context.
//!
//! One frame is `substeps` simulation steps of `dt` seconds, then one render pass. Each step is
//! one full-screen pass that reads the front state and writes the back state (MRT), then a swap.

use crate::error::Result;
use crate::gl::Context;
use crate::render::{FrameTarget, PointRenderer};
use crate::scene::Scene;

use crate::sim::FireSim;

/// Runs one scene.
#[derive(Debug)]
pub struct Engine {
    scene: Scene,
    sim: FireSim,
    points: PointRenderer,
    target: FrameTarget,
    ctx: Context,
}

/// Folds a 64-bit seed into the 32 bits the shader hash takes.
pub fn shader_seed(seed: u64) -> u32 {
    (seed as u32) ^ ((seed >> 32) as u32)
}

impl Engine {
    /// Validates the scene against itself and the device, and builds everything.
    pub fn new(ctx: &Context, scene: Scene, seed: u64) -> Result<Self> {
        scene.validate()?;
        let [w, h] = scene.particles;
        crate::gl::check_size(ctx, "particle texture (--particles)", w, h)?;
        let [rw, rh] = scene.resolution;
        crate::gl::check_size(ctx, "frame (--resolution)", rw, rh)?;
        let sim = FireSim::new(ctx, w, h, (&scene.fire).into(), shader_seed(seed))?;
        Ok(Engine {
            points: PointRenderer::new(ctx)?,
            target: FrameTarget::new(ctx, rw, rh)?,
            sim,
            scene,
            ctx: ctx.clone(),
        })
    }

    /// Advances the simulation by one frame: `substeps` steps of `dt`.
    pub fn advance_frame(&mut self) {
        for _ in 0..self.scene.substeps {
            self.sim.step(self.scene.dt);
        }
    }

    /// Draws the current state into the frame target (cleared first).
    pub fn draw(&self) {
        self.target.clear();
        let mut camera = crate::render::Camera::from(&self.scene.camera);
        camera.azimuth +=
            self.scene.camera.orbit * (self.sim.steps() as f64 * self.scene.dt as f64) as f32;
        self.points.draw(
            &self.target,
            self.sim.positions(),
            self.sim.velocities(),
            &camera,
            &(&self.scene.style).into(),
        );
    }

    /// Draws the current state and reads the frame back.
    pub fn render(&self) -> Result<image::RgbImage> {
        self.draw();
        let img = self.target.read_rgb()?;
        self.ctx.check_error("rendering a frame")?;
        Ok(img)
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The simulation.
    pub fn sim(&self) -> &FireSim {
        &self.sim
    }

    /// The frame target.
    pub fn target(&self) -> &FrameTarget {
        &self.target
    }

    /// The point renderer.
    pub fn points(&self) -> &PointRenderer {
        &self.points
    }

    /// The context.
    pub fn context(&self) -> &Context {
        &self.ctx
    }
}

/// Runs a scene of the particle pipeline: simulation, the sort alpha blending needs, rendering.
#[derive(Debug)]
pub struct ParticleEngine {
    sim: crate::sim::ParticleSim,
    renderer: crate::render::ParticleRenderer,
    sort: Option<SortStage>,
    target: FrameTarget,
    camera: crate::render::Camera,
    /// The camera at time 0; `camera` is it turned by `orbit` degrees per simulated second.
    camera_start: crate::render::Camera,
    orbit: f32,
    ctx: Context,
}

/// The sort of an alpha-blended scene and the textures it gathers into.
#[derive(Debug)]
struct SortStage {
    sorter: crate::sort::Sorter,
    sorted: crate::gl::Framebuffer,
    back_to_front: bool,
    spread: bool,
    keyed: bool,
}

impl ParticleEngine {
    /// Validates the scene against the device and builds everything.
    pub fn new(ctx: &Context, scene: &crate::scene::SceneFile, seed: u64) -> Result<Self> {
        use crate::gl::{Framebuffer, Texture, TextureDesc, TextureFormat};
        use crate::scene::DrawOrder;
        let [rw, rh] = scene.render.resolution;
        crate::gl::check_size(ctx, "frame (render.resolution)", rw, rh)?;
        let sim = crate::sim::ParticleSim::new(ctx, scene, shader_seed(seed))?;
        let [w, h] = scene.particles.size;
        let mut scales = [1.0f32; 4];
        let mut tiles = [0, 1, 2, 3];
        for (k, e) in scene.emitters.all().enumerate() {
            scales[k] = e.sprite_scale;
            tiles[k] = e.tile.unwrap_or(k as u32);
        }
        let mut style = crate::render::ParticleStyle::from_render(&scene.render, scales);
        style.type_tile = tiles;
        let renderer = crate::render::ParticleRenderer::new(ctx, style, w, h)?;
        let sort = match crate::scene::plan::sort_plan(scene) {
            None => None,
            Some(p) => {
                let options = crate::sort::SortOptions {
                    passes_per_frame: p.passes_per_frame.map(|n| n as usize),
                    ..Default::default()
                };
                let sorter =
                    crate::sort::Sorter::new(ctx, p.variant, p.size[0], p.size[1], options)?;
                let tex = |label: &str| {
                    Texture::new(
                        ctx,
                        TextureDesc {
                            width: w,
                            height: h,
                            format: TextureFormat::Rgba32F,
                            label,
                        },
                    )
                };
                let sorted = Framebuffer::new(
                    ctx,
                    "sorted",
                    vec![tex("sorted position")?, tex("sorted static")?],
                )?;
                Some(SortStage {
                    sorter,
                    sorted,
                    back_to_front: scene.render.order == DrawOrder::BackToFront,
                    spread: p.passes_per_frame.is_some(),
                    keyed: false,
                })
            }
        };
        let camera = crate::render::Camera::from(&scene.render.camera);
        Ok(ParticleEngine {
            target: FrameTarget::new(ctx, rw, rh)?,
            camera,
            camera_start: camera,
            orbit: scene.render.camera.orbit,
            sim,
            renderer,
            sort,
            ctx: ctx.clone(),
        })
    }

    /// Advances the simulation by one frame: `substeps` steps of `dt`.
    pub fn advance_frame(&mut self) -> Result<()> {
        for _ in 0..self.sim.scene().time.substeps {
            self.sim.step()?;
        }
        Ok(())
    }

    /// One frame of collisionless motion ([`crate::sim::ParticleSim::step_without_collisions`]):
    /// births, forces, colliders, no collisions between particles. Benchmarks warm up with it.
    pub fn advance_frame_without_collisions(&mut self) -> Result<()> {
        for _ in 0..self.sim.scene().time.substeps {
            self.sim.step_without_collisions()?;
        }
        Ok(())
    }

    /// Sorts (alpha blending only) and draws the current state into the frame target.
    pub fn draw(&mut self) -> Result<()> {
        let count = self.sim.active_count();
        self.renderer.clear(&self.target);
        if self.order_for_drawing()? {
            let s = self.sort.as_ref().expect("a sort stage");
            let texels = self.sim.size().x as usize * self.sim.size().y as usize;
            // Dead particles sort last (+inf keys), so the live ones are a prefix.
            self.renderer.draw(
                &self.target,
                s.sorted.texture(0),
                s.sorted.texture(1),
                &self.camera,
                texels,
            )?;
        } else {
            self.renderer.draw(
                &self.target,
                self.sim.positions(),
                self.sim.statics(),
                &self.camera,
                count,
            )?;
        }
        self.ctx.check_error("drawing a frame")
    }

    /// The sort stage of a frame, without drawing: turns the camera to the current time, and for
    /// alpha blending writes the viewer-distance keys (refreshed in place when the sort is spread
    /// over frames), runs this frame's share of the sort and gathers positions and statics into
    /// [`sorted`](Self::sorted). Returns whether the scene sorts at all. [`draw`](Self::draw)
    /// calls it; it is public so that the sort's cost and quality can be measured alone.
    pub fn order_for_drawing(&mut self) -> Result<bool> {
        let t = self.sim.time() as f32;
        self.camera.azimuth = self.camera_start.azimuth + self.orbit * t;
        let Some(s) = &mut self.sort else {
            return Ok(false);
        };
        let mode = crate::sort::KeyMode::ViewerDistance {
            eye: self.camera.eye(),
            back_to_front: s.back_to_front,
        };
        let texels = self.sim.size().x as usize * self.sim.size().y as usize;
        if s.spread && s.keyed {
            s.sorter
                .refresh_keys(self.sim.positions(), texels, &mode, true)?;
        } else {
            s.sorter
                .write_keys(self.sim.positions(), texels, &mode, true)?;
            s.keyed = true;
        }
        s.sorter.sort_frame();
        s.sorter
            .gather(&[self.sim.positions(), self.sim.statics()], &s.sorted)?;
        Ok(true)
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
    pub fn sim(&self) -> &crate::sim::ParticleSim {
        &self.sim
    }

    /// The simulation, mutable (to set a state).
    pub fn sim_mut(&mut self) -> &mut crate::sim::ParticleSim {
        &mut self.sim
    }

    /// The positions and statics in drawing order after the last [`draw`](Self::draw) (alpha
    /// blending only).
    pub fn sorted(&self) -> Option<&crate::gl::Framebuffer> {
        self.sort.as_ref().map(|s| &s.sorted)
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
}

/// Either engine, chosen by the scene: the thesis's fire or the particle pipeline.
#[derive(Debug)]
pub enum SceneRunner {
    /// A scene with a `[fire]` section.
    Fire(Box<Engine>),
    /// Every other scene.
    Particles(Box<ParticleEngine>),
}

/// Live particles' positions and velocities, N×4 each, for `--dump-state`.
#[derive(Debug, Clone, PartialEq)]
pub struct StateDump {
    /// xyz and remaining life of every live particle.
    pub positions: Vec<[f32; 4]>,
    /// Velocity (xyz, 0) of the same particles.
    pub velocities: Vec<[f32; 4]>,
    /// Live particles with a NaN or infinite component: kept in the dump, and counted so that
    /// the CLI reports them rather than hiding them.
    pub non_finite: usize,
}

impl SceneRunner {
    /// Builds the engine `scene` needs.
    pub fn new(ctx: &Context, scene: &crate::scene::SceneFile, seed: u64) -> Result<Self> {
        Ok(if scene.fire.is_some() {
            SceneRunner::Fire(Box::new(Engine::new(ctx, Scene::from_file(scene)?, seed)?))
        } else {
            SceneRunner::Particles(Box::new(ParticleEngine::new(ctx, scene, seed)?))
        })
    }

    /// Advances one frame.
    pub fn advance_frame(&mut self) -> Result<()> {
        match self {
            SceneRunner::Fire(e) => {
                e.advance_frame();
                Ok(())
            }
            SceneRunner::Particles(e) => e.advance_frame(),
        }
    }

    /// Renders the current state.
    pub fn render(&mut self) -> Result<image::RgbImage> {
        match self {
            SceneRunner::Fire(e) => e.render(),
            SceneRunner::Particles(e) => e.render(),
        }
    }

    /// Simulation steps taken.
    pub fn steps(&self) -> u64 {
        match self {
            SceneRunner::Fire(e) => e.sim().steps(),
            SceneRunner::Particles(e) => e.sim().steps(),
        }
    }

    /// State texture size.
    pub fn state_size(&self) -> [u32; 2] {
        match self {
            SceneRunner::Fire(e) => e.scene().particles,
            SceneRunner::Particles(e) => e.sim().size().to_array(),
        }
    }

    /// Counts the live particles with a NaN or infinite component on the GPU (a reduction by
    /// fragment passes), so that garbage is reported instead of rendered silently.
    pub fn non_finite(
        &self,
        counter: &crate::sim::nonfinite::NonFiniteCounter,
    ) -> Result<crate::sim::nonfinite::NonFiniteCount> {
        match self {
            SceneRunner::Fire(e) => counter.count(e.sim().positions(), Some(e.sim().velocities())),
            SceneRunner::Particles(e) => counter.count_sim(e.sim()),
        }
    }

    /// Reads back the live particles (remaining life > 0).
    pub fn dump(&self) -> Result<StateDump> {
        let (pos, vel) = match self {
            SceneRunner::Fire(e) => (
                e.sim().positions().read_f32()?,
                e.sim().velocities().read_f32()?,
            ),
            SceneRunner::Particles(e) => (e.sim().read_positions()?, e.sim().read_velocities()?),
        };
        let mut d = StateDump {
            positions: Vec::new(),
            velocities: Vec::new(),
            non_finite: 0,
        };
        for (p, v) in pos.chunks_exact(4).zip(vel.chunks_exact(4)) {
            if p[3] > 0.0 {
                if !p.iter().chain(&v[..3]).all(|x| x.is_finite()) {
                    d.non_finite += 1;
                }
                d.positions.push([p[0], p[1], p[2], p[3]]);
                // The fire keeps its wait counter in velocity.w; the dump holds velocities only.
                d.velocities.push([v[0], v[1], v[2], 0.0]);
            }
        }
        Ok(d)
    }
}
