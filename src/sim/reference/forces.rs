//! Forces of the twin: `glsl/sim/forces.glsl`.

use glam::Vec3;

use super::Reference;
use crate::scene::{ForceKind, WindForm};
use crate::sim::params;

impl Reference {
    /// `acceleration(x, v, type)` of `glsl/sim/forces.glsl`: the accelerations (gravity,
    /// damping, wind) plus the forces (attractors, springs, vortices) times the inverse mass of type
    /// `ty` (0 to 3).
    pub fn acceleration(&self, x: Vec3, v: Vec3, ty: usize) -> Vec3 {
        self.acceleration_of(x, v, self.inv_mass[ty])
    }

    /// `particle_inv_mass(type, r)`: the inverse mass of a particle of type `ty` whose static
    /// texel holds the random number `r`: `1 / mix(lo, hi, fract(4096 r))` with a mass range
    /// (Latta §3.3), else the type's.
    pub fn particle_inv_mass(&self, ty: usize, r: f32) -> f32 {
        match &self.mass_range {
            Some((lo, hi)) => {
                let t = (4096.0 * r).fract();
                1.0 / (lo[ty] * (1.0 - t) + hi[ty] * t)
            }
            None => self.inv_mass[ty],
        }
    }

    /// `wind_kick(x)`: UberFlow eq. 1's wind velocity, added to the velocity in each step with
    /// `form = "uberflow"`; zero otherwise.
    pub fn wind_kick(&self, x: Vec3) -> Vec3 {
        match &self.wind {
            Some(w) if w.form == WindForm::Uberflow => w.field.sample(x),
            _ => Vec3::ZERO,
        }
    }

    /// `acceleration(x, v, inv_mass)`: [`Reference::acceleration`] with a given inverse mass.
    /// Kind by kind in the shader's order, so the sums round as the GPU's do.
    pub fn acceleration_of(&self, x: Vec3, v: Vec3, inv_mass: f32) -> Vec3 {
        let mut a = Vec3::ZERO;
        let mut f = Vec3::ZERO;
        for kind in ForceKind::ALL {
            match kind {
                ForceKind::Gravity => {
                    if let Some(g) = self.gravity {
                        a += g;
                    }
                }
                ForceKind::Damping => {
                    if let Some(c) = self.damping {
                        a -= c * v;
                    }
                }
                ForceKind::Wind => {
                    if let Some(w) = &self.wind {
                        match w.form {
                            WindForm::Drag => a += w.drag * (w.field.sample(x) - v),
                            WindForm::Latta => f += w.drag * (w.field.sample(x) - v),
                            WindForm::Uberflow => {}
                        }
                    }
                }
                ForceKind::Attractor => {
                    for at in &self.attractors {
                        f += point_force(at.at.truncate() - x, at.at.w, at.shape.truncate());
                    }
                }
                ForceKind::Spring => {
                    for sp in &self.springs {
                        f -= sp.at.w * (x - sp.at.truncate());
                    }
                }
                ForceKind::Vortex => {
                    for vx in &self.vortices {
                        f += vortex_force(vx, x);
                    }
                }
                // GLSL the twin does not run: `Reference::new` refuses them.
                ForceKind::Custom | ForceKind::Pair => {}
            }
        }
        a + f * inv_mass
    }

    /// Verlet's second-order start (`glsl/sim/verlet_start.frag`, what `ParticleSim::set_state`
    /// draws): `x_prev = x - v dt + a(x, v) dt^2 / 2` for a live particle.
    pub fn verlet_start(&self, x: Vec3, v: Vec3, ty: usize) -> Vec3 {
        let a = self.acceleration_of(x, v, self.particle_inv_mass(ty, self.random));
        let dt = self.dt;
        self.store(x - v * dt + 0.5 * a * dt * dt)
    }
}

/// A vortex's force on a particle at `x` (the `N_VORTICES` loop of `glsl/sim/forces.glsl`).
fn vortex_force(vx: &params::Vortex, x: Vec3) -> Vec3 {
    let rel = x - vx.at.truncate();
    let ax = vx.axis;
    let perp = rel - rel.dot(ax) * ax;
    let vs = vx.shape;
    if vs.x > 0.5 {
        point_force(-perp, vx.at.w, Vec3::new(vs.y, vs.z, vs.w))
    } else {
        let core = perp.length().max(0.1);
        vx.at.w * ax.cross(perp) / (core * core)
    }
}

/// `point_force(d, strength, shape)`: a force towards `d` with an attractor's falloff; `shape`
/// = (constant falloff 0/1, max distance < 0 for none, softening).
fn point_force(d: Vec3, strength: f32, shape: Vec3) -> Vec3 {
    let r = d.length();
    if r > 0.0 && (shape.y < 0.0 || r <= shape.y) {
        if shape.x > 0.5 {
            return strength * (d / r);
        }
        let q = r * r + shape.z * shape.z;
        return strength * d / (q * q.sqrt());
    }
    Vec3::ZERO
}
