//! The passes of one step with the programs each draws: the features' lines
//! ([`Features::step_passes`](super::Features::step_passes)), each given the draws of the programs
//! this simulation built (its own, the relaxation's, the collision and fluid stages', their
//! sorters'), so that the list is checked against what a frame draws (tests/pass_list.rs).

use super::{ParticleSim, State};
use crate::gl::{attach_draws, PassDraw, PassInfo};
use crate::sim::{Pass, Stage};

impl ParticleSim {
    /// The passes of one step, in order, with the draws of each per step.
    pub(super) fn pass_list(&self) -> Vec<PassInfo> {
        let lines = self.features.step_passes();
        let mut out = Vec::new();
        for stage in crate::sim::stages_of(&lines) {
            let mut names: Vec<String> = (lines.iter().filter(|p| p.stage == stage))
                .map(|p: &Pass| p.name.clone())
                .collect();
            let draws = match stage {
                Stage::Births => self.birth_draws(),
                Stage::Integrate => {
                    if self.bounces.is_some() && matches!(self.state, State::Explicit(_)) {
                        names.push(super::bounces::bounce_tally_line());
                    }
                    self.integration_draws()
                }
                Stage::Relax => (self.relax.iter()).flat_map(|r| r.pass_draws()).collect(),
                Stage::Collide => {
                    let mut d: Vec<PassDraw> =
                        (self.fluid.iter()).flat_map(|f| f.pass_draws()).collect();
                    d.extend(self.collisions.iter().flat_map(|c| c.pass_draws()));
                    d.extend(self.fluid_carry_draws());
                    d
                }
            };
            out.extend(attach_draws(stage.label(), names, draws));
        }
        out
    }
}
