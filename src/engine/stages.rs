//! A GPU engine's frame in its stages, for the measuring floor: `bench scene` and `bench step`
//! time them one by one, `trace` pictures them, the report reads the sort. Everything above the
//! engines reaches them through [`Engine::stages`](super::Engine::stages) on the engine
//! [`build`](super::build) made, so that what is measured is what `render` runs.

use crate::error::Result;
use crate::gl::{Blend, Framebuffer};
use crate::render::{Camera, HalfAngleRenderer, ParticleRenderer};
use crate::sim::Simulation;
use crate::sort::{KeyMode, Sorter};

/// One frame of a GPU engine taken apart: the simulation's stages (each run alone by
/// [`Simulation::run`]), the sort alpha blending needs (keys, network, gather) and the render
/// pass. Run in order, the parts are the engine's frame: [`sort_keys`](Self::sort_keys),
/// [`sort_network`](Self::sort_network) and [`sort_gather`](Self::sort_gather) are what
/// [`order_for_drawing`](super::Engine::order_for_drawing) runs, and
/// [`render_pass`](Self::render_pass) is what [`draw`](super::Engine::draw) runs after it.
///
/// ```
/// use texflow::{engine, gl::Context, scene};
/// let ctx = Context::new(0)?;
/// let mut s = scene::load("e3")?; // alpha blending: sorted
/// s.particles.size = [16, 16];
/// s.render.resolution = [16, 16];
/// let mut e = engine::build(&ctx, &s, 1, engine::EngineKind::Gpu)?;
/// let g = e.stages().expect("the GPU engine has stages");
/// g.advance_frame()?;
/// assert!(g.sort_keys()?.is_some());
/// assert!(g.sort_network() > 0);
/// g.sort_gather()?;
/// g.render_pass(true)?;
/// assert_eq!(g.model(), "particles");
/// # Ok::<(), texflow::Error>(())
/// ```
pub trait Stages: super::Engine {
    /// The simulation: its pass list, its stages, its state.
    fn sim(&self) -> &dyn Simulation;

    /// The simulation, mutable: to run a stage alone.
    fn sim_mut(&mut self) -> &mut dyn Simulation;

    /// The simulation's model, as benchmark records name it: `fire` or `particles`.
    fn model(&self) -> &'static str;

    /// The particle renderer.
    fn renderer(&self) -> &ParticleRenderer;

    /// Half-angle slicing, when the scene is lit.
    fn lit(&self) -> Option<&HalfAngleRenderer>;

    /// The camera of the last sort stage (turned by the orbit and the viewer).
    fn camera(&self) -> &Camera;

    /// The blend and clear colour the frame's particles are drawn with: the half-angle eye
    /// passes' (under or over, from where the light is this frame) when lit, else the
    /// renderer's. The render floors draw with the same.
    fn frame_blend(&self) -> (Blend, [f32; 4]) {
        match self.lit() {
            Some(lit) => {
                let d = lit.slice_draws(self.camera());
                (d.eye_blend, d.eye_clear)
            }
            None => {
                let p = self.renderer().params();
                (p.blend, p.clear_color)
            }
        }
    }

    /// The sorter of an alpha-blended scene.
    fn sorter(&self) -> Option<&Sorter>;

    /// The state in drawing order after the last gather (alpha blending with the gather).
    fn sorted(&self) -> Option<&Framebuffer>;

    /// The sort stage's key pass: turns the camera to the current time, sets the compact
    /// sort's depth range and writes the keys; the key mode it wrote, `None` for a scene
    /// that does not sort.
    fn sort_keys(&mut self) -> Result<Option<KeyMode>>;

    /// This frame's share of the sort network; the passes run (0 for a scene that does not
    /// sort).
    fn sort_network(&mut self) -> usize;

    /// The gather into [`sorted`](Self::sorted) (nothing with the index lookup); marks the
    /// sorted state as this step's.
    fn sort_gather(&mut self) -> Result<()>;

    /// The render pass alone, from the sorted state when `sorted`.
    fn render_pass(&self, sorted: bool) -> Result<()>;

    /// The render pass drawn by `renderer` instead (a benchmark's fill floor).
    fn render_pass_with(&self, renderer: &ParticleRenderer, sorted: bool) -> Result<()>;

    /// The sort stage, handing the sorter to `seen` after the key pass (`"keys"`) and after
    /// the network (`"network"`); whether the scene sorts.
    fn order_for_drawing_observed(
        &mut self,
        seen: &mut dyn FnMut(&str, &Sorter) -> Result<()>,
    ) -> Result<bool>;
}
