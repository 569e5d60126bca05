//! The rounding-free CPU reference of each scheme: what the GPU would compute without rounding,
//! so that the difference between the two is what rounding and storage precision did.

use glam::DVec3;

use super::problem::KEPLER_SOFTENING;
use super::{Problem, G};
use crate::scene::Integrator;

/// `SKIN` of `glsl/sim/colliders.glsl`.
const SKIN: f64 = 1e-4;

/// The rounding-free `f64` twin of `glsl/sim/integrate.frag` for the problems' forces (gravity,
/// damping, a spring to the origin, an attractor of strength 1 at the origin) and a plane y = 0
/// without friction, for one particle of mass 1.
#[derive(Debug, Clone, Copy)]
pub(super) struct Twin {
    pub(super) integrator: Integrator,
    pub(super) dt: f64,
    pub(super) gravity: DVec3,
    pub(super) damping: f64,
    pub(super) spring: f64,
    pub(super) attractor: Option<f64>,
    pub(super) plane: Option<f64>,
}

/// Position and velocity (explicit integrators) or previous position (Verlet).
#[derive(Debug, Clone, Copy)]
pub(super) struct TwinState {
    pub(super) x: DVec3,
    pub(super) v: DVec3,
    pub(super) prev: DVec3,
}

impl Twin {
    fn accel(&self, x: DVec3, v: DVec3) -> DVec3 {
        let mut a = self.gravity - self.damping * v - self.spring * x;
        if let Some(soft) = self.attractor {
            let d = -x;
            let r = d.length();
            if r > 0.0 {
                let q = r * r + soft * soft;
                a += d / (q * q.sqrt());
            }
        }
        a
    }

    pub(super) fn start(&self, x: DVec3, v: DVec3) -> TwinState {
        let dt = self.dt;
        TwinState {
            x,
            v,
            prev: x - v * dt + 0.5 * self.accel(x, v) * dt * dt,
        }
    }

    fn advance(&self, x: DVec3, v: DVec3, vb: DVec3) -> DVec3 {
        match self.integrator {
            Integrator::Euler | Integrator::Verlet => x + vb * self.dt,
            Integrator::Uberflow | Integrator::Heun | Integrator::Rk4 | Integrator::Leapfrog => {
                x + 0.5 * (v + vb) * self.dt
            }
        }
    }

    /// `stages` of `glsl/sim/stages.glsl`: Heun, RK4 or leapfrog. New (x, v).
    fn stages(&self, x: DVec3, v: DVec3) -> (DVec3, DVec3) {
        let h = self.dt;
        let acc = |x: DVec3, v: DVec3| self.accel(x, v);
        match self.integrator {
            Integrator::Heun => {
                let a1 = acc(x, v);
                let (x2, v2) = (x + h * v, v + h * a1);
                (x + 0.5 * h * (v + v2), v + 0.5 * h * (a1 + acc(x2, v2)))
            }
            Integrator::Rk4 => {
                let hh = 0.5 * h;
                let a1 = acc(x, v);
                let v2 = v + hh * a1;
                let a2 = acc(x + hh * v, v2);
                let v3 = v + hh * a2;
                let a3 = acc(x + hh * v2, v3);
                let v4 = v + h * a3;
                let a4 = acc(x + h * v3, v4);
                (
                    x + h / 6.0 * (v + 2.0 * v2 + 2.0 * v3 + v4),
                    v + h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
                )
            }
            // Leapfrog; the single-stage integrators do not reach `stages`.
            Integrator::Leapfrog
            | Integrator::Euler
            | Integrator::Uberflow
            | Integrator::Verlet => {
                let vh = v + 0.5 * h * acc(x, v);
                let xn = x + h * vh;
                (xn, vh + 0.5 * h * acc(xn, vh))
            }
        }
    }

    pub(super) fn step(&self, s: &mut TwinState) {
        let dt = self.dt;
        if self.integrator == Integrator::Verlet {
            let v = (s.x - s.prev) / dt;
            let mut xn = 2.0 * s.x - s.prev + self.accel(s.x, v) * dt * dt;
            if let Some(e) = self.plane {
                if xn.y < 0.0 {
                    // Latta eq. 5 on the implied velocity, restarted from x (colliders.glsl).
                    let mut vi = (xn - s.x) / dt;
                    if vi.y < 0.0 {
                        vi.y *= -e;
                    }
                    xn = s.x + vi * dt;
                }
                if xn.y < 0.0 {
                    xn.y = SKIN;
                }
            }
            s.prev = s.x;
            s.x = xn;
            return;
        }
        let mut x = s.x;
        let v = s.v;
        let (mut xb, mut vb) = if self.integrator.multistage() {
            self.stages(x, v)
        } else {
            let vb = v + self.accel(x, v) * dt;
            (self.advance(x, v, vb), vb)
        };
        if let Some(e) = self.plane {
            if xb.y < 0.0 {
                if x.y < 0.0 {
                    x.y = SKIN;
                    vb.y = vb.y.abs();
                } else if vb.y < 0.0 {
                    vb.y *= -e;
                }
                xb = self.advance(x, v, vb);
            }
            if xb.y < 0.0 {
                xb.y = SKIN;
                vb.y = vb.y.max(0.0);
            }
        }
        s.x = xb;
        s.v = vb;
    }
}

/// A sample of the twin taken as the GPU's is: for Verlet the velocity by the central difference,
/// with one extra step.
pub(super) fn twin_sample(t: &Twin, s: &mut TwinState) -> (DVec3, DVec3) {
    if t.integrator != Integrator::Verlet {
        return (s.x, s.v);
    }
    let (x, prev) = (s.x, s.prev);
    t.step(s);
    (x, (s.x - prev) / (2.0 * t.dt))
}

impl Problem {
    /// The rounding-free twin of the scheme for this problem.
    pub(super) fn twin(&self, integrator: Integrator, dt: f64) -> Twin {
        let mut t = Twin {
            integrator,
            dt,
            gravity: DVec3::ZERO,
            damping: 0.0,
            spring: 0.0,
            attractor: None,
            plane: None,
        };
        match *self {
            Problem::Drag { drag, .. } => {
                t.gravity = DVec3::new(0.0, -G, 0.0);
                t.damping = drag;
            }
            Problem::Oscillator { omega, .. } => t.spring = omega * omega,
            Problem::Kepler { .. } => t.attractor = Some(KEPLER_SOFTENING),
            Problem::Bounce { resilience, .. } => {
                t.gravity = DVec3::new(0.0, -G, 0.0);
                t.plane = Some(resilience);
            }
        }
        t
    }
}
