//! The SPH stage of a scene with `[fluid]` (src/sim/fluid/) in the particle pipeline: the
//! particles placed on their lattice at the start, the fluid's passes as the collision stage,
//! its counts and per-frame figures.

use super::{set_constants_for, ParticleSim, State};
use crate::error::{Error, Result};
use crate::gl::Program;
use crate::scene::SceneFile;
use crate::sim::fluid::FluidStats;
use crate::sim::state::{POSITION, VELOCITY};

impl ParticleSim {
    /// Places the fluid's particles on the lattice of their box emitters (after the initial
    /// state is drawn).
    pub(super) fn place_fluid(&mut self, scene: &SceneFile) {
        if let (Some(f), State::Explicit(pp)) = (&self.fluid, &mut self.state) {
            f.place(scene, pp);
        }
    }

    /// One step of the fluid's passes on the integrated state.
    pub(super) fn run_fluid(&mut self) -> Result<()> {
        let (Some(f), State::Explicit(pp)) = (self.fluid.as_mut(), &mut self.state) else {
            return Err(Error::InvalidInput(
                "[fluid] needs an explicit integrator".into(),
            ));
        };
        let (params, fields) = (&self.params, &self.fields);
        let (size, seed, types) = ([self.width, self.height], self.seed, self.features.types);
        let set = |p: &Program| set_constants_for(p, params, fields, size, seed, types);
        f.run(pp, &self.statics, params.time.dt, set)
    }

    /// Fluid searches that hit their bound, over the run (one read-back).
    pub(super) fn fluid_truncated(&self) -> Result<u64> {
        self.fluid
            .as_ref()
            .map_or(Ok(0), |f| f.truncated_searches())
    }

    /// The fluid's density error and energy now (scenes with `[fluid]`; read-backs of the state
    /// and the last density pass).
    pub fn fluid_stats(&self) -> Result<Option<FluidStats>> {
        let (Some(f), State::Explicit(pp)) = (&self.fluid, &self.state) else {
            return Ok(None);
        };
        let front = pp.front();
        f.stats(front.texture(POSITION), front.texture(VELOCITY))
            .map(Some)
    }
}
