//! A CPU twin of the integration pass (`glsl/sim/integrate.frag` with `glsl/sim/forces.glsl` and
//! `glsl/sim/colliders.glsl`): one time step of one particle, in `f32`, with the same operations
//! in the same order as the GLSL.
//!
//! # Why it exists
//!
//! The GPU pass is the thing the project is about, and it cannot be stepped through or printed.
//! This twin lets tests (tests/forces.rs, tests/colliders.rs) put particles exactly where a
//! branch of the shader fires (a particle hitting a sphere during the step, one caught inside a
//! box, one slower than `slow_speed`, one crossing the height field) and check the GPU's result
//! against an independent, readable evaluation of the same formulas. Both sides do the same `f32`
//! arithmetic, so they agree up to rounding (the GPU may fuse multiply-adds, divide through a
//! reciprocal and normalise with a reciprocal square root): any difference beyond a few ulps per
//! operation is a bug on one side.
//!
//! # What it covers
//!
//! - Integrators: Latta's Euler (eq. 3, 8), UberFlow's velocity-averaged update (eq. 1-2),
//!   the thesis's Heun, fourth-order Runge-Kutta and leapfrog (`glsl/sim/stages.glsl`) and
//!   Verlet (Latta eq. 9), plus Verlet's second-order start (`glsl/sim/verlet_start.frag`).
//! - Forces: gravity, damping, wind (Stokes drag towards [`FlowField::sample`]), attractors
//!   (inverse square with softening, or constant; `max_distance`), springs, vortices, per-type
//!   inverse mass (each kind reached through [`scene::ForceKind`]).
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
//! specified), user GLSL forces (`[[forces.custom]]`, `[[forces.pair]]`) and the fire scene.
//!
//! Keep this file in step with the GLSL: a change to one without the other fails
//! tests/forces.rs and tests/colliders.rs.

mod colliders;
pub mod constraints;
mod forces;
#[cfg(test)]
mod tests;

use glam::{Vec2, Vec3, Vec4};

use super::fields::{DistanceField, FlowField, HeightField};
use super::params::{self, Params};
use super::particles::{Emission, Features};
use crate::error::{Error, Result};
use crate::scene::{self, ForceKind, Integrator, Precision, SceneFile, VelocityFormat};

/// `SKIN` in `glsl/sim/colliders.glsl`: how far above a surface a particle is put back.
pub const SKIN: f32 = 1e-4;

/// The branches one step took (for tests that must show that a placement exercises the branch
/// it was meant for).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Events {
    /// Latta eq. 4-5 responses applied (to the velocity, or to Verlet's implied velocity).
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
    /// Of those, walks through a collider that shares a face with another (along the previous
    /// push's direction, onto the union's surface).
    pub walked_out: u32,
    /// Bounces after Latta's response at the point where the replayed path entered a plane,
    /// sphere or box (`bounce_on`).
    pub bounces: u32,
    /// Steps whose path still entered one after `MAX_BOUNCES` bounces (the pass flags them).
    pub bounces_truncated: u32,
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
        self.walked_out += o.walked_out;
        self.bounces += o.bounces;
        self.bounces_truncated += o.bounces_truncated;
        self.dead |= o.dead;
    }
}

#[derive(Debug, Clone)]
struct Wind {
    field: FlowField,
    drag: f32,
    form: scene::WindForm,
}

/// A collider's shape, with the uniforms the shader gets (from [`params::Shape`]).
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
    /// Mass ranges per type (`u_mass_lo`, `u_mass_hi`), with `MASS_RANGE`.
    mass_range: Option<([f32; 4], [f32; 4])>,
    /// The static texel's random number of the particle being stepped (see
    /// [`Reference::set_static_random`]).
    random: f32,
    gravity: Option<Vec3>,
    damping: Option<f32>,
    wind: Option<Wind>,
    attractors: Vec<params::Attractor>,
    springs: Vec<params::Spring>,
    vortices: Vec<params::Vortex>,
    slow_speed: f32,
    /// Planes, spheres, boxes, then the distance field: the order of `collide`.
    colliders: Vec<Collider>,
    height: Option<Height>,
}

/// The height field and its response (friction, resilience).
type Height = (HeightField, Vec2);

impl Reference {
    /// The twin of the integration pass that `ParticleSim::new` compiles for `scene`, reading
    /// the parameter blocks ([`Params`]) whose values `ParticleSim` uploads as uniforms.
    pub fn new(scene: &SceneFile) -> Result<Self> {
        if scene.fire.is_some() {
            return Err(Error::InvalidInput(format!(
                "scene `{}` is the thesis's fire: the reference covers the particle system",
                scene.name
            )));
        }
        scene.check()?;
        let features = Features::of(scene);
        covered(scene, &features)?;
        let s = scene;
        // The values the GPU passes upload, packed once (`crate::sim::params`).
        let Params {
            integration: m,
            colliders: c,
            ..
        } = Params::of(s);
        let wind = match s.forces.wind.first() {
            Some(w) => Some(Wind {
                field: FlowField::new(w)?,
                drag: w.drag,
                form: w.form,
            }),
            None => None,
        };
        let (colliders, height) = shapes(s, &c)?;
        Ok(Reference {
            integrator: s.integrator,
            life: features.life(),
            fp24: s.particles.precision == Precision::Fp24,
            dt: m.dt,
            inv_mass: m.inv_mass,
            mass_range: features.mass_range.then_some((m.mass_lo, m.mass_hi)),
            random: 0.5,
            gravity: m.gravity,
            damping: m.damping,
            wind,
            // The reference refuses forces per emitter: every one is the scene's (owner -1).
            attractors: m.attractors,
            springs: m.springs,
            vortices: m.vortices,
            slow_speed: c.slow_speed,
            colliders,
            height,
        })
    }

    /// Sets the random number of the static texel (`w`) of the particles stepped next: with a
    /// mass range it chooses the particle's mass. 0.5 until set.
    pub fn set_static_random(&mut self, r: f32) {
        self.random = r;
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

    /// Moves sphere collider `i` (in scene order) to `centre`, as `u_sphere[i]` is moved for an
    /// orbiting sphere.
    pub fn move_sphere(&mut self, i: usize, centre: Vec3) {
        let sphere = self
            .colliders
            .iter_mut()
            .filter_map(|c| match &mut c.shape {
                Shape::Sphere(s) => Some(s),
                Shape::Plane(_) | Shape::Box(..) | Shape::Sdf(..) => None,
            })
            .nth(i);
        if let Some(s) = sphere {
            *s = centre.extend(s.w);
        }
    }

    /// `keep_outside` on a position alone (the constraint relaxation's last step), `fp_store`
    /// not applied.
    pub fn keep_outside_position(&self, mut x: Vec3) -> Vec3 {
        if self.has_colliders() {
            let mut v = Vec3::ZERO;
            self.keep_outside(&mut x, &mut v, &mut Events::default());
        }
        x
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
        let im = self.particle_inv_mass(ty, self.random);
        let (mut xb, mut vb) = if self.integrator.multistage() {
            self.stages(x, v + self.wind_kick(x), im)
        } else {
            let a = self.acceleration_of(x, v, im);
            let vb = v + self.wind_kick(x) + a * self.dt;
            (self.advance(x, v, vb), vb)
        };
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
        let a = self.acceleration_of(x, v, self.particle_inv_mass(ty, self.random));
        let mut xn = 2.0 * x - x_prev + a * (dt * dt) + self.wind_kick(x) * dt;
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

    /// `stages(x, v, im)` of `glsl/sim/stages.glsl`: Heun, RK4 or leapfrog, in the shader's
    /// order of operations. Returns the new position and velocity.
    fn stages(&self, x: Vec3, v: Vec3, im: f32) -> (Vec3, Vec3) {
        let h = self.dt;
        let acc = |x: Vec3, v: Vec3| self.acceleration_of(x, v, im);
        match self.integrator {
            Integrator::Heun => {
                let a1 = acc(x, v);
                let x2 = x + h * v;
                let v2 = v + h * a1;
                let a2 = acc(x2, v2);
                (x + (0.5 * h) * (v + v2), v + (0.5 * h) * (a1 + a2))
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
                    x + (h / 6.0) * (v + 2.0 * v2 + 2.0 * v3 + v4),
                    v + (h / 6.0) * (a1 + 2.0 * a2 + 2.0 * a3 + a4),
                )
            }
            // Leapfrog; the single-stage integrators do not reach `stages`.
            Integrator::Leapfrog
            | Integrator::Euler
            | Integrator::Uberflow
            | Integrator::Verlet => {
                let vh = v + (0.5 * h) * acc(x, v);
                let xn = x + h * vh;
                (xn, vh + (0.5 * h) * acc(xn, vh))
            }
        }
    }

    /// `advance(x, v, vb)`.
    fn advance(&self, x: Vec3, v: Vec3, vb: Vec3) -> Vec3 {
        match self.integrator {
            Integrator::Uberflow | Integrator::Heun | Integrator::Rk4 | Integrator::Leapfrog => {
                x + 0.5 * (v + vb) * self.dt
            }
            Integrator::Euler | Integrator::Verlet => x + vb * self.dt,
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
}

/// Refuses the scenes whose features the reference does not model.
fn covered(scene: &SceneFile, features: &Features) -> Result<()> {
    if features.stateless {
        return Err(Error::InvalidInput(format!(
            "scene `{}`: the reference steps the stateful pass; a stateless scene's twin is \
             its closed form (sim::ClosedForm)",
            scene.name
        )));
    }
    if features.emitter_forces {
        return Err(Error::InvalidInput(format!(
            "scene `{}`: the reference models the scene's [[forces.*]], not forces per \
             emitter ([[emitters.*.forces.*]])",
            scene.name
        )));
    }
    for kind in ForceKind::ALL {
        let modelled = match kind {
            ForceKind::Gravity
            | ForceKind::Damping
            | ForceKind::Wind
            | ForceKind::Attractor
            | ForceKind::Spring
            | ForceKind::Vortex => true,
            // User GLSL: only the GPU runs it.
            ForceKind::Custom | ForceKind::Pair => false,
        };
        if !modelled && scene.forces.count(kind) > 0 {
            return Err(Error::InvalidInput(format!(
                "scene `{}`: the reference does not run user GLSL ([[forces.{}]])",
                scene.name,
                kind.key()
            )));
        }
    }
    if features.children > 0 {
        return Err(Error::InvalidInput(format!(
            "scene `{}`: the reference does not cover child emitters",
            scene.name
        )));
    }
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
    Ok(())
}

/// The twin's colliders from the collider block: planes, spheres, boxes and the distance field
/// in the order the shader tests them, and the height field, each with its CPU field built from
/// the scene's key.
fn shapes(s: &SceneFile, c: &params::Colliders) -> Result<(Vec<Collider>, Option<Height>)> {
    let mut colliders = Vec::new();
    let mut height = None;
    for p in &c.list {
        let shape = match &p.shape {
            params::Shape::Plane(pl) => Shape::Plane(*pl),
            params::Shape::Sphere(sp) => Shape::Sphere(*sp),
            params::Shape::Box(lo, hi) => Shape::Box(*lo, *hi),
            params::Shape::HeightField(_) => {
                // The pass reads one height field (validation refuses more).
                if let (None, Some(h)) = (&height, s.colliders.heightfield.first()) {
                    height = Some((HeightField::new(h)?, p.resp));
                }
                continue;
            }
            params::Shape::Sdf(lo, hi) => {
                if colliders
                    .iter()
                    .any(|c: &Collider| matches!(c.shape, Shape::Sdf(..)))
                {
                    continue;
                }
                let Some(d) = s.colliders.sdf.first() else {
                    continue;
                };
                Shape::Sdf(*lo, *hi, Box::new(DistanceField::new(d)?))
            }
        };
        colliders.push(Collider {
            shape,
            resp: p.resp,
        });
    }
    Ok((colliders, height))
}
