//! The passes of one step with the programs each draws: the features' lines
//! ([`Features::step_passes`](super::Features::step_passes)), each given the draws of the programs
//! this simulation built (its own, the relaxation's, the collision and fluid stages', their
//! sorters'), so that the list is checked against what a frame draws (tests/pass_list.rs).

use super::{ParticleSim, State};
use crate::gl::{attach_draws, PassDraw, PassInfo};
use crate::sim::{Pass, Stage};

/// The bounce tally's line: the integration flags paths past the bound in the velocity's w.
const BOUNCE_TALLY: &str = "bounce tally: one point per particle whose path hit the bound on \
                            bounces at the colliders, added into one texel (read back once, at \
                            the end of a run)";

/// The stage's name in the pass list.
pub(crate) fn stage_label(stage: Stage) -> &'static str {
    match stage {
        Stage::Births => "births",
        Stage::Integrate => "integrate",
        Stage::Relax => "relax",
        Stage::Collide => "collide",
    }
}

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
                        names.push(BOUNCE_TALLY.into());
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
            out.extend(attach_draws(stage_label(stage), names, draws));
        }
        out
    }

    /// The allocator's births: each program at most once a step (none without births).
    fn birth_draws(&self) -> Vec<PassDraw> {
        [&self.emit_state, &self.emit_previous, &self.emit_static]
            .into_iter()
            .flatten()
            .map(|p| PassDraw::of("emit:", p, 1).varying())
            .collect()
    }

    /// The integration (or its halves, or the closed form), the user states, the bounce tally.
    fn integration_draws(&self) -> Vec<PassDraw> {
        let mut out = Vec::new();
        match (&self.stateless, &self.integrate_position) {
            (Some(s), _) => out.push(PassDraw::of("stateless", &s.program, 1)),
            (None, Some(position)) => {
                out.push(PassDraw::of("integrate velocity", &self.integrate, 1));
                out.push(PassDraw::of("integrate position", position, 1));
            }
            (None, None) => {
                // "integrate: …" or "integrate (live rows only): …".
                out.push(PassDraw::of("integrate:", &self.integrate, 1));
                out.push(PassDraw::of("integrate (", &self.integrate, 1));
            }
        }
        if let Some(u) = &self.user {
            out.extend(u.pass_draws());
        }
        if let (Some(t), State::Explicit(_)) = (&self.bounces, &self.state) {
            out.push(PassDraw::of("bounce tally", t.program(), 1));
        }
        out
    }
}
