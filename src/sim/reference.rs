//! A CPU twin of the integration pass (`glsl/sim/integrate.frag` with `glsl/sim/forces.glsl` and
//! `glsl/sim/colliders.glsl`): one time step of one particle, in `f32`, with the same operations
//! in the same order as the GLSL.
//!
//! # Why it exists
//!
//! The GPU pass is the thing the project is about, and it cannot be stepped through or printed.
//! This twin lets tests (tests/forces_colliders.rs) put particles exactly where a branch of the
//! shader fires (a particle hitting a sphere during the step, one caught inside a box, one slower
//! than `slow_speed`, one crossing the height field) and check the GPU's result against an
//! independent, readable evaluation of the same formulas. Both sides do the same `f32`
//! arithmetic, so they agree up to rounding (the GPU may fuse multiply-adds, divide through a
//! reciprocal and normalise with a reciprocal square root): any difference beyond a few ulps per
//! operation is a bug on one side.
//!
//! # What it covers
//!
//! - Integrators: Latta's Euler (eq. 3, 8), UberFlow's velocity-averaged update (eq. 1-2) and
//!   Verlet (Latta eq. 9), plus Verlet's second-order start (`glsl/sim/verlet_start.frag`).
//! - Forces: gravity, damping, wind (Stokes drag towards [`FlowField::sample`]), attractors
//!   (inverse square with softening, or constant; `max_distance`), vortices, per-type inverse
//!   mass.
//! - Colliders: planes, spheres, boxes, the height field ([`HeightField::sample`]) and the
//!   distance field ([`DistanceField::sample`], [`DistanceField::normal`]), with Latta's response
//!   (eq. 4-5), the slow-speed threshold, the push-out of caught particles (eq. 7), UberFlow's
//!   crossing point on the height field (§4.6), Verlet's position constraints and the final
//!   `keep_outside` projection.
//! - Life: `LIFE` scenes (allocator emission, or initial emitters with a life) count the
//!   remaining life down and move the dead to `+inf`; permanent particles keep their `w`.
//! - `fp24` scenes: what the pass writes is rounded with [`crate::sort::precision::R300`], the
//!   twin of `fp_store`.
//!
//! Not covered (rejected by [`Reference::new`]): time-stamp emission (the respawn needs the
//! shader's random streams), `rgba16f` velocities (the driver's rounding to half floats is not
//! specified), and the fire scene.
//!
//! Keep this file in step with the GLSL: a change to one without the other fails
//! tests/forces_colliders.rs.

use glam::{Vec2, Vec3, Vec4};

use super::fields::{DistanceField, FlowField, HeightField};
use super::particles::{Emission, Features};
use crate::error::{Error, Result};
use crate::scene::{self, Integrator, Precision, SceneFile, VelocityFormat};

/// `SKIN` in `glsl/sim/colliders.glsl`: how far above a surface a particle is put back.
pub const SKIN: f32 = 1e-4;

/// The branches one step took (for tests that must show that a placement exercises the branch
/// it was meant for).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Events {
    /// Latta eq. 4-5 responses applied (explicit) or position constraints applied (Verlet).
    pub hits: u32,
    /// Of those, responses or constraints without friction because the particle was slow.
    pub slow: u32,
    /// Particles already inside at the start of the step, pushed out (Latta eq. 7).
    pub caught: u32,
    /// Height-field crossings (UberFlow §4.6): back to the crossing point, then the rest of the
    /// step.
    pub crossings: u32,
    /// Projections by the final `keep_outside`.
    pub kept_outside: u32,
    /// The particle died in this step (or was dead already).
    pub dead: bool,
}

impl std::ops::AddAssign for Events {
    /// Sums the counters of several steps or particles (`dead`: any).
    fn add_assign(&mut self, o: Events) {
        self.hits += o.hits;
        self.slow += o.slow;
        self.caught += o.caught;
        self.crossings += o.crossings;
        self.kept_outside += o.kept_outside;
        self.dead |= o.dead;
    }
}

#[derive(Debug, Clone)]
struct Attractor {
    /// centre, strength: `u_attractor[i]`.
    at: Vec4,
    /// constant falloff (0/1), max distance (< 0: none), softening: `u_attractor_shape[i]`.
    shape: Vec4,
}

#[derive(Debug, Clone)]
struct Vortex {
    /// point on the axis, strength: `u_vortex[i]`.
    at: Vec4,
    /// unit axis: `u_vortex_axis[i]`.
    axis: Vec3,
}

#[derive(Debug, Clone)]
struct Wind {
    field: FlowField,
    drag: f32,
}

/// A collider's shape, with the uniforms the shader gets.
#[derive(Debug, Clone)]
enum Shape {
    /// unit normal, offset: `u_plane[i]`.
    Plane(Vec4),
    /// centre, radius: `u_sphere[i]`.
    Sphere(Vec4),
    /// `u_box_min[i]`, `u_box_max[i]`.
    Box(Vec3, Vec3),
    /// `u_sdf_min`, `u_sdf_max` and the field.
    Sdf(Vec3, Vec3, Box<DistanceField>),
}

#[derive(Debug, Clone)]
struct Collider {
    shape: Shape,
    /// friction, resilience.
    resp: Vec2,
}

/// One integration step of one particle on the CPU, the twin of `glsl/sim/integrate.frag` for a
/// scene (see the module documentation).
#[derive(Debug, Clone)]
pub struct Reference {
    integrator: Integrator,
    life: bool,
    fp24: bool,
    dt: f32,
    inv_mass: [f32; 4],
    gravity: Option<Vec3>,
    damping: Option<f32>,
    wind: Option<Wind>,
    attractors: Vec<Attractor>,
    vortices: Vec<Vortex>,
    slow_speed: f32,
    /// Planes, spheres, boxes, then the distance field: the order of `collide`.
    colliders: Vec<Collider>,
    height: Option<(HeightField, Vec2)>,
}

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from(a)
}

impl Reference {
    /// The twin of the integration pass that `ParticleSim::new` compiles for `scene`, with the
    /// uniform values that `ParticleSim::set_constants` computes, computed the same way.
    pub fn new(scene: &SceneFile) -> Result<Self> {
        if scene.fire.is_some() {
            return Err(Error::InvalidInput(format!(
                "scene `{}` is the thesis's fire: the reference covers the particle system",
                scene.name
            )));
        }
        scene
            .validate()
            .map_err(|e| Error::InvalidInput(e.message))?;
        let features = Features::of(scene);
        if features.emission == Emission::Timestamp {
            return Err(Error::InvalidInput(format!(
                "scene `{}`: the reference does not cover time-stamp emission",
                scene.name
            )));
        }
        if scene.particles.velocity_format == VelocityFormat::Rgba16f
            && scene.integrator != Integrator::Verlet
        {
            return Err(Error::InvalidInput(format!(
                "scene `{}`: the reference models rgba32f velocities only",
                scene.name
            )));
        }
        let s = scene;
        let mut inv_mass = [1.0 / s.particles.mass; 4];
        for (k, e) in s.emitters.all().enumerate() {
            inv_mass[k] = 1.0 / e.mass.unwrap_or(s.particles.mass);
        }
        let f = &s.forces;
        let gravity = (!f.gravity.is_empty())
            .then(|| f.gravity.iter().map(|g| v3(g.acceleration)).sum::<Vec3>());
        let damping = (!f.damping.is_empty()).then(|| f.damping.iter().map(|d| d.rate).sum());
        let wind = match f.wind.first() {
            Some(w) => Some(Wind {
                field: FlowField::new(w)?,
                drag: w.drag,
            }),
            None => None,
        };
        let attractors = f
            .attractor
            .iter()
            .map(|a| Attractor {
                at: v3(a.position).extend(a.strength),
                shape: Vec4::new(
                    (a.falloff == scene::Falloff::Constant) as u8 as f32,
                    a.max_distance.unwrap_or(-1.0),
                    a.softening,
                    0.0,
                ),
            })
            .collect();
        let vortices = f
            .vortex
            .iter()
            .map(|v| Vortex {
                at: v3(v.point).extend(v.strength),
                axis: v3(v.axis).normalize(),
            })
            .collect();
        let c = &s.colliders;
        let resp = |mu: f32, eps: f32| Vec2::new(mu, eps);
        let mut colliders = Vec::new();
        for pl in &c.plane {
            let n = v3(pl.normal).normalize();
            colliders.push(Collider {
                shape: Shape::Plane(n.extend(n.dot(v3(pl.point)))),
                resp: resp(pl.friction, pl.resilience),
            });
        }
        for sp in &c.sphere {
            colliders.push(Collider {
                shape: Shape::Sphere(v3(sp.center).extend(sp.radius)),
                resp: resp(sp.friction, sp.resilience),
            });
        }
        for b in &c.boxes {
            colliders.push(Collider {
                shape: Shape::Box(v3(b.min), v3(b.max)),
                resp: resp(b.friction, b.resilience),
            });
        }
        if let Some(d) = c.sdf.first() {
            colliders.push(Collider {
                shape: Shape::Sdf(
                    v3(d.bounds[0]),
                    v3(d.bounds[1]),
                    Box::new(DistanceField::new(d)?),
                ),
                resp: resp(d.friction, d.resilience),
            });
        }
        let height = match c.heightfield.first() {
            Some(h) => Some((HeightField::new(h)?, resp(h.friction, h.resilience))),
            None => None,
        };
        Ok(Reference {
            integrator: s.integrator,
            life: features.life(),
            fp24: s.particles.precision == Precision::Fp24,
            dt: s.time.dt,
            inv_mass,
            gravity,
            damping,
            wind,
            attractors,
            vortices,
            slow_speed: c.slow_speed,
            colliders,
            height,
        })
    }

    /// The time step.
    pub fn dt(&self) -> f32 {
        self.dt
    }

    /// The scene's integrator.
    pub fn integrator(&self) -> Integrator {
        self.integrator
    }

    /// Whether the pass counts life down (`LIFE`).
    pub fn has_life(&self) -> bool {
        self.life
    }

    /// Whether the scene has any collider (`HAS_COLLIDERS`).
    pub fn has_colliders(&self) -> bool {
        !self.colliders.is_empty() || self.height.is_some()
    }

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

    /// One step of an explicit integrator (Euler or UberFlow): position, velocity and remaining
    /// life as the pass writes them. Panics for a Verlet scene.
    pub fn step_explicit(&self, x: Vec3, v: Vec3, life: f32, ty: usize) -> (Vec3, Vec3, f32) {
        let (x, v, life, _) = self.step_explicit_events(x, v, life, ty);
        (x, v, life)
    }

    /// [`Reference::step_explicit`], also telling which branches the step took.
    pub fn step_explicit_events(
        &self,
        x: Vec3,
        v: Vec3,
        life: f32,
        ty: usize,
    ) -> (Vec3, Vec3, f32, Events) {
        assert!(
            self.integrator != Integrator::Verlet,
            "step_explicit on a Verlet scene: use step_verlet"
        );
        let mut ev = Events::default();
        let mut x = x;
        let life = match self.life(life) {
            Ok(l) => l,
            Err(l) => {
                ev.dead = true;
                return (self.store(Vec3::INFINITY), self.store(Vec3::ZERO), l, ev);
            }
        };
        let a = self.acceleration(x, v, ty);
        let mut vb = v + a * self.dt;
        let mut xb = self.advance(x, v, vb);
        if self.has_colliders() {
            self.collide_explicit(&mut x, v, &mut vb, &mut xb, &mut ev);
            self.keep_outside(&mut xb, &mut vb, &mut ev);
        }
        (self.store(xb), self.store(vb), self.store1(life), ev)
    }

    /// One Verlet step: the new position and remaining life, from the current position `x` and
    /// the previous one `x_prev`. Panics for a scene with an explicit integrator.
    pub fn step_verlet(&self, x: Vec3, x_prev: Vec3, life: f32, ty: usize) -> (Vec3, f32) {
        let (x, life, _) = self.step_verlet_events(x, x_prev, life, ty);
        (x, life)
    }

    /// [`Reference::step_verlet`], also telling which branches the step took.
    pub fn step_verlet_events(
        &self,
        x: Vec3,
        x_prev: Vec3,
        life: f32,
        ty: usize,
    ) -> (Vec3, f32, Events) {
        assert!(
            self.integrator == Integrator::Verlet,
            "step_verlet on a scene with an explicit integrator: use step_explicit"
        );
        let mut ev = Events::default();
        let dt = self.dt;
        let v = (x - x_prev) / dt;
        let life = match self.life(life) {
            Ok(l) => l,
            Err(l) => {
                ev.dead = true;
                return (self.store(Vec3::INFINITY), l, ev);
            }
        };
        let a = self.acceleration(x, v, ty);
        let mut xn = 2.0 * x - x_prev + a * (dt * dt);
        if self.has_colliders() {
            self.collide_verlet(x, &mut xn, &mut ev);
            let mut vn = (xn - x) / dt;
            self.keep_outside(&mut xn, &mut vn, &mut ev);
        }
        (self.store(xn), self.store1(life), ev)
    }

    /// The `LIFE` block of `main`: `Ok(remaining life)` for a particle that lives on, `Err(w)`
    /// with the `w` the pass writes for one that is (or just became) dead. Without `LIFE` the
    /// life passes through.
    // `!(w > 0.0)` as in the shader: a NaN life counts as dead.
    #[allow(clippy::neg_cmp_op_on_partial_ord)]
    fn life(&self, w: f32) -> std::result::Result<f32, f32> {
        if !self.life {
            return Ok(w);
        }
        if !(w > 0.0) {
            return Err(w);
        }
        let life = w - self.dt;
        if life <= 0.0 {
            return Err(0.0);
        }
        Ok(life)
    }

    /// `advance(x, v, vb)`.
    fn advance(&self, x: Vec3, v: Vec3, vb: Vec3) -> Vec3 {
        match self.integrator {
            Integrator::Uberflow => x + 0.5 * (v + vb) * self.dt,
            _ => x + vb * self.dt,
        }
    }

    /// `fp_store` on three channels.
    fn store(&self, v: Vec3) -> Vec3 {
        Vec3::new(self.store1(v.x), self.store1(v.y), self.store1(v.z))
    }

    fn store1(&self, x: f32) -> f32 {
        if self.fp24 {
            crate::sort::precision::R300.round(x)
        } else {
            x
        }
    }

    /// Signed distance and outward normal of `p` to a collider other than the height field:
    /// `plane_distance`, `sphere_distance`, `box_distance`, `sdf_distance`.
    fn distance(shape: &Shape, p: Vec3) -> (f32, Vec3) {
        match shape {
            Shape::Plane(pl) => {
                let n = pl.truncate();
                (n.dot(p) - pl.w, n)
            }
            Shape::Sphere(s) => {
                let d = p - s.truncate();
                let r = d.length();
                let n = if r > 0.0 { d / r } else { Vec3::Y };
                (r - s.w, n)
            }
            Shape::Box(lo, hi) => box_distance(*lo, *hi, p),
            Shape::Sdf(lo, hi, field) => {
                if p.cmplt(*lo).any() || p.cmpgt(*hi).any() {
                    return (1e30, Vec3::Y);
                }
                let n = field.normal(p);
                (field.sample(p), n)
            }
        }
    }

    /// `height_distance`: vertical distance to the landscape and its normal there.
    fn height_distance(field: &HeightField, p: Vec3) -> (f32, Vec3) {
        let (h, n) = field.sample(p.x, p.z);
        (p.y - h, n)
    }

    /// `collision_response`: Latta eq. 4-5 with the slow-speed threshold.
    fn response(&self, v: Vec3, n: Vec3, resp: Vec2, ev: &mut Events) -> Vec3 {
        let vn = v.dot(n);
        if vn >= 0.0 {
            return v;
        }
        ev.hits += 1;
        let v_n = vn * n;
        let v_t = v - v_n;
        let mu = if v.length() < self.slow_speed {
            ev.slow += 1;
            0.0
        } else {
            resp.x
        };
        (1.0 - mu) * v_t - resp.y * v_n
    }

    /// `collide` for the explicit integrators, then nothing else: `keep_outside` follows.
    fn collide_explicit(
        &self,
        x: &mut Vec3,
        v: Vec3,
        vb: &mut Vec3,
        xb: &mut Vec3,
        ev: &mut Events,
    ) {
        for c in &self.colliders {
            let (d0, n0) = Self::distance(&c.shape, *x);
            let (d1, n1) = Self::distance(&c.shape, *xb);
            // collide_explicit
            if d1 >= 0.0 {
                continue;
            }
            if d0 < 0.0 {
                *x -= (d0 - SKIN) * n0;
                *vb = caught_response(*vb, n0);
                ev.caught += 1;
            } else {
                *vb = self.response(*vb, n1, c.resp, ev);
            }
            *xb = self.advance(*x, v, *vb);
        }
        if let Some((field, resp)) = &self.height {
            let (d1, _) = Self::height_distance(field, *xb);
            if d1 < 0.0 {
                let (d0, n0) = Self::height_distance(field, *x);
                if d0 < 0.0 {
                    x.y -= d0 - SKIN;
                    *vb = caught_response(*vb, n0);
                    *xb = self.advance(*x, v, *vb);
                    ev.caught += 1;
                } else {
                    let s = d0 / (d0 - d1);
                    let xc = mix(*x, *xb, s);
                    let (_, nc) = Self::height_distance(field, xc);
                    *vb = self.response(*vb, nc, *resp, ev);
                    *xb = xc + *vb * ((1.0 - s) * self.dt);
                    ev.crossings += 1;
                }
            }
        }
    }

    /// `constrain`: Verlet's position constraint for one collider.
    fn constrain(&self, d: f32, n: Vec3, resp: Vec2, x: Vec3, xn: &mut Vec3, ev: &mut Events) {
        if d >= 0.0 {
            return;
        }
        ev.hits += 1;
        let slow = (*xn - x).length() < self.slow_speed * self.dt;
        *xn -= (1.0 + resp.y) * d * n;
        let disp = *xn - x;
        let disp_n = disp.dot(n) * n;
        if slow {
            ev.slow += 1;
        } else {
            *xn = x + disp_n + (1.0 - resp.x) * (disp - disp_n);
        }
    }

    /// `collide` for Verlet.
    fn collide_verlet(&self, x: Vec3, xn: &mut Vec3, ev: &mut Events) {
        for c in &self.colliders {
            let (d, n) = Self::distance(&c.shape, *xn);
            self.constrain(d, n, c.resp, x, xn, ev);
        }
        if let Some((field, resp)) = &self.height {
            let (d, n) = Self::height_distance(field, *xn);
            // Vertical distance to distance along the normal.
            self.constrain(d * n.y, n, *resp, x, xn, ev);
        }
    }

    /// `keep_outside`: projects a position still inside a collider out to `SKIN` above its
    /// surface and takes away the velocity into the surface.
    fn keep_outside(&self, x: &mut Vec3, v: &mut Vec3, ev: &mut Events) {
        // Up to KEEP_OUTSIDE_SWEEPS sweeps: one collider's push-out can move a particle into
        // another (a sphere sunk into a plane); stop after a sweep that moves nothing.
        for _ in 0..KEEP_OUTSIDE_SWEEPS {
            let mut moved = false;
            for c in &self.colliders {
                let (d, n) = Self::distance(&c.shape, *x);
                if d < 0.0 {
                    *x -= (d - SKIN) * n;
                    *v -= v.dot(n).min(0.0) * n;
                    ev.kept_outside += 1;
                    moved = true;
                }
            }
            if let Some((field, _)) = &self.height {
                let (d, n) = Self::height_distance(field, *x);
                if d < 0.0 {
                    x.y -= d - SKIN;
                    *v -= v.dot(n).min(0.0) * n;
                    ev.kept_outside += 1;
                    moved = true;
                }
            }
            if !moved {
                break;
            }
        }
    }

    /// The least signed distance of `p` to the scene's colliders (the height field's vertical
    /// one), `+inf` without colliders: for tests that place particles inside, near or far.
    pub fn distance_to_colliders(&self, p: Vec3) -> f32 {
        let mut d = f32::INFINITY;
        for c in &self.colliders {
            d = d.min(Self::distance(&c.shape, p).0);
        }
        if let Some((field, _)) = &self.height {
            d = d.min(Self::height_distance(field, p).0);
        }
        d
    }
}

/// Sweeps of `keep_outside` over all colliders (`KEEP_OUTSIDE_SWEEPS` in colliders.glsl).
const KEEP_OUTSIDE_SWEEPS: usize = 4;

/// `caught_response`: Latta eq. 7, the way out of a collider a particle is caught in.
fn caught_response(v: Vec3, n: Vec3) -> Vec3 {
    let vn = v.dot(n);
    if vn < 0.0 {
        v - 2.0 * vn * n
    } else {
        v
    }
}

/// GLSL's `mix(x, y, a) = x (1 - a) + y a`.
fn mix(x: Vec3, y: Vec3, a: f32) -> Vec3 {
    x * (1.0 - a) + y * a
}

/// `box_distance`: exact distance outside a solid axis-aligned box; inside, the distance to the
/// nearest face (negative).
fn box_distance(lo: Vec3, hi: Vec3, p: Vec3) -> (f32, Vec3) {
    let c = 0.5 * (lo + hi);
    let h = 0.5 * (hi - lo);
    let rel = p - c;
    let q = rel.abs() - h;
    let sign = |r: f32| if r < 0.0 { -1.0 } else { 1.0 };
    let s = Vec3::new(sign(rel.x), sign(rel.y), sign(rel.z));
    if q.x.max(q.y.max(q.z)) > 0.0 {
        let o = q.max(Vec3::ZERO);
        let d = o.length();
        return (d, s * o / d);
    }
    if q.x >= q.y && q.x >= q.z {
        return (q.x, Vec3::new(s.x, 0.0, 0.0));
    }
    if q.y >= q.z {
        return (q.y, Vec3::new(0.0, s.y, 0.0));
    }
    (q.z, Vec3::new(0.0, 0.0, s.z))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::parse;

    const HEAD: &str = r#"
name = "reference"
[particles]
size = [2, 2]
[time]
dt = 0.125
[[emitters.initial]]
shape = "point"
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
"#;

    fn scene(integrator: &str, rest: &str) -> Reference {
        let src = format!("integrator = \"{integrator}\"\n{HEAD}{rest}");
        Reference::new(&parse("test", &src).unwrap()).unwrap()
    }

    #[test]
    fn reference_euler_and_uberflow_under_gravity_are_exact_on_dyadic_numbers() {
        // dt = 1/8 and g = -8: every product is exact, so the formulas give the exact values.
        let g = "[[forces.gravity]]\nacceleration = [0.0, -8.0, 0.0]\n";
        let x = Vec3::new(1.0, 2.0, 3.0);
        let v = Vec3::new(0.5, 1.0, 0.0);
        let (xe, ve, _) = scene("euler", g).step_explicit(x, v, 1.0, 0);
        assert_eq!(ve, Vec3::new(0.5, 0.0, 0.0));
        assert_eq!(xe, x + ve * 0.125);
        let (xu, vu, _) = scene("uberflow", g).step_explicit(x, v, 1.0, 0);
        assert_eq!(vu, ve);
        assert_eq!(xu, Vec3::new(1.0625, 2.0625, 3.0));
        // Verlet from its second-order start reproduces x + v dt + a dt^2 / 2.
        let r = scene("verlet", g);
        let xp = r.verlet_start(x, v, 0);
        let (xv, _) = r.step_verlet(x, xp, 1.0, 0);
        assert_eq!(xv, Vec3::new(1.0625, 2.0625, 3.0));
    }

    #[test]
    fn reference_life_counts_down_and_kills() {
        let src = format!(
            "integrator = \"euler\"\n{}\nlife = [1.0, 1.0]\n",
            HEAD.trim_end()
        );
        let r = Reference::new(&parse("test", &src).unwrap()).unwrap();
        assert!(r.has_life());
        let (_, _, l) = r.step_explicit(Vec3::ZERO, Vec3::ZERO, 0.5, 0);
        assert_eq!(l, 0.375);
        let (x, v, l, ev) = r.step_explicit_events(Vec3::ZERO, Vec3::ONE, 0.125, 0);
        assert!(ev.dead && l == 0.0 && x == Vec3::INFINITY && v == Vec3::ZERO);
        let (_, _, l) = r.step_explicit(Vec3::ZERO, Vec3::ONE, -1.0, 0);
        assert_eq!(l, -1.0);
        // Permanent particles keep their w.
        let (_, _, l) = scene("euler", "").step_explicit(Vec3::ZERO, Vec3::ZERO, 1.0, 0);
        assert_eq!(l, 1.0);
    }

    #[test]
    fn reference_plane_bounce_reflects_and_friction_spares_slow_particles() {
        let plane = "[colliders]\nslow_speed = 0.5\n[[colliders.plane]]\npoint = [0.0, 0.0, 0.0]\n\
                     normal = [0.0, 1.0, 0.0]\nfriction = 0.5\nresilience = 0.5\n";
        let r = scene("euler", plane);
        // Hits during the step: v = (1, -2, 0) -> (0.5, 1, 0), moved from x.
        let x = Vec3::new(0.0, 0.125, 0.0);
        let (xb, vb, _, ev) = r.step_explicit_events(x, Vec3::new(1.0, -2.0, 0.0), 1.0, 0);
        assert_eq!((ev.hits, ev.slow, ev.caught), (1, 0, 0));
        assert_eq!(vb, Vec3::new(0.5, 1.0, 0.0));
        assert_eq!(xb, x + vb * 0.125);
        // Slow: no friction.
        let (_, vb, _, ev) = r.step_explicit_events(
            Vec3::new(0.0, 0.01, 0.0),
            Vec3::new(0.25, -0.25, 0.0),
            1.0,
            0,
        );
        assert_eq!((ev.hits, ev.slow), (1, 1));
        assert_eq!(vb, Vec3::new(0.25, 0.125, 0.0));
        // Caught inside: pushed out to SKIN, velocity mirrored.
        let (xb, vb, _, ev) =
            r.step_explicit_events(Vec3::new(0.0, -0.5, 0.0), Vec3::new(0.0, -1.0, 0.0), 1.0, 0);
        assert_eq!(ev.caught, 1);
        assert_eq!(vb, Vec3::new(0.0, 1.0, 0.0));
        assert!((xb.y - (SKIN + 0.125)).abs() < 1e-6, "{xb}");
    }

    #[test]
    fn reference_box_distance_picks_the_nearest_face_inside() {
        let (lo, hi) = (Vec3::ZERO, Vec3::new(2.0, 4.0, 6.0));
        assert_eq!(
            box_distance(lo, hi, Vec3::new(0.25, 2.0, 3.0)),
            (-0.25, -Vec3::X)
        );
        assert_eq!(
            box_distance(lo, hi, Vec3::new(1.0, 3.5, 3.0)),
            (-0.5, Vec3::Y)
        );
        let (d, n) = box_distance(lo, hi, Vec3::new(3.0, 5.0, 3.0));
        assert!(
            (d - 2f32.sqrt()).abs() < 1e-6
                && (n - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6
        );
    }

    #[test]
    fn reference_rejects_what_it_does_not_model() {
        let src = format!(
            "integrator = \"euler\"\n{}",
            HEAD.replace("[particles]", "[particles]\nvelocity_format = \"rgba16f\"")
        );
        assert!(Reference::new(&parse("test", &src).unwrap()).is_err());
        let src = HEAD.replace(
            "[[emitters.initial]]",
            "[[emitters.timestamp]]\ncycle = 2.0\nlife = [1.0, 1.0]",
        );
        assert!(Reference::new(&parse("test", &src).unwrap()).is_err());
    }
}
