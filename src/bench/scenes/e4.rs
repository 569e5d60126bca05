//! E4, UberFlow's inter-particle collisions (§5), in the regime the paper describes: "particles
//! released in time-sequential order ... holding in the same row all particles that are released
//! in one time step ... as long as these sets do not mix up entirely, the number of missed
//! collisions will be small".
//!
//! Each step releases a run of rows of the state texture (one row at 256²), split into compact
//! clouds of [`CLOUD`] spheres, each in a place of its own (`release_spread`, `release_cloud`),
//! with small random velocities, so its particles collide among themselves and not with other
//! releases. A cycle is 256 steps at every size. The density is held as the state grows: a
//! cloud is the same at every size, and the region the clouds land in grows with the particle
//! count (its side ∝ N^(1/3)), up to the largest lattice whose cell keys stay exact.
//! Collisions as the paper runs E4: rows-only sort, 8 neighbours to each side, and the staggered
//! lattice.

use crate::error::Result;
use crate::scene::{parse, SceneFile, MAX_LATTICE_CELLS};

/// Sphere radius (m).
pub const RADIUS: f32 = 0.01;
/// Lattice cell: four radii, so that a cell holds a few particles and most overlapping pairs
/// share a cell on one of the two lattices (UberFlow §4.4's "cell size small enough").
pub const CELL: f32 = 4.0 * RADIUS;
/// Volume fraction of spheres inside a fresh cloud.
pub const PACKING: f32 = 0.1;
/// Damping rate (1/s): a cloud's random velocities die out within its life, so clouds stay
/// apart.
pub const DAMPING: f32 = 2.0;
/// Side of the region the releases land in at 256² (m); it grows with N^(1/3).
pub const SPREAD_256: f32 = 3.8;
/// Steps per frame and step length (s).
const SUBSTEPS: u32 = 2;
const DT: f32 = 0.005;
/// Steps of an emission cycle (every particle's life): the same at every size, so that the
/// clouds' ages, and with them their spread and overlaps, are the same at every size.
const CYCLE_STEPS: u32 = 256;

/// Particles of a cloud: a release (one row) is split into clouds of this many consecutive
/// texels, each in its own place, so that a cloud looks the same at every row width.
pub const CLOUD: u32 = 64;

/// Radius of a fresh cloud of `n` spheres at [`PACKING`].
pub fn release_radius(n: u32) -> f32 {
    RADIUS * (n as f32 / PACKING).cbrt()
}

/// Side of the region releases land in at size × size particles: ∝ N^(1/3) from [`SPREAD_256`],
/// capped so that the lattice over it stays within the exact float keys.
pub fn spread(size: u32) -> f32 {
    let held = SPREAD_256 * (size as f32 / 256.0).powf(2.0 / 3.0);
    let cap = (MAX_LATTICE_CELLS as f32).cbrt() * CELL - 2.0 * release_radius(CLOUD) - 4.0 * CELL;
    held.min(cap)
}

/// E4's scene at size × size particles.
pub fn scene(size: u32) -> Result<SceneFile> {
    let cycle = CYCLE_STEPS.min(size) as f32 * DT;
    let r0 = release_radius(CLOUD.min(size));
    let l = spread(size);
    let half = 0.5 * l + r0 + 2.0 * CELL;
    let text = format!(
        r#"name = "e4"
integrator = "euler"

[particles]
size = [{size}, {size}]

[time]
dt = {DT}
substeps = {SUBSTEPS}

[[emitters.timestamp]]
cycle = {cycle}
shape = "sphere"
center = [0.0, 0.0, 0.0]
radius = {r0}
direction = [0.0, 1.0, 0.0]
cone_degrees = 180.0
speed = [0.0, 0.05]
life = [{cycle}, {cycle}]
release_spread = [{l}, {l}, {l}]
release_cloud = {cloud}

[[forces.damping]]
rate = {DAMPING}

[collisions]
radius = {RADIUS}
restitution = 0.3
neighbours = 8
cell = {CELL}
bounds = [[-{half}, -{half}, -{half}], [{half}, {half}, {half}]]
staggered = true
rows_only = 1

[render]
resolution = [512, 512]
point_size = 1.0
intensity = 0.5
camera = {{ target = [0.0, 0.0, 0.0], distance = {dist}, azimuth = 30.0, elevation = 20.0 }}
"#,
        dist = 1.8 * l,
        cloud = CLOUD.min(size)
    );
    parse("E4 (built in)", &text)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn density_is_held_and_the_lattice_fits() {
        // Particles per volume of the region: N / L^3, the same at every size Table 2 runs.
        let density = |n: u32| (n as f64 * n as f64) / (spread(n) as f64).powi(3);
        let d256 = density(256);
        for n in [64, 128, 256, 512, 1024] {
            let s = scene(n).unwrap();
            let c = s.collisions.as_ref().unwrap();
            let cells = ((c.bounds[1][0] - c.bounds[0][0]) / CELL).ceil() as u64;
            assert!(cells.pow(3) <= MAX_LATTICE_CELLS, "{n}: {cells}^3 cells");
            assert_eq!(c.rows_only, Some(1));
            if n >= 256 {
                let ratio = density(n) / d256;
                assert!((0.99..1.01).contains(&ratio), "{n}: density ×{ratio}");
            }
        }
    }
}
