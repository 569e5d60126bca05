//! `[[forces.*]]`: what accelerates particles (what they bounce off: `colliders.rs`).

use serde::{Deserialize, Serialize};

use super::one;

/// Forces by kind (Latta §3.4.2, UberFlow §4.2).
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Forces {
    /// Uniform acceleration.
    #[serde(default)]
    pub gravity: Vec<Gravity>,
    /// Point attractors (negative strength: repulsors).
    #[serde(default)]
    pub attractor: Vec<Attractor>,
    /// Rotation around a line.
    #[serde(default)]
    pub vortex: Vec<Vortex>,
    /// Linear damping (negative rate: un-damping).
    #[serde(default)]
    pub damping: Vec<Damping>,
    /// Wind from a 3D flow-field texture with Stokes drag (Latta eq. 1).
    #[serde(default)]
    pub wind: Vec<Wind>,
    /// Linear springs to an anchor (harmonic oscillators: the integrators' test problem).
    #[serde(default)]
    pub spring: Vec<Spring>,
    /// User GLSL forces (at most four), added to the integration pass.
    #[serde(default)]
    pub custom: Vec<CustomForce>,
    /// User GLSL forces between neighbours (at most four), summed over the particles the exact
    /// collision detection finds within each one's radius.
    #[serde(default)]
    pub pair: Vec<super::PairForce>,
}

/// Most `[[forces.custom]]` of one scene.
pub const MAX_CUSTOM_FORCES: usize = 4;

/// A user force: a GLSL file defining `vec3 force(vec3 x, vec3 v, float age, int type)`, the
/// force in N on a particle at `x` with velocity `v`, `age` seconds after its birth, of type
/// `type`; divided by the particle's mass (Latta eq. 2) and added in the integration pass. It is
/// compiled after `common/rng.glsl` and `sim/fields.glsl`, so their functions may be used.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CustomForce {
    /// The file, relative to the scene file (see `SceneFile::resolve_custom_paths`).
    pub glsl: String,
    /// The file's text, once read and checked ([`crate::scene::load_custom`]); `None` until
    /// then (the engine then reads the file itself).
    #[serde(skip)]
    pub source: Option<String>,
}

/// A linear spring pulling every particle towards an anchor: F = -k (x - anchor).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Spring {
    /// Rest point.
    pub anchor: [f32; 3],
    /// Stiffness k in N/m (with mass m the angular frequency is sqrt(k/m)).
    pub stiffness: f32,
}

/// Uniform acceleration.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Gravity {
    /// m/s².
    pub acceleration: [f32; 3],
}

/// Falloff of a point force.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Falloff {
    /// strength / r², softened near the centre.
    #[default]
    InverseSquare,
    /// strength, up to `max_distance`.
    Constant,
}

/// A point attractor or repulsor.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Attractor {
    /// Centre.
    pub position: [f32; 3],
    /// Force (N; N·m² for inverse square); negative repels.
    pub strength: f32,
    /// Falloff.
    #[serde(default)]
    pub falloff: Falloff,
    /// No force beyond this distance.
    pub max_distance: Option<f32>,
    /// Inverse square only: Plummer softening length, F = s d / (r² + soft²)^(3/2), which keeps
    /// the force finite and smooth, and zero at the centre.
    #[serde(default = "softening")]
    pub softening: f32,
}

fn softening() -> f32 {
    0.05
}

/// Which vortex: the papers' or the swirl.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VortexForm {
    /// A tangential force around the axis, `s (a × r) / max(|r|, 0.1)²` (a Rankine vortex; the
    /// default, what the scenes had before the paper's form).
    #[default]
    Swirl,
    /// Latta §3.4.2: towards the closest point on the line, with the falloff of an attractor
    /// (`falloff`, `max_distance`, `softening`); particles moving across it orbit the line.
    Latta,
}

/// A vortex around a line.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Vortex {
    /// A point on the axis.
    pub point: [f32; 3],
    /// Axis direction.
    pub axis: [f32; 3],
    /// Force at distance 1 (N; N·m² for the inverse square of `form = "latta"`); tangential for
    /// `swirl`, towards the line for `latta` (negative pushes away).
    pub strength: f32,
    /// Which form.
    #[serde(default)]
    pub form: VortexForm,
    /// `latta` only: falloff with the distance to the line.
    #[serde(default)]
    pub falloff: Falloff,
    /// `latta` only: no force beyond this distance from the line.
    pub max_distance: Option<f32>,
    /// `latta` only, inverse square: Plummer softening length.
    #[serde(default = "softening")]
    pub softening: f32,
}

/// Linear damping.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Damping {
    /// 1/s; negative un-damps.
    pub rate: f32,
}

/// How the wind acts on a particle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum WindForm {
    /// `a = k (w(x) - v)`: Stokes drag as an acceleration, `k = drag` in 1/s, the same for every
    /// mass (the default, what the scenes had before the papers' forms).
    #[default]
    Drag,
    /// Latta eq. 1-2: the force `F = c (w(x) - v)`, `c = drag` in kg/s, divided by the
    /// particle's mass, `a = F / m`.
    Latta,
    /// UberFlow eq. 1: the wind velocity added to the velocity every step,
    /// `v' = v + w(x) + (F / m) dt` (no `drag`).
    Uberflow,
}

/// Wind from a flow field.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Wind {
    /// Which form.
    #[serde(default)]
    pub form: WindForm,
    /// Mean wind velocity (added to `field` and to the curl noise, when given).
    #[serde(default)]
    pub velocity: [f32; 3],
    /// Amplitude of the field's variation around the mean.
    #[serde(default)]
    pub turbulence: f32,
    /// Amplitude (m/s) of curl noise added to the wind: the curl of a gradient-noise vector
    /// potential, divergence-free (the discrete divergence of the texture vanishes).
    #[serde(default)]
    pub curl: f32,
    /// Size (m) of the curl noise's swirls: the period of its noise lattice.
    #[serde(default = "one")]
    pub curl_scale: f32,
    /// Flow-field texture size per axis (not with `field`, whose shape gives it).
    #[serde(default = "wind_resolution")]
    pub resolution: u32,
    /// Region the field covers: [min corner, max corner].
    pub bounds: [[f32; 3]; 2],
    /// Stokes drag coefficient: 1/s for `drag`, kg/s for `latta`, absent for `uberflow`.
    #[serde(default)]
    pub drag: f32,
    /// A measured or precomputed wind: a float32 `.npy` of shape (nz, ny, nx, 3), or (nz, nx, 3)
    /// for a layer the same at every height, spread over `bounds` (relative to the scene file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<String>,
    /// The velocities of `field`, read when the scene file is parsed.
    #[serde(skip)]
    pub data: Option<FieldData>,
}

/// Values of a field read from a file a scene names: `size` nodes per axis (x fastest, then y,
/// then z), `channels` floats per node.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FieldData {
    /// Nodes per axis [x, y, z] (1 for an axis the file does not have).
    pub size: [u32; 3],
    /// Floats per node.
    pub channels: usize,
    /// The values, x fastest.
    pub data: Vec<f32>,
}

fn wind_resolution() -> u32 {
    32
}
