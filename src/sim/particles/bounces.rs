//! Paths that still entered a collider after the bound on bounces per step (`MAX_BOUNCES` in
//! `glsl/sim/colliders.glsl`): the integration pass flags them in the velocity's w, and a tally
//! on the GPU counts the flags after every step, read back once at the end of a run, as the exact
//! search's truncations are (`crate::sim::collide::tally`).

use super::{ParticleSim, State};
use crate::error::Result;
use crate::gl::Context;
use crate::scene::Integrator;
use crate::sim::collide::tally::TruncationTally;
use crate::sim::particles::Features;
use crate::sim::state::VELOCITY;

/// The bounce tally's line in the pass list: the integration flags paths past the bound in the
/// velocity's w.
pub(super) fn bounce_tally_line() -> String {
    crate::sim::collide::tally::pass_line(
        "bounce tally: the particles whose path hit the bound on bounces at the colliders",
    )
}

/// A tally where the integration pass can flag a particle: explicit integrators with a plane, a
/// sphere or a box (the colliders `bounce_on` follows).
pub(super) fn tally(
    ctx: &Context,
    f: &Features,
    size: [u32; 2],
) -> Result<Option<TruncationTally>> {
    let bounces = f.collider_counts.any_bouncing();
    if bounces && f.integrator != Integrator::Verlet {
        Ok(Some(TruncationTally::new(ctx, size)?))
    } else {
        Ok(None)
    }
}

impl ParticleSim {
    /// Adds the particles the last integration pass flagged: the texels of its `rows` (rows
    /// above them keep older velocities, whose flags were counted when they were written) below
    /// the child emitters', whose velocity's w counts dropped births.
    pub(super) fn count_bounce_flags(&self, rows: u32) {
        let (Some(t), State::Explicit(pp)) = (&self.bounces, &self.state) else {
            return;
        };
        let n =
            (self.params.emitters.layout.parent_slots as usize).min((self.width * rows) as usize);
        t.add_flags(pp.front().texture(VELOCITY), 3, n);
    }

    /// Paths that entered a collider after `MAX_BOUNCES` bounces in a step, summed over steps
    /// (one read-back of one texel; call it once, at the end of a run). 0 without planes,
    /// spheres or boxes, or with Verlet.
    pub fn truncated_bounces(&self) -> Result<u64> {
        self.bounces.as_ref().map_or(Ok(0), |t| t.total())
    }
}
