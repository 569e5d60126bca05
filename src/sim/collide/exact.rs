//! The exact mode's step: every iteration keys, sorts and gathers the state it reads again, so
//! each iteration's search walks the cells the particles are in now, not where the step's first
//! sort found them. An iteration is the whole stage: keys, sort, gather, partner counts (the one
//! walk of the cells, which also sums the response's separations), the response with every
//! partner, and the static texture copied in the new order.

use super::{CollisionStage, Passes, Readback, EXCHANGED, PARTNERS, SEPARATION};
use crate::error::Result;
use crate::gl::{Defines, Framebuffer, PingPong, Sampled, Uniform, UniformList};
use crate::scene;
use crate::sim::state::{POSITION, STATIC, VELOCITY};

impl CollisionStage {
    /// `collisions.iterations` exact iterations; with [`record_iterations`]
    /// (Self::record_iterations) on, each one's detection is read back after its count pass.
    pub(super) fn run_exact(
        &mut self,
        state: &mut PingPong,
        statics: &mut Framebuffer,
        dt: f32,
        fields: &[(&str, Sampled<'_>)],
        constants: &UniformList,
    ) -> Result<()> {
        self.recorded.clear();
        for _ in 0..self.config.iterations.max(1) {
            self.sort_first(state, statics)?;
            self.exchange(constants);
            let Passes::Exact {
                counts,
                count,
                response,
            } = &self.passes
            else {
                unreachable!("called in the exact mode only");
            };
            let g = &self.first;
            // A field, not `searched()`: the read-backs are pushed while it is held.
            let cells = g
                .sorted
                .search()
                .expect("the exact detection builds the search");
            let entries = (self.width * state.height()) as i32;
            let mut search = self.contact_search();
            search.extend([
                ("u_restitution", Uniform::F32(self.config.restitution)),
                ("u_dt", Uniform::F32(dt)),
            ]);
            let layout = g.sorted.layout();
            let mut own: Vec<(&str, Sampled)> = vec![
                ("u_position", layout.texture(POSITION).into()),
                ("u_velocity", layout.texture(VELOCITY).into()),
                ("u_static", layout.texture(STATIC).into()),
            ];
            if let Some(s) = &g.spin {
                own.push(("u_spin", s.only_texture().into()));
            }
            let mut textures = cells.textures(g.sorted.keys());
            textures.extend(own.iter().cloned());
            self.pass.draw(
                count,
                &textures,
                &constants.for_draw(count, search.clone()),
                counts,
            );
            if let Some(t) = &self.tally {
                t.add(counts.texture(PARTNERS), entries as usize);
            }
            if self.record {
                self.recorded.push(Readback {
                    positions: layout.texture(POSITION).read_f32()?,
                    velocities: layout.texture(VELOCITY).read_f32()?,
                    partners: self.read_partners(counts)?,
                });
            }
            // The response walks nothing: it reads the count's sums, and the closest partner's
            // count and state.
            let p = response;
            let mut textures = own;
            textures.extend([
                ("u_counts", counts.texture(PARTNERS).into()),
                ("u_separation", counts.texture(SEPARATION).into()),
                ("u_exchanged", counts.texture(EXCHANGED).into()),
            ]);
            textures.extend(fields.iter().filter(|(n, _)| p.declares(n)).copied());
            let uniforms = constants.for_draw(p, search);
            self.pass.draw(p, &textures, &uniforms, state.back());
            state.swap();
            self.take_statics(false, statics)?;
            self.carry_back(false);
        }
        Ok(())
    }

    /// The count pass's (partners, truncated, closest, distance) read back, in sorted order (it
    /// wrote them in the walk's: [`walk_order`](super::walk_order)).
    pub(super) fn read_partners(&self, counts: &Framebuffer) -> Result<Vec<f32>> {
        let size = [counts.width(), counts.height()];
        let texels = counts.texture(PARTNERS).read_f32()?;
        Ok(super::walk_order::to_sorted_order(size, &texels, 4))
    }

    /// The first lattice's search, which the exact mode, the neighbour forces and the exchanges
    /// read (built with the stage whenever the detection is exact, which all of them need).
    pub(super) fn searched(&self) -> &super::cells::CellSearch {
        self.first
            .sorted
            .search()
            .expect("the exact detection builds the search")
    }

    /// The search's uniforms for the passes that look for contacts (closer than 2 radius): the
    /// radius, and the reach of a trimmed walk (a cell below 2 radius), 2 radius.
    pub(super) fn contact_search(&self) -> Vec<(&'static str, Uniform)> {
        let r = self.config.radius;
        let mut out = self.searched().uniforms();
        out.extend([
            ("u_radius", Uniform::F32(r)),
            ("u_search_radius", Uniform::F32(2.0 * r)),
        ]);
        out
    }

    /// Whether the exact mode reads back every iteration's detection (`recorded`
    /// (Self::recorded)): for statistics, which cost a read-back per iteration.
    pub fn record_iterations(&mut self, on: bool) {
        self.record = on;
    }

    /// The exact mode's detection of each iteration of the last step, in the order they ran,
    /// if [`record_iterations`](Self::record_iterations) was on (else empty). Each is in that
    /// iteration's sorted order; `partners` holds (partners found, truncated, 0, 0).
    pub fn recorded(&self) -> &[Readback] {
        &self.recorded
    }
}

/// The simulation's `defines` and how the collision sort lays out its sorted keys, for the
/// passes that search them (`glsl/collide/cells.glsl`): `PACKED_KEYS` for the packed network's
/// two entries per texel; none for the blocked network's one (key, id) per texel.
pub(super) fn key_layout(defines: &Defines, sort: scene::CollisionSort) -> Defines {
    let mut d = defines.clone();
    if sort.variant().packed() {
        d.push(("PACKED_KEYS".into(), "1".into()));
    }
    d
}

/// The sorted keys' layout ([`key_layout`]) and, where the exact search of `c`'s lattice over a
/// `size` state reads a cell-start table, `CELL_TABLE` (`src/sim/collide/cells.rs`).
pub(super) fn search_layout(defines: &Defines, c: &scene::Collisions, size: [u32; 2]) -> Defines {
    let d = key_layout(defines, c.sort);
    match c.detection {
        scene::Detection::Exact => {
            super::cells::search_defines(&d, &super::Lattice::of(c, false), size)
        }
        scene::Detection::Uberflow => d,
    }
}

/// The simulation's `defines` and the stage's own: the detection loop's bounds, and whether a
/// staggered lattice's detection is gathered along.
pub(super) fn stage_defines(defines: &Defines, staggered: bool) -> Defines {
    let mut d = defines.clone();
    // The neighbours themselves are a uniform: fetching them all before weighing any, with the
    // count compiled in, ran 0.1 ms a draw slower at 1024² on an NVIDIA H100.
    d.push(("MAX_NEIGHBOURS".into(), super::MAX_NEIGHBOURS.to_string()));
    d.push(("EXACT_SCAN".into(), super::EXACT_SCAN.to_string()));
    if staggered {
        d.push(("STAGGERED".into(), "1".into()));
    }
    d
}
