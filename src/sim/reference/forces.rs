//! Forces of the twin: `glsl/sim/forces.glsl`.

use glam::Vec3;

use super::Reference;

impl Reference {
    /// `acceleration(x, v, type)` of `glsl/sim/forces.glsl`: the accelerations (gravity,
    /// damping, wind) plus the forces (attractors, vortices) times the inverse mass of type
    /// `ty` (0 to 3).
    pub fn acceleration(&self, x: Vec3, v: Vec3, ty: usize) -> Vec3 {
        let mut a = Vec3::ZERO;
        let mut f = Vec3::ZERO;
        if let Some(g) = self.gravity {
            a += g;
        }
        if let Some(c) = self.damping {
            a -= c * v;
        }
        if let Some(w) = &self.wind {
            a += w.drag * (w.field.sample(x) - v);
        }
        for at in &self.attractors {
            let d = at.at.truncate() - x;
            let r = d.length();
            let s = at.shape;
            if r > 0.0 && (s.y < 0.0 || r <= s.y) {
                if s.x > 0.5 {
                    f += at.at.w * (d / r);
                } else {
                    let q = r * r + s.z * s.z;
                    f += at.at.w * d / (q * q.sqrt());
                }
            }
        }
        for vx in &self.vortices {
            let rel = x - vx.at.truncate();
            let ax = vx.axis;
            let perp = rel - rel.dot(ax) * ax;
            let core = perp.length().max(0.1);
            f += vx.at.w * ax.cross(perp) / (core * core);
        }
        a + f * self.inv_mass[ty]
    }

    /// Verlet's second-order start (`glsl/sim/verlet_start.frag`, what `ParticleSim::set_state`
    /// draws): `x_prev = x - v dt + a(x, v) dt^2 / 2` for a live particle.
    pub fn verlet_start(&self, x: Vec3, v: Vec3, ty: usize) -> Vec3 {
        let a = self.acceleration(x, v, ty);
        let dt = self.dt;
        self.store(x - v * dt + 0.5 * a * dt * dt)
    }
}
