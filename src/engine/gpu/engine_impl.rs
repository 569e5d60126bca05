//! The [`Engine`](crate::engine::Engine) trait for [`GpuEngine`] over any simulation: what the
//! frame loop, the CLI and the benchmarks call.

use super::GpuEngine;
use crate::error::Result;
use crate::render::FrameTarget;
use crate::sim::Simulation;

impl<S: Simulation> crate::engine::Engine for GpuEngine<S> {
    fn advance_frame(&mut self) -> Result<()> {
        GpuEngine::advance_frame(self)
    }

    fn warm_up_frame(&mut self) -> Result<()> {
        self.advance_frame_without_collisions()
    }

    fn order_for_drawing(&mut self) -> Result<()> {
        GpuEngine::order_for_drawing(self).map(drop)
    }

    fn draw(&mut self) -> Result<()> {
        GpuEngine::draw(self)
    }

    fn target(&self) -> &FrameTarget {
        &self.target
    }

    fn set_view(&mut self, view: crate::render::ViewOffset) {
        GpuEngine::set_view(self, view)
    }

    fn steps(&self) -> u64 {
        self.sim.steps()
    }

    fn state_size(&self) -> [u32; 2] {
        self.sim.size()
    }

    fn dropped_births(&self) -> u64 {
        self.sim.dropped_births()
    }

    fn dropped_child_births(&self) -> Result<u64> {
        self.sim.dropped_child_births()
    }

    fn truncated_searches(&self) -> Result<u64> {
        self.sim.truncated_searches()
    }

    fn stretched(&self) -> Result<Option<crate::sim::Stretched>> {
        self.sim.stretched()
    }

    fn fluid_stats(&self) -> Result<Option<crate::sim::fluid::FluidStats>> {
        self.sim.fluid_stats()
    }

    fn truncated_bounces(&self) -> Result<u64> {
        self.sim.truncated_bounces()
    }

    fn non_finite(
        &self,
        counter: &crate::sim::nonfinite::NonFiniteCounter,
    ) -> Result<crate::sim::nonfinite::NonFiniteCount> {
        self.sim.non_finite(counter)
    }

    fn dump(&self) -> Result<crate::engine::StateDump> {
        let (p, v) = self.sim.read_state()?;
        Ok(crate::engine::StateDump::of_live_with(
            &p,
            &v,
            &self.sim.read_more()?,
        ))
    }

    fn emitter_keys(&self) -> Vec<String> {
        self.emitter_keys.clone()
    }

    fn live(&self) -> Result<u64> {
        let p = self.sim.drawn().positions.read_f32()?;
        Ok(p.chunks_exact(4)
            .filter(|p| crate::sim::particle_live([p[0], p[1], p[2], p[3]]))
            .count() as u64)
    }

    fn timed_frame(&mut self, timer: &crate::gl::PassTimer) -> Result<Vec<(&'static str, f64)>> {
        let simulate = crate::engine::timed(timer, || GpuEngine::advance_frame(self))?;
        let draw = crate::engine::timed(timer, || GpuEngine::draw(self))?;
        let name = if self.sort.is_some() {
            "keys, sort, gather and draw"
        } else {
            "draw"
        };
        Ok(vec![("simulate", simulate), (name, draw)])
    }

    fn stages(&mut self) -> Option<&mut dyn crate::engine::Stages> {
        Some(self)
    }

    fn stages_ref(&self) -> Option<&dyn crate::engine::Stages> {
        Some(self)
    }

    fn census(&self) -> Result<Option<crate::sim::collide::PairCensus>> {
        self.sim.census()
    }

    fn plan(&self) -> crate::engine::plan::Plan {
        crate::engine::plan::Plan::new(&self.name, self.sim.substeps(), self.frame_passes())
    }
}
