//! The scene file format (TOML): every section's serde type, with its defaults.
//!
//! Kinds of emitters, forces and colliders are array tables named after the kind
//! (`[[forces.attractor]]`, `[[colliders.sphere]]`), not a `kind = ...` tag: serde's tagged enums
//! buffer their content and would lose the spans that errors point at.

mod colliders;
mod constraints;
mod emitters;
mod fluid;
mod forces;
mod neighbours;
mod render;
mod rules;
mod state;

use serde::{Deserialize, Serialize};

pub use colliders::{
    BoxCollider, Collider, ColliderCounts, ColliderKind, Colliders, HeightFieldCollider, Orbit,
    PlaneCollider, SdfCollider, SphereCollider,
};
pub use constraints::{ConstraintKind, Constraints, RelaxScheme, MAX_CONSTRAINT_ITERATIONS};
pub use emitters::{
    AllocatorKind, Burst, Emitter, EmitterKind, Emitters, Flipbook, Shape, MAX_BIRTH_KEYS,
    MAX_BURSTS, MAX_EMITTERS, MAX_EMITTER_FORCES,
};
pub use fluid::{
    emitter_texels, fluid_particles, Fluid, FluidCell, Initial, Resort, Wall, FINE_CELL_PARTICLES,
};
pub use forces::{
    Attractor, CustomForce, Damping, Falloff, FieldData, Force, ForceKind, Forces, Gravity, Spring,
    Vortex, VortexForm, Wind, WindForm, MAX_CUSTOM_FORCES,
};
pub use neighbours::{Dem, PairForce, Response, MAX_PAIR_FORCES};
pub use render::{
    Blending, CameraSection, DrawMode, DrawOrder, DrawPrimitive, Keyframe, LightSection, Lighting,
    Render, RenderPath, Rotate, SortEntries, SortKey, SortSection, Variant, MAX_KEYFRAMES,
};
pub use render::{Lookup, Spread, Trails};
pub use state::{StateFormat, StatePassKind, UserState, MAX_STATE_EXPRESSION, MAX_USER_STATES};

pub(super) fn one() -> f32 {
    1.0
}
fn sixtieth() -> f32 {
    1.0 / 60.0
}
fn one_u32() -> u32 {
    1
}

/// A whole scene file.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Scene name.
    pub name: String,
    /// State texture and storage.
    pub particles: Particles,
    /// Time step.
    #[serde(default)]
    pub time: Time,
    /// Integrator: `euler` (Latta eq. 3, 8), `uberflow` (eq. 1-2), `verlet` (Latta eq. 9), or
    /// the thesis's others (§2.1): `heun`, `rk4`, `leapfrog`.
    #[serde(default)]
    pub integrator: Integrator,
    /// How an explicit integrator writes position and velocity: `mrt` (one pass, two render
    /// targets) or `separate` (a velocity pass, then a position pass: Latta §3.1 without MRT).
    #[serde(default)]
    pub passes: UpdatePasses,
    /// `stateful` (the default: state textures updated step by step) or `stateless` (Latta
    /// §2.1, thesis §2.2.5: every step from start values and time, by a closed form; gravity,
    /// damping and a constant wind only).
    #[serde(default)]
    pub simulation: StateModel,
    /// Emitters by kind.
    #[serde(default)]
    pub emitters: Emitters,
    /// Forces by kind.
    #[serde(default)]
    pub forces: Forces,
    /// Colliders by kind.
    #[serde(default)]
    pub colliders: Colliders,
    /// Collisions between particles (UberFlow §4.3-4.5).
    pub collisions: Option<Collisions>,
    /// Distance constraints between particles (Latta §3.4.3): cloth or hair.
    pub constraints: Option<Constraints>,
    /// Weakly compressible SPH over the cell-sorted state (UberFlow §6).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fluid: Option<Fluid>,
    /// The thesis's fire model (in-shader respawn), instead of emitters, forces and integrator.
    pub fire: Option<Fire>,
    /// How the scene is drawn.
    #[serde(default)]
    pub render: Render,
    /// Per-particle state of the user's own (`[[state]]`), each updated by a pass of its own.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub state: Vec<UserState>,
    /// The file the scene was parsed from, so that a value changed later and rejected by the
    /// engine is still reported at its line and column ([`SceneFile::check`]).
    #[serde(skip)]
    pub origin: Origin,
}

/// Where a scene came from: its path and text, kept to locate later errors. Two scenes compare
/// equal whatever their origins: it says where the values were written, not what they are.
#[derive(Debug, Clone, Default)]
pub struct Origin(pub Option<std::sync::Arc<(String, String)>>);

impl PartialEq for Origin {
    fn eq(&self, _: &Origin) -> bool {
        true
    }
}

/// State texture size and storage (Latta §3.3).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Particles {
    /// State texture size [width, height]: one particle per texel.
    pub size: [u32; 2],
    /// Velocity storage: `rgba32f`, or `rgba16f` (Latta: half floats suffice).
    #[serde(default)]
    pub velocity_format: VelocityFormat,
    /// Mass of every particle (kg), unless its emitter sets one.
    #[serde(default = "one")]
    pub mass: f32,
    /// Arithmetic of the state the simulation writes: `fp32`, or `fp24` (the ATI R300's 24-bit
    /// floats, 16-bit mantissa and 7-bit exponent, emulated by rounding every value written).
    #[serde(default)]
    pub precision: Precision,
}

/// Precision of the written state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Precision {
    /// IEEE single precision.
    #[default]
    Fp32,
    /// Emulated 24-bit floats (UberFlow §4.3.1).
    Fp24,
}

/// Velocity texture format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum VelocityFormat {
    /// Four 32-bit floats.
    #[default]
    Rgba32f,
    /// Four 16-bit floats.
    Rgba16f,
}

/// The fixed time step.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Time {
    /// Simulation step in seconds.
    #[serde(default = "sixtieth")]
    pub dt: f32,
    /// Steps per rendered frame.
    #[serde(default = "one_u32")]
    pub substeps: u32,
}

impl Default for Time {
    fn default() -> Self {
        Time {
            dt: sixtieth(),
            substeps: 1,
        }
    }
}

/// Integration scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Integrator {
    /// Latta's Euler: velocity first, then position from the new velocity.
    #[default]
    Euler,
    /// UberFlow's update: position advanced with the mean of old and new velocity.
    Uberflow,
    /// Position Verlet with three position textures and no velocity pass.
    Verlet,
    /// Heun's predictor-corrector (explicit trapezoid), second order.
    Heun,
    /// The classical fourth-order Runge-Kutta.
    Rk4,
    /// Leapfrog, kick-drift-kick: second order, symplectic for forces of position alone.
    Leapfrog,
}

impl Integrator {
    /// Every integrator, in table order.
    pub const ALL: [Integrator; 6] = [
        Integrator::Euler,
        Integrator::Uberflow,
        Integrator::Verlet,
        Integrator::Heun,
        Integrator::Rk4,
        Integrator::Leapfrog,
    ];

    /// The scene-file name.
    pub fn name(self) -> &'static str {
        match self {
            Integrator::Euler => "euler",
            Integrator::Uberflow => "uberflow",
            Integrator::Verlet => "verlet",
            Integrator::Heun => "heun",
            Integrator::Rk4 => "rk4",
            Integrator::Leapfrog => "leapfrog",
        }
    }

    /// Whether the scheme evaluates the forces at intermediate states (`glsl/sim/stages.glsl`).
    pub fn multistage(self) -> bool {
        matches!(
            self,
            Integrator::Heun | Integrator::Rk4 | Integrator::Leapfrog
        )
    }
}

/// Whether particles keep a state between steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StateModel {
    /// Position and velocity textures integrated step by step (Latta §3, UberFlow §4.2).
    #[default]
    Stateful,
    /// Positions and velocities from start values and time by a closed form (Latta §2.1).
    Stateless,
}

/// How the velocity and position textures of an explicit integrator are written in a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum UpdatePasses {
    /// One pass writing both through multiple render targets (thesis §3.2, UberFlow).
    #[default]
    Mrt,
    /// A velocity pass, then a position pass (Latta §3.1, hardware without MRT).
    Separate,
}

/// Inter-particle collisions as UberFlow does them: particles sorted by the index of their cell
/// in a lattice, each one's closest partner among its `neighbours` left and right in the sorted
/// texture, a second sort on a staggered lattice, sphere response with back-tracking.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Collisions {
    /// Sphere radius of every particle (m); two particles collide closer than 2 radius.
    pub radius: f32,
    /// Coefficient of restitution: 1 elastic, 0 perfectly inelastic.
    #[serde(default = "one")]
    pub restitution: f32,
    /// Particles fetched to each side in the sorted texture (UberFlow: 8).
    #[serde(default = "eight")]
    pub neighbours: u32,
    /// Lattice mesh size g0 (m); default 2 radius. The exact detection takes any cell from the
    /// radius up to the largest its runs allow: from 2 radius it walks the 27 cells around a
    /// particle's, below it the cells within 2 radius (trimmed; on a cell of one radius about
    /// 0.39 of the volume, so of the particles, visited).
    pub cell: Option<f32>,
    /// Region the lattice covers: [min corner, max corner]; outside, cells are clamped.
    pub bounds: [[f32; 3]; 2],
    /// A second sort and detection on a lattice shifted by g0/2 (UberFlow Fig. 3).
    #[serde(default = "yes")]
    pub staggered: bool,
    /// Sort only within sets of this many consecutive rows (1 = rows only, UberFlow §5); default
    /// the whole texture.
    pub rows_only: Option<u32>,
    /// How pairs are found: `uberflow` (closest of `neighbours` each side in the sorted rows,
    /// one partner per lattice) or `exact` (every particle closer than 2 radius, from the cells
    /// around it in the sorted cell keys; several partners per particle; needs the full sort and
    /// a cell of at least the radius; `neighbours` and `staggered` do not apply).
    #[serde(default)]
    pub detection: Detection,
    /// The network of the collision sorts: `blocked` (ours, the default) or `packed`
    /// (UberFlow's GP/FP packed bitonic sort). Both sort exact (key, id) entries.
    #[serde(default, skip_serializing_if = "CollisionSort::is_default")]
    pub sort: CollisionSort,
    /// Time-stamp emission with phases in texel order, so that the particles released in one
    /// step share a row (UberFlow §5; default); `false`: random phases.
    #[serde(default = "yes")]
    pub row_phases: bool,
    /// Exact mode: detection and response passes per step (1 to 16); each one relaxes what the
    /// last left overlapping (a resting pile needs a few).
    #[serde(default = "one_u32")]
    pub iterations: u32,
    /// Spinning spheres (UberFlow §4.5: "additional containers for angular momentum and
    /// rotation"): every particle carries an angular velocity in a state texture of its own,
    /// and contacts with friction exchange linear and angular momentum (solid spheres,
    /// I = 2/5 m r²). Off: no spin texture and the passes of a scene without it.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub spin: bool,
    /// With `spin`: the Coulomb friction coefficient of contacts between particles (the
    /// tangential impulse is at most `friction` times the normal one); 0: frictionless.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub friction: f32,
    /// Exact mode: `impulse` (UberFlow §4.5, the default) or `dem`, the discrete-element contact
    /// force of `[collisions.dem]` (one search per step; `iterations` then does not apply).
    #[serde(default)]
    pub response: Response,
    /// The contact force of `response = "dem"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dem: Option<Dem>,
}

fn is_zero(x: &f32) -> bool {
    *x == 0.0
}

/// `collisions.detection`: how collision partners are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Detection {
    /// UberFlow §4.4: the closest of k neighbours to each side in the sorted row, per lattice.
    #[default]
    Uberflow,
    /// Every particle within 2 radius, found in the cells around each particle (the 27 around
    /// its cell, or on a cell below 2 radius those within 2 radius) through the sorted keys
    /// (fragment passes only).
    Exact,
}

/// `collisions.sort`: the sorting network of the collision stage's cell sorts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CollisionSort {
    /// Our blocked bitonic network (`crate::sort::blocked`), exact (key, id) entries.
    #[default]
    Blocked,
    /// UberFlow §4.3.3's GP/FP packed bitonic network, one step per pass.
    Packed,
}

impl CollisionSort {
    fn is_default(&self) -> bool {
        *self == CollisionSort::Blocked
    }

    /// The sort variant that runs it.
    pub fn variant(self) -> Variant {
        match self {
            CollisionSort::Blocked => Variant::Blocked,
            CollisionSort::Packed => Variant::Packed,
        }
    }

    /// Its words in pass lists.
    pub fn label(self) -> &'static str {
        match self {
            CollisionSort::Blocked => "blocked: a network pass, then merge passes",
            CollisionSort::Packed => "GP/FP packed bitonic network",
        }
    }
}

fn eight() -> u32 {
    8
}
fn yes() -> bool {
    true
}

/// `[fire]`: the thesis's fire model, whose particles respawn in the shader.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Fire {
    /// Emitter disc centre.
    pub emitter_center: [f32; 3],
    /// Emitter disc radius.
    pub emitter_radius: f32,
    /// Mean upward speed at birth.
    pub speed: f32,
    /// Sideways speed at birth.
    pub spread: f32,
    /// Pull towards the axis (1/s).
    pub converge: f32,
    /// Buoyancy (negative gravity), m/s².
    pub buoyancy: [f32; 3],
    /// Random acceleration amplitude.
    pub turbulence: f32,
    /// Damping rate (1/s).
    pub damping: f32,
    /// Life range [min, max].
    pub life: [f32; 2],
    /// Cycle length: life plus wait.
    pub max_age: f32,
}
