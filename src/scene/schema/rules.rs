//! Numbers derived from a scene by a rule rather than read from a key: each rule has one home
//! here, and the validation, the passes' parameters, the CPU twins and the reports all ask it.

use super::{Collisions, Emitter, SceneFile};

impl Collisions {
    /// The lattice's mesh size g0 (m): `cell`, else twice the particles' `radius` (the smallest
    /// cell whose 27 neighbours hold every partner closer than 2 radius).
    pub fn cell(&self) -> f32 {
        self.cell.unwrap_or(2.0 * self.radius)
    }

    /// Whether the cell is below 2 radius: the exact detection then walks the cells within 2
    /// radius of a particle (trimmed, as the fluid's search on cells of h) instead of the 27
    /// around its cell.
    pub fn trims(&self) -> bool {
        self.cell() < 2.0 * self.radius
    }
}

impl SceneFile {
    /// The mass range `[lo, hi]` of emitter `e`'s type (Latta §3.3): `mass_range`, else `[m, m]`
    /// with its `mass`, else `particles.mass`. The inverse mass of a particle is
    /// `1 / mix(lo, hi, fract(4096 r))`, `r` the random number of its static texel; its type's
    /// inverse mass is that of the mean, `1 / ((lo + hi) / 2)`.
    pub fn mass_range(&self, e: &Emitter) -> [f32; 2] {
        e.mass_range.unwrap_or_else(|| {
            let m = e.mass.unwrap_or(self.particles.mass);
            [m, m]
        })
    }
}
