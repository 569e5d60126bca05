//! What each exact iteration found, and what a run did to kinetic energy and momentum: the
//! parts of `texflow collide-stats` that follow the stage through a step and through a run.

use glam::Vec3;

use crate::error::Result;
use crate::sim::collide::CollisionStage;
use crate::sim::params::Integration;
use crate::sim::ParticleSim;

pub use super::collide_stats::IterationStats;
use super::collide_stats::{LatticeSnapshot, Snapshot};

/// The recorded iterations of the last step of `stage` (see
/// [`CollisionStage::record_iterations`]), each measured against the CPU's true pairs.
pub fn iteration_stats(stage: &CollisionStage) -> Vec<IterationStats> {
    let lattice = stage.lattices().0;
    stage
        .recorded()
        .iter()
        .enumerate()
        .map(|(k, r)| {
            let snap = Snapshot {
                width: stage.width(),
                neighbours: stage.config().neighbours,
                radius: stage.config().radius,
                dt: stage.dt(),
                first: LatticeSnapshot {
                    lattice,
                    positions: r.positions.clone(),
                    velocities: r.velocities.clone(),
                    partners: r.partners.clone(),
                },
                second: None,
                exact: true,
            };
            let s = snap.stats();
            IterationStats {
                iteration: k as u32 + 1,
                pairs_true: s.pairs_true,
                found: s.found,
                missed: s.missed,
                truncated: s.truncated,
            }
        })
        .collect()
}

/// Total kinetic energy Σ ½ m v² and momentum Σ m v of the live particles, each with its own
/// mass (the CPU twin of `glsl/common/mass.glsl`).
pub fn energy_momentum(sim: &ParticleSim) -> Result<(f64, [f64; 3])> {
    let x = sim.read_positions()?;
    let v = sim.read_velocities()?;
    let st = sim.statics().read_f32()?;
    Ok(energy_momentum_of(&sim.params().integration, &x, &v, &st))
}

/// [`energy_momentum`] of read-back state (4 floats per texel each), each type's mass range
/// from the integration block `m` (types past the four a scene may have take the last's).
pub fn energy_momentum_of(m: &Integration, x: &[f32], v: &[f32], st: &[f32]) -> (f64, [f64; 3]) {
    let mut e = 0.0;
    let mut p = [0.0; 3];
    for i in 0..x.len() / 4 {
        // Live only (life above 0; NaN is not).
        if x[i * 4 + 3].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        let ty = (st[i * 4 + 1] as usize).min(3);
        let (lo, hi) = (m.mass_lo[ty], m.mass_hi[ty]);
        let f = (4096.0 * st[i * 4 + 3]).fract();
        let m = if lo == hi { lo } else { lo + (hi - lo) * f } as f64;
        let vi = Vec3::new(v[i * 4], v[i * 4 + 1], v[i * 4 + 2]).as_dvec3();
        e += 0.5 * m * vi.length_squared();
        for k in 0..3 {
            p[k] += m * vi[k];
        }
    }
    (e, p)
}
