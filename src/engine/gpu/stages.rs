//! The GPU engine's sort stage in its three parts (keys, network, gather), which
//! [`order_for_drawing`](GpuEngine::order_for_drawing) runs in order, and the
//! [`Stages`](crate::engine::Stages) the measuring floor times them through.

use super::GpuEngine;
use crate::error::Result;
use crate::sim::Simulation;
use crate::sort::{KeyMode, Sorter};

impl<S: Simulation> GpuEngine<S> {
    /// The key pass: turns the camera to the current time, and for alpha blending writes the
    /// keys (refreshed in place when the sort is spread over frames) in the compact sort's
    /// depth range; the key mode written, `None` for a scene that does not sort.
    pub fn sort_keys(&mut self) -> Result<Option<KeyMode>> {
        self.turn_camera();
        let Some(s) = &mut self.sort else {
            return Ok(None);
        };
        let mode = match &self.lit {
            Some(l) => crate::engine::half_angle_keys(&self.camera, l.light()),
            None => super::key_mode(s.key, self.camera.eye(), s.back_to_front),
        };
        let [w, h] = self.sim.size();
        let texels = w as usize * h as usize;
        let d = self.sim.drawn();
        if s.sorter.quantiser().is_some() {
            let (lo, hi) = super::compact_depth_range(self.camera.distance);
            let (lo, hi) = if s.back_to_front {
                (-hi, -lo)
            } else {
                (lo, hi)
            };
            s.sorter.set_key_range(lo, hi)?;
        }
        let refresh = s.spread && s.keyed;
        s.sorter
            .write_keys_with_statics(d.positions, d.statics, texels, &mode, true, refresh)?;
        s.keyed = true;
        Ok(Some(mode))
    }

    /// This frame's share of the sort network (all of it unless spread over frames); the
    /// passes run.
    pub fn sort_network(&mut self) -> usize {
        self.sort.as_mut().map_or(0, |s| s.sorter.sort_frame())
    }

    /// The gather of the state the renderer draws (positions, statics, and the motion and
    /// spins where it draws them) into [`sorted`](Self::sorted) in the sort's order; nothing
    /// with the index lookup (Latta §3.4.4). The sorted state is this step's from now on.
    pub fn sort_gather(&mut self) -> Result<()> {
        let steps = self.sim.steps();
        let Some(s) = &mut self.sort else {
            return Ok(());
        };
        if !s.lookup {
            let d = self.sim.drawn();
            let mut sources = vec![d.positions, d.statics];
            if self.renderer.needs_motion() {
                sources.extend(d.velocities.or(d.previous));
            }
            if self.renderer.needs_spins() {
                sources.extend(d.spins);
            }
            s.sorter.gather(&sources, &s.sorted)?;
        }
        s.ordered_at = Some(steps);
        Ok(())
    }
}

impl<S: Simulation> crate::engine::Stages for GpuEngine<S> {
    fn sim(&self) -> &dyn Simulation {
        &self.sim
    }

    fn sim_mut(&mut self) -> &mut dyn Simulation {
        &mut self.sim
    }

    fn model(&self) -> &'static str {
        self.model
    }

    fn renderer(&self) -> &crate::render::ParticleRenderer {
        &self.renderer
    }

    fn lit(&self) -> Option<&crate::render::HalfAngleRenderer> {
        self.lit.as_ref()
    }

    fn camera(&self) -> &crate::render::Camera {
        &self.camera
    }

    fn sorter(&self) -> Option<&Sorter> {
        GpuEngine::sorter(self)
    }

    fn sorted(&self) -> Option<&crate::gl::Framebuffer> {
        GpuEngine::sorted(self)
    }

    fn sort_keys(&mut self) -> Result<Option<KeyMode>> {
        GpuEngine::sort_keys(self)
    }

    fn sort_network(&mut self) -> usize {
        GpuEngine::sort_network(self)
    }

    fn sort_gather(&mut self) -> Result<()> {
        GpuEngine::sort_gather(self)
    }

    fn render_pass(&self, sorted: bool) -> Result<()> {
        GpuEngine::render_pass(self, sorted)
    }

    fn render_pass_with(
        &self,
        renderer: &crate::render::ParticleRenderer,
        sorted: bool,
    ) -> Result<()> {
        GpuEngine::render_pass_with(self, renderer, sorted)
    }

    fn order_for_drawing_observed(
        &mut self,
        seen: &mut dyn FnMut(&str, &Sorter) -> Result<()>,
    ) -> Result<bool> {
        GpuEngine::order_for_drawing_observed(self, seen)
    }
}
