//! The thesis's fire: its simulation, its point renderer and its frame target on one context.
//!
//! One frame is `substeps` simulation steps of `dt` seconds, then one render pass. Each step is
//! one full-screen pass that reads the front state and writes the back state (MRT), then a swap.

use super::shader_seed;
use crate::error::Result;
use crate::gl::Context;
use crate::render::{FrameTarget, PointRenderer};
use crate::scene::Scene;
use crate::sim::FireSim;

/// Runs the thesis's fire: its simulation pass, its point renderer and its frame target.
///
/// ```
/// use texflow::{gl::Context, scene, FireEngine};
/// let ctx = Context::new(0)?;
/// let mut fire = scene::builtin("fire")?;
/// fire.particles = [32, 32];
/// fire.resolution = [32, 32];
/// let mut engine = FireEngine::new(&ctx, fire, 1)?;
/// engine.advance_frame();
/// assert_eq!(engine.sim().steps(), engine.scene().substeps as u64);
/// # Ok::<(), texflow::Error>(())
/// ```
#[derive(Debug)]
pub struct FireEngine {
    scene: Scene,
    sim: FireSim,
    points: PointRenderer,
    target: FrameTarget,
    view: crate::render::ViewOffset,
    ctx: Context,
}

impl FireEngine {
    /// Validates the scene against itself and the device, and builds everything.
    pub fn new(ctx: &Context, scene: Scene, seed: u64) -> Result<Self> {
        scene.validate()?;
        let [w, h] = scene.particles;
        crate::gl::check_size(ctx, "particle texture (--particles)", w, h)?;
        let [rw, rh] = scene.resolution;
        crate::gl::check_size(ctx, "frame (--resolution)", rw, rh)?;
        let sim = FireSim::new(ctx, w, h, (&scene.fire).into(), shader_seed(seed))?;
        Ok(FireEngine {
            points: PointRenderer::new(ctx)?,
            target: FrameTarget::new(ctx, rw, rh)?,
            sim,
            scene,
            view: crate::render::ViewOffset::default(),
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
        let [r, g, b] = self.scene.background;
        self.target.clear_to([r, g, b, 1.0]);
        let mut camera = crate::render::Camera::from(&self.scene.camera);
        camera.azimuth +=
            self.scene.camera.orbit * (self.sim.steps() as f64 * self.scene.dt as f64) as f32;
        let camera = self.view.apply(camera);
        self.points.draw(
            &self.target,
            self.sim.positions(),
            self.sim.velocities(),
            &camera,
            &(&self.scene.style).into(),
        );
    }

    /// Sets the viewer's change to the scene's camera (the live window).
    pub fn set_view(&mut self, view: crate::render::ViewOffset) {
        self.view = view;
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
