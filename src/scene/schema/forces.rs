//! `[[forces.*]]` and `[colliders]`: what accelerates particles and what they bounce off.

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

/// Colliders by kind.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Colliders {
    /// Below this speed no friction is applied (Latta §3.4.2: "if the overall velocity is
    /// smaller than a given threshold").
    #[serde(default)]
    pub slow_speed: f32,
    /// Infinite planes.
    #[serde(default)]
    pub plane: Vec<PlaneCollider>,
    /// Spheres.
    #[serde(default)]
    pub sphere: Vec<SphereCollider>,
    /// Axis-aligned boxes.
    #[serde(default, rename = "box")]
    pub boxes: Vec<BoxCollider>,
    /// Height fields (UberFlow §4.6).
    #[serde(default)]
    pub heightfield: Vec<HeightFieldCollider>,
    /// Signed distance fields in a 3D texture (UberFlow §4.6).
    #[serde(default)]
    pub sdf: Vec<SdfCollider>,
}

/// A plane collider.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneCollider {
    /// A point on the plane.
    pub point: [f32; 3],
    /// Normal (towards the free side).
    pub normal: [f32; 3],
    /// Friction μ in [0, 1] (Latta eq. 5).
    #[serde(default)]
    pub friction: f32,
    /// Resilience ε in [0, 1] (Latta eq. 5).
    #[serde(default = "one")]
    pub resilience: f32,
}

/// A sphere collider.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SphereCollider {
    /// Centre.
    pub center: [f32; 3],
    /// Radius.
    pub radius: f32,
    /// Friction μ in [0, 1] (Latta eq. 5).
    #[serde(default)]
    pub friction: f32,
    /// Resilience ε in [0, 1] (Latta eq. 5).
    #[serde(default = "one")]
    pub resilience: f32,
    /// A horizontal circle the centre travels (Verlet scenes without `[collisions]`).
    pub orbit: Option<Orbit>,
}

impl SphereCollider {
    /// The centre at simulated time `t`: `center`, moved along its orbit if it has one. The one
    /// place a sphere's position is computed: the collision passes' uniforms, the CPU twins and
    /// the drawn geometry all read it here.
    pub fn center_at(&self, t: f64) -> [f32; 3] {
        let d = self.orbit.map_or([0.0; 3], |o| o.offset(t));
        [0, 1, 2].map(|k| self.center[k] + d[k])
    }
}

/// A sphere's motion: its centre at time t is
/// `center + radius (cos(2 pi t / period) - 1, 0, sin(2 pi t / period))`, so it starts at
/// `center`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Orbit {
    /// Radius of the circle (m).
    pub radius: f32,
    /// Time of one turn (s).
    pub period: f32,
}

impl Orbit {
    /// How far the centre has moved from `center` at time `t`.
    pub fn offset(&self, t: f64) -> [f32; 3] {
        let a = std::f64::consts::TAU * t / self.period as f64;
        let r = self.radius as f64;
        [(r * (a.cos() - 1.0)) as f32, 0.0, (r * a.sin()) as f32]
    }
}

/// A box collider.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct BoxCollider {
    /// Minimum corner.
    pub min: [f32; 3],
    /// Maximum corner.
    pub max: [f32; 3],
    /// Friction μ in [0, 1] (Latta eq. 5).
    #[serde(default)]
    pub friction: f32,
    /// Resilience ε in [0, 1] (Latta eq. 5).
    #[serde(default = "one")]
    pub resilience: f32,
}

/// A height field: a landscape of sums of sines over the xz plane, sampled into a texture.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct HeightFieldCollider {
    /// Region [min x, min z, max x, max z].
    pub extent: [f32; 4],
    /// Texture size per axis (procedural hills only: a file's size gives it).
    #[serde(default)]
    pub resolution: u32,
    /// Base height.
    #[serde(default)]
    pub base: f32,
    /// Amplitude of the hills, or the height of a file's value 1 above `base`.
    pub amplitude: f32,
    /// Spatial frequency of the hills (1/m; procedural hills only).
    #[serde(default)]
    pub frequency: f32,
    /// A grey PNG, 8 or 16 bits (relative to the scene file): height = base + amplitude ·
    /// grey / max grey; its first row is min z, its columns run along x.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image: Option<String>,
    /// A float32 `.npy` of shape (nz, nx) (relative to the scene file): height = base +
    /// amplitude · value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub npy: Option<String>,
    /// The values of `image` or `npy` (in [0, 1] for an image), read when the scene is parsed.
    #[serde(skip)]
    pub heights: Option<FieldData>,
    /// Friction μ in [0, 1] (Latta eq. 5).
    #[serde(default)]
    pub friction: f32,
    /// Resilience ε in [0, 1] (Latta eq. 5).
    #[serde(default = "one")]
    pub resilience: f32,
}

/// A signed distance field (UberFlow §4.6) built from analytic shapes, or scan-converted on the
/// GPU from a triangle mesh.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SdfCollider {
    /// Region the field covers: [min corner, max corner].
    pub bounds: [[f32; 3]; 2],
    /// Texture size per axis (not with `field`, whose shape gives it).
    #[serde(default)]
    pub resolution: u32,
    /// A signed distance field from a file: a float32 `.npy` of shape (nz, ny, nx), metres,
    /// negative inside, over `bounds` (relative to the scene file).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub field: Option<String>,
    /// The distances of `field`, read when the scene file is parsed.
    #[serde(skip)]
    pub distances: Option<FieldData>,
    /// Spheres [x, y, z, radius] united into the shape.
    #[serde(default)]
    pub spheres: Vec<[f32; 4]>,
    /// Boxes [min x, min y, min z, max x, max y, max z] united into the shape.
    #[serde(default)]
    pub boxes: Vec<[f32; 6]>,
    /// A closed triangle mesh (an OBJ file, relative to the scene file) scan-converted into
    /// the field instead of spheres and boxes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<String>,
    /// The mesh's triangles, read when the scene file is parsed (empty without a mesh).
    #[serde(skip)]
    pub triangles: Vec<[[f32; 3]; 3]>,
    /// Friction μ in [0, 1] (Latta eq. 5).
    #[serde(default)]
    pub friction: f32,
    /// Resilience ε in [0, 1] (Latta eq. 5).
    #[serde(default = "one")]
    pub resilience: f32,
}
