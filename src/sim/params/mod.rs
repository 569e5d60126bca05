//! The numbers the simulation passes read, packed once from the scene.
//!
//! One typed block per pass family: [`Time`] (the step), [`Integration`] (masses, gravity,
//! damping, point forces), [`Colliders`] (the shapes and their responses), [`Emitters`] (births
//! and spawn) and [`Constraints`] (the relaxation). [`Params::of`] builds them from the scene
//! file; the particle simulation holds them, not the scene; the GPU passes upload them (`src/sim/particles/uniforms.rs`), and the CPU twin of the
//! integration pass (`src/sim/reference/`, which the CPU engine steps) reads the same values,
//! so the scene is encoded once. Each field names the uniform it becomes.
//!
//! Rules derived from the scene (the collision cell, the mass range of a type) are methods of
//! the scene's data (`src/scene/schema/rules.rs`), which the validation also asks.

mod constraints;
mod emitters;

use glam::{Vec2, Vec3, Vec4};

use crate::scene::{self, Collider as SceneCollider, ColliderKind, Force as SceneForce, SceneFile};
pub use constraints::Constraints;
pub use emitters::Emitters;

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from(a)
}

/// Every parameter block of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// The time step.
    pub time: Time,
    /// What the integration pass (and the collision response's masses) read.
    pub integration: Integration,
    /// The colliders.
    pub colliders: Colliders,
    /// The emitters: births and spawn.
    pub emitters: Emitters,
    /// The relaxation (scenes with `[constraints]`).
    pub constraints: Option<Constraints>,
}

impl Params {
    /// The blocks of `s`.
    pub fn of(s: &SceneFile) -> Self {
        Params {
            time: Time {
                dt: s.time.dt,
                substeps: s.time.substeps,
            },
            integration: Integration::of(s),
            colliders: Colliders::of(&s.colliders),
            emitters: Emitters::of(s),
            constraints: Constraints::of(s),
        }
    }
}

/// The step: simulation time advances `dt` per step, `substeps` steps per frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Time {
    /// Seconds per step.
    pub dt: f32,
    /// Steps per rendered frame.
    pub substeps: u32,
}

/// The integration pass's masses and forces (`glsl/common/mass.glsl`, `glsl/sim/forces.glsl`).
#[derive(Debug, Clone, PartialEq)]
pub struct Integration {
    /// `u_dt`.
    pub dt: f32,
    /// Each type's inverse mass, of its mean mass: `u_inv_mass`.
    pub inv_mass: [f32; 4],
    /// Each type's lightest mass: `u_mass_lo`.
    pub mass_lo: [f32; 4],
    /// Each type's heaviest mass: `u_mass_hi`.
    pub mass_hi: [f32; 4],
    /// Each type's emission cycle (s): `u_cycle`.
    pub cycle: [f32; 4],
    /// The scene's gravity, summed (`None` without `[[forces.gravity]]`): `u_gravity`.
    pub gravity: Option<Vec3>,
    /// The scene's damping rates, summed (`None` without `[[forces.damping]]`): `u_damping`.
    pub damping: Option<f32>,
    /// The attractors, the scene's then each emitter's.
    pub attractors: Vec<Attractor>,
    /// The springs, the scene's then each emitter's.
    pub springs: Vec<Spring>,
    /// The vortices, the scene's then each emitter's.
    pub vortices: Vec<Vortex>,
    /// Each emitter's own gravity, summed (at most four): `u_type_gravity[k]`.
    pub type_gravity: Vec<Vec3>,
    /// Each emitter's own damping, summed: `u_type_damping`.
    pub type_damping: [f32; 4],
    /// The scene's first wind (the flow field's texture is built apart, `src/sim/fields/`).
    pub wind: Option<Wind>,
    /// Spinning spheres (`glsl/collide/spin.glsl`): their radius `u_spin_radius` and the pairs'
    /// friction `u_friction`.
    pub spin: Option<Vec2>,
}

/// The wind's bounds and drag.
#[derive(Debug, Clone, PartialEq)]
pub struct Wind {
    /// The flow field's box: `u_flow_min`, `u_flow_max`.
    pub bounds: [Vec3; 2],
    /// `u_drag`.
    pub drag: f32,
}

/// A point attractor or repulsor.
#[derive(Debug, Clone, PartialEq)]
pub struct Attractor {
    /// Centre, strength: `u_attractor[i]`.
    pub at: Vec4,
    /// Constant falloff (0/1), max distance (< 0: none), softening: `u_attractor_shape[i]`.
    pub shape: Vec4,
    /// The type it acts on (-1: every type): `u_attractor_owner[i]`.
    pub owner: i32,
}

/// A linear spring.
#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// Anchor, stiffness: `u_spring[i]`.
    pub at: Vec4,
    /// The type it acts on (-1: every type): `u_spring_owner[i]`.
    pub owner: i32,
}

/// A vortex.
#[derive(Debug, Clone, PartialEq)]
pub struct Vortex {
    /// Point on the axis, strength: `u_vortex[i]`.
    pub at: Vec4,
    /// Unit axis: `u_vortex_axis[i]`.
    pub axis: Vec3,
    /// Latta form (0/1), constant falloff (0/1), max distance (< 0: none), softening:
    /// `u_vortex_shape[i]`.
    pub shape: Vec4,
    /// The type it acts on (-1: every type): `u_vortex_owner[i]`.
    pub owner: i32,
}

impl Integration {
    /// The integration block of `s`.
    pub fn of(s: &SceneFile) -> Self {
        let mut inv_mass = [1.0 / s.particles.mass; 4];
        let mut cycle = [1.0f32; 4];
        let (mut mass_lo, mut mass_hi) = ([s.particles.mass; 4], [s.particles.mass; 4]);
        for (k, e) in s.emitters.all().enumerate() {
            let [l, h] = s.mass_range(e);
            (mass_lo[k], mass_hi[k]) = (l, h);
            inv_mass[k] = 1.0 / (0.5 * (l + h));
            cycle[k] = e.cycle.unwrap_or(1.0);
        }
        let f = &s.forces;
        let gravity = (!f.gravity.is_empty()).then(|| sum_gravity(f));
        let damping = (!f.damping.is_empty()).then(|| sum_damping(f));
        // The scene's forces (owner -1: every type), then each emitter's (owner: its type), in
        // the order Features counts them.
        let lists: Vec<(i32, &scene::Forces)> = std::iter::once((-1, f))
            .chain(
                s.emitters
                    .all()
                    .enumerate()
                    .map(|(k, e)| (k as i32, &e.forces)),
            )
            .collect();
        let (mut attractors, mut springs, mut vortices) = (Vec::new(), Vec::new(), Vec::new());
        for &(owner, fs) in &lists {
            for force in fs.iter() {
                match force {
                    SceneForce::Attractor(a) => attractors.push(Attractor::of(a, owner)),
                    SceneForce::Spring(sp) => springs.push(Spring {
                        at: v3(sp.anchor).extend(sp.stiffness),
                        owner,
                    }),
                    SceneForce::Vortex(v) => vortices.push(Vortex::of(v, owner)),
                    // Summed: the scene's above, each emitter's below.
                    SceneForce::Gravity(_) | SceneForce::Damping(_) => {}
                    // The wind is a texture (`src/sim/particles/setup.rs`), a custom force
                    // compiled in (`src/sim/particles/custom.rs`), a pair force a pass of the
                    // collision stage (`src/sim/collide/`).
                    SceneForce::Wind(_) | SceneForce::Custom(_) | SceneForce::Pair(_) => {}
                }
            }
        }
        let mut type_damping = [0.0f32; 4];
        let mut type_gravity = Vec::new();
        for (k, e) in s.emitters.all().enumerate().take(4) {
            type_gravity.push(sum_gravity(&e.forces));
            type_damping[k] = sum_damping(&e.forces);
        }
        Integration {
            dt: s.time.dt,
            inv_mass,
            mass_lo,
            mass_hi,
            cycle,
            gravity,
            damping,
            attractors,
            springs,
            vortices,
            type_gravity,
            type_damping,
            wind: f.wind.first().map(|w| Wind {
                bounds: w.bounds.map(v3),
                drag: w.drag,
            }),
            spin: (s.collisions.as_ref())
                .filter(|k| k.spin)
                .map(|k| Vec2::new(k.radius, k.friction)),
        }
    }
}

fn sum_gravity(f: &scene::Forces) -> Vec3 {
    f.gravity.iter().map(|g| v3(g.acceleration)).sum()
}

fn sum_damping(f: &scene::Forces) -> f32 {
    f.damping.iter().map(|d| d.rate).sum()
}

impl Attractor {
    fn of(a: &scene::Attractor, owner: i32) -> Self {
        Attractor {
            at: v3(a.position).extend(a.strength),
            shape: Vec4::new(
                (a.falloff == scene::Falloff::Constant) as u8 as f32,
                a.max_distance.unwrap_or(-1.0),
                a.softening,
                0.0,
            ),
            owner,
        }
    }
}

impl Vortex {
    fn of(v: &scene::Vortex, owner: i32) -> Self {
        Vortex {
            at: v3(v.point).extend(v.strength),
            axis: v3(v.axis).normalize(),
            shape: Vec4::new(
                (v.form == scene::VortexForm::Latta) as u8 as f32,
                (v.falloff == scene::Falloff::Constant) as u8 as f32,
                v.max_distance.unwrap_or(-1.0),
                v.softening,
            ),
            owner,
        }
    }
}

/// The colliders as `glsl/sim/colliders.glsl` reads them.
#[derive(Debug, Clone, PartialEq)]
pub struct Colliders {
    /// Below this speed no friction: `u_slow_speed`.
    pub slow_speed: f32,
    /// Every collider, kind by kind in [`ColliderKind::ALL`]'s order (the order the pass tests
    /// them), each kind in scene order.
    pub list: Vec<Collider>,
    /// Every sphere, when one orbits (else none): `u_sphere` is set at every step's time.
    pub moving_spheres: Vec<scene::SphereCollider>,
}

/// One collider.
#[derive(Debug, Clone, PartialEq)]
pub struct Collider {
    /// Its shape.
    pub shape: Shape,
    /// Friction μ, resilience ε (Latta eq. 5): `u_KIND_resp[i]`.
    pub resp: Vec2,
}

/// A collider's shape, as its uniforms hold it.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// Unit normal, offset `n·p`: `u_plane[i]`.
    Plane(Vec4),
    /// Centre at time 0, radius: `u_sphere[i]`.
    Sphere(Vec4),
    /// `u_box_min[i]`, `u_box_max[i]`.
    Box(Vec3, Vec3),
    /// Region [min x, min z, max x, max z]: `u_height_extent` (the texture's size is the built
    /// field's).
    HeightField(Vec4),
    /// The key's bounds (the pass reads the built field's, which a file may give).
    Sdf(Vec3, Vec3),
}

impl Shape {
    /// Its kind.
    pub fn kind(&self) -> ColliderKind {
        match self {
            Shape::Plane(_) => ColliderKind::Plane,
            Shape::Sphere(_) => ColliderKind::Sphere,
            Shape::Box(..) => ColliderKind::Box,
            Shape::HeightField(_) => ColliderKind::HeightField,
            Shape::Sdf(..) => ColliderKind::Sdf,
        }
    }
}

impl Colliders {
    /// The spheres' places at time `t` (none unless one orbits).
    pub fn spheres_at(&self, t: f64) -> Vec<Vec4> {
        (self.moving_spheres.iter())
            .map(|s| v3(s.center_at(t)).extend(s.radius))
            .collect()
    }

    /// The collider block of a scene's `[colliders]`.
    pub fn of(c: &scene::Colliders) -> Self {
        Colliders {
            slow_speed: c.slow_speed,
            list: c.iter().map(Collider::of).collect(),
            moving_spheres: match c.sphere.iter().any(|s| s.orbit.is_some()) {
                true => c.sphere.clone(),
                false => Vec::new(),
            },
        }
    }
}

impl Collider {
    /// One collider's uniforms.
    pub fn of(c: SceneCollider<'_>) -> Self {
        let shape = match c {
            SceneCollider::Plane(pl) => {
                let n = v3(pl.normal).normalize();
                Shape::Plane(n.extend(n.dot(v3(pl.point))))
            }
            SceneCollider::Sphere(sp) => Shape::Sphere(v3(sp.center_at(0.0)).extend(sp.radius)),
            SceneCollider::Box(b) => Shape::Box(v3(b.min), v3(b.max)),
            SceneCollider::HeightField(h) => Shape::HeightField(Vec4::from(h.extent)),
            SceneCollider::Sdf(d) => Shape::Sdf(v3(d.bounds[0]), v3(d.bounds[1])),
        };
        Collider {
            shape,
            resp: Vec2::from(c.response()),
        }
    }
}
