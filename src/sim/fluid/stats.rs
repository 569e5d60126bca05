//! Per-frame figures of a fluid (`render --json`): the density error of the last step's density
//! pass and the energy of the state, from one read-back of each.

use glam::Vec3;

use super::Fluid;
use crate::error::Result;
use crate::gl::Texture;

/// A fluid's density error and energy at one frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct FluidStats {
    /// Live particles.
    pub live: u64,
    /// Largest |ρ/ρ0 − 1| (the free surface's particles miss part of their kernel, so their
    /// density is low: this includes that deficit).
    pub max_density_error: f64,
    /// Mean |ρ/ρ0 − 1| over the live particles.
    pub mean_density_error: f64,
    /// Largest compression ρ/ρ0 − 1 (0 if none): what the speed of sound bounds.
    pub max_compression: f64,
    /// Kinetic energy Σ m |v|² / 2 (J).
    pub kinetic: f64,
    /// Potential energy Σ −m g · x (J), zero at the origin.
    pub potential: f64,
    /// `resort = "coherent"`: steps the cheap network sorted, so far.
    pub coherent_resorts: u64,
    /// `resort = "coherent"`: steps that fell back to the full sort, so far.
    pub resort_fallbacks: u64,
    /// `resort = "coherent"`: entries the check found out of order, summed over the steps.
    pub out_of_order: u64,
}

impl Fluid {
    /// The figures of the state `positions`, `velocities` (the textures the last step wrote, in
    /// the cell order of its density pass).
    pub fn stats(&self, positions: &Texture, velocities: &Texture) -> Result<FluidStats> {
        let x = positions.read_f32()?;
        let v = velocities.read_f32()?;
        let rho = self.density.only_texture().read_f32()?;
        let r = self.resort_counts();
        Ok(FluidStats {
            coherent_resorts: r.coherent,
            resort_fallbacks: r.fallbacks,
            out_of_order: r.out_of_order,
            ..fluid_stats(&self.config, self.gravity, &x, &v, &rho)
        })
    }
}

/// The figures of RGBA texel arrays (position, velocity, density) in one order.
pub fn fluid_stats(
    f: &crate::scene::Fluid,
    gravity: Vec3,
    x: &[f32],
    v: &[f32],
    rho: &[f32],
) -> FluidStats {
    let m = f.mass() as f64;
    let rho0 = f.rest_density as f64;
    let mut s = FluidStats::default();
    let mut sum = 0.0;
    for ((p, u), d) in x.chunks(4).zip(v.chunks(4)).zip(rho.chunks(4)) {
        if p[3].is_nan() || p[3] <= 0.0 {
            continue;
        }
        s.live += 1;
        let e = d[0] as f64 / rho0 - 1.0;
        s.max_density_error = s.max_density_error.max(e.abs());
        s.max_compression = s.max_compression.max(e);
        sum += e.abs();
        let speed2: f64 = u[..3].iter().map(|c| (*c as f64).powi(2)).sum();
        s.kinetic += 0.5 * m * speed2;
        let g = gravity.as_dvec3();
        s.potential -= m * (g.x * p[0] as f64 + g.y * p[1] as f64 + g.z * p[2] as f64);
    }
    if s.live > 0 {
        s.mean_density_error = sum / s.live as f64;
    }
    s
}
