//! The lattices' sorts and gathers of one UberFlow collision step, and where the response reads
//! the first lattice's partners.
//!
//! With the staggered lattice the state is gathered twice: into the first lattice's order, then
//! from there into the staggered lattice's, where the response writes the new state. Only the
//! detections read the first lattice's layout, and they read positions alone, so the first
//! gather writes the positions only ([`reads_through_first`]): the staggered gather reads
//! velocity and static at the place the first sort gave each particle, in the state the first
//! sort read (`glsl/sort/first_id.glsl`), the first lattice's mutual check writes its partners
//! as places in that state, and the response reads the first lattice's partners there. The
//! values read are the same texels as before; 32 bytes a particle fewer are written a step.

use super::{CollisionStage, FIRST_PARTNER};
use crate::error::Result;
use crate::gl::{Framebuffer, PingPong, Sampled};
use crate::sim::state::{POSITION, SPIN, STATIC, VELOCITY};

/// The staggered gather's sources read through the first sort: velocity and static (of
/// position, velocity, static, first partner).
const THROUGH: u32 = 0b0110;

/// Whether the first lattice gathers positions alone, the staggered lattice reading velocity and
/// static through both sorts: UberFlow's detection on the staggered grid, without neighbour
/// forces (whose passes read the first layout's velocity and static). The stage and the pass
/// list both ask this.
pub fn reads_through_first(staggered: bool, exact: bool, neighbour_forces: bool) -> bool {
    staggered && !exact && !neighbour_forces
}

impl CollisionStage {
    /// Keys on the first lattice from the current state, the sort, and the gather of position,
    /// velocity and static into the lattice's layout (positions alone where the staggered
    /// lattice reads the rest through both sorts).
    pub(super) fn sort_first(&mut self, state: &PingPong, statics: &Framebuffer) -> Result<()> {
        let count = self.width as usize * state.height() as usize;
        let front = state.front();
        let g = &mut self.first;
        if self.through {
            g.sorted
                .sort_positions(&self.pass, count, front.texture(POSITION))?;
        } else {
            g.sorted.sort(
                &self.pass,
                count,
                &[
                    front.texture(POSITION),
                    front.texture(VELOCITY),
                    statics.texture(STATIC),
                ],
            )?;
        }
        if let Some(spin) = &g.spin {
            g.sorted.gather(&[front.texture(SPIN)], spin)?;
        }
        self.gather_states(false)
    }

    /// The staggered lattice, if any: keys on it from the first lattice's layout, the sort, and
    /// the gather of that layout with the first detection along (velocity and static through
    /// both sorts from `state` and `statics`, where the first lattice gathered positions alone).
    pub(super) fn sort_second(
        &mut self,
        count: usize,
        state: &PingPong,
        statics: &Framebuffer,
    ) -> Result<()> {
        if let Some(g2) = &mut self.second {
            let a = self.first.sorted.layout();
            let partner = self.first.partner.only_texture();
            if self.through {
                let front = state.front();
                let sources = [
                    a.texture(POSITION),
                    front.texture(VELOCITY),
                    statics.texture(STATIC),
                    partner,
                ];
                let first = &self.first.sorted;
                g2.sorted
                    .sort_through(&self.pass, count, first, THROUGH, &sources)?;
            } else {
                let sources = [
                    a.texture(POSITION),
                    a.texture(VELOCITY),
                    a.texture(STATIC),
                    partner,
                ];
                g2.sorted.sort(&self.pass, count, &sources)?;
            }
            if let (Some(from), Some(to)) = (&self.first.spin, &g2.spin) {
                g2.sorted.gather(&[from.only_texture()], to)?;
            }
        }
        self.gather_states(true)
    }

    /// The response's samplers of the first lattice's partners (with the staggered lattice):
    /// the first detection gathered into `own`, and the state the partners' places name: the
    /// first layout, or where it holds positions alone the state the first sort read
    /// (`state`, `statics`).
    pub(super) fn first_partner_textures<'a>(
        &'a self,
        own: &'a Framebuffer,
        state: &'a PingPong,
        statics: &'a Framebuffer,
    ) -> Vec<(&'static str, Sampled<'a>)> {
        // The state the partners' places name: its position and velocity, and its static.
        let first = self.first.sorted.layout();
        let (pv, st) = match self.through {
            true => (state.front(), statics),
            false => (first, first),
        };
        let mut out = vec![
            ("u_partner2", own.texture(FIRST_PARTNER).into()),
            ("u_position2", pv.texture(POSITION).into()),
            ("u_velocity2", pv.texture(VELOCITY).into()),
            ("u_static2", st.texture(STATIC).into()),
        ];
        if let Some(spin) = &self.first.spin {
            let spin2 = match self.through {
                true => state.front().texture(SPIN),
                false => spin.only_texture(),
            };
            out.push(("u_spin2", spin2.into()));
        }
        out
    }

    /// The first layout's velocities in its order (RGBA texels), where the first lattice
    /// gathered positions alone: the staggered layout's, each put back at the place in the
    /// first layout the staggered sort took it from.
    pub(super) fn first_velocities(&self) -> Result<Vec<f32>> {
        let g = &self.first;
        if !self.through {
            return g.sorted.layout().texture(VELOCITY).read_f32();
        }
        let g2 = self
            .second
            .as_ref()
            .expect("reading through needs the staggered lattice");
        let v2 = g2.sorted.layout().texture(VELOCITY).read_f32()?;
        let mut out = vec![0.0; v2.len()];
        for (s, e) in g2.sorted.sorter().read()?.iter().enumerate() {
            let i = e[1] as usize * 4;
            out[i..i + 4].copy_from_slice(&v2[s * 4..s * 4 + 4]);
        }
        Ok(out)
    }

    /// Hands the static texture of the layout the response wrote the state in (the second
    /// lattice's with `second`, else the first's) to the simulation, which gives its own
    /// (the old order) to the layout as the next gather's target: the statics in the new
    /// order without a copy pass.
    pub(super) fn take_statics(&mut self, second: bool, statics: &mut Framebuffer) -> Result<()> {
        let g = match (second, &mut self.second) {
            (true, Some(g2)) => g2,
            _ => &mut self.first,
        };
        statics.exchange(STATIC, g.sorted.layout_mut(), STATIC)
    }
}
