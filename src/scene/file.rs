//! Scene files (TOML): what a scene simulates and how it is drawn.
//!
//! Every error names the file, line and column: syntax errors and wrong types from the TOML
//! parser, unknown keys (`deny_unknown_fields`), non-finite numbers (TOML accepts `nan` and `inf`;
//! scenes do not), and meaningless values (a negative time step, friction outside [0, 1], ...),
//! located through the spans of a second, untyped parse.
//!
//! Kinds of emitters, forces and colliders are array tables named after the kind
//! (`[[forces.attractor]]`, `[[colliders.sphere]]`), not a `kind = ...` tag: serde's tagged enums
//! buffer their content and would lose the spans that errors point at.

use serde::{Deserialize, Serialize};
use toml::de::{DeTable, DeValue};
use toml::Spanned;

use crate::error::{Error, Result};

fn one() -> f32 {
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
    /// Integrator: `euler` (Latta eq. 3, 8), `uberflow` (eq. 1-2), `verlet` (Latta eq. 9).
    #[serde(default)]
    pub integrator: Integrator,
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
    /// The thesis's fire model (in-shader respawn), instead of emitters, forces and integrator.
    pub fire: Option<Fire>,
    /// How the scene is drawn.
    #[serde(default)]
    pub render: Render,
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
}

/// Emitters by kind.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Emitters {
    /// Latta §3.4.1: a CPU allocator hands out texel indices; new particles are drawn as points.
    /// Needs `rate`.
    #[serde(default)]
    pub allocator: Vec<Emitter>,
    /// UberFlow §4.1: birth times stamped in the state; unborn particles kept out of view; the
    /// particle resets at the end of its `cycle`. Needs `cycle`.
    #[serde(default)]
    pub timestamp: Vec<Emitter>,
    /// Latta §3.4.1's simplest case: every texel filled once at the start. Without `life` the
    /// particles are permanent and the scene runs no birth or death code.
    #[serde(default)]
    pub initial: Vec<Emitter>,
}

impl Emitters {
    /// All emitters in type order (a particle's type is its emitter's place in this list).
    pub fn all(&self) -> impl Iterator<Item = &Emitter> {
        self.allocator
            .iter()
            .chain(&self.timestamp)
            .chain(&self.initial)
    }

    /// Number of emitters.
    pub fn len(&self) -> usize {
        self.allocator.len() + self.timestamp.len() + self.initial.len()
    }

    /// No emitter at all.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Most emitters (particle types) in one scene: one atlas tile each.
pub const MAX_EMITTERS: usize = 4;

/// Where new particles appear.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Shape {
    /// At the centre.
    #[default]
    Point,
    /// In an axis-aligned box of `size` around the centre.
    Box,
    /// In a ball of `radius`.
    Sphere,
    /// On a disc of `radius` in the plane normal to `normal`.
    Disc,
}

/// Allocator strategy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum AllocatorKind {
    /// Last freed, first reused.
    Stack,
    /// Smallest free index first: live particles stay in the first rows.
    #[default]
    MinHeap,
}

/// An emitter: shape, velocity and life of newborn particles.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Emitter {
    /// Particles per second (allocator emitters).
    pub rate: Option<f32>,
    /// Index allocation strategy (allocator emitters).
    pub allocator: Option<AllocatorKind>,
    /// Length of one life cycle in seconds (timestamp emitters).
    pub cycle: Option<f32>,
    /// Emitter shape.
    #[serde(default)]
    pub shape: Shape,
    /// Centre.
    #[serde(default)]
    pub center: [f32; 3],
    /// Box size.
    #[serde(default)]
    pub size: [f32; 3],
    /// Sphere or disc radius.
    #[serde(default)]
    pub radius: f32,
    /// Disc normal (default +y).
    pub normal: Option<[f32; 3]>,
    /// Mean direction of the velocity cone.
    pub direction: [f32; 3],
    /// Half-angle of the velocity cone, degrees.
    #[serde(default)]
    pub cone_degrees: f32,
    /// Speed range [min, max].
    pub speed: [f32; 2],
    /// Life range [min, max], seconds; initial emitters may leave it out (permanent particles).
    pub life: Option<[f32; 2]>,
    /// Mass of this emitter's particles (its type); default `particles.mass`.
    pub mass: Option<f32>,
    /// Sprite size of this type relative to `render.point_size`.
    #[serde(default = "one")]
    pub sprite_scale: f32,
    /// Atlas tile of this type's sprites (0 soft blob, 1 snowflake, 2 smoke puff, 3 ring);
    /// default: the type's own number.
    pub tile: Option<u32>,
}

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

/// A vortex around a line.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Vortex {
    /// A point on the axis.
    pub point: [f32; 3],
    /// Axis direction.
    pub axis: [f32; 3],
    /// Tangential acceleration at distance 1.
    pub strength: f32,
}

/// Linear damping.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Damping {
    /// 1/s; negative un-damps.
    pub rate: f32,
}

/// Wind from a flow field.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Wind {
    /// Mean wind velocity.
    pub velocity: [f32; 3],
    /// Amplitude of the field's variation around the mean.
    #[serde(default)]
    pub turbulence: f32,
    /// Flow-field texture size per axis.
    #[serde(default = "wind_resolution")]
    pub resolution: u32,
    /// Region the field covers: [min corner, max corner].
    pub bounds: [[f32; 3]; 2],
    /// Stokes drag coefficient (1/s).
    pub drag: f32,
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
    /// Texture size per axis.
    pub resolution: u32,
    /// Base height.
    #[serde(default)]
    pub base: f32,
    /// Amplitude of the hills.
    pub amplitude: f32,
    /// Spatial frequency of the hills (1/m).
    pub frequency: f32,
    /// Friction μ in [0, 1] (Latta eq. 5).
    #[serde(default)]
    pub friction: f32,
    /// Resilience ε in [0, 1] (Latta eq. 5).
    #[serde(default = "one")]
    pub resilience: f32,
}

/// A signed distance field built from analytic shapes.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SdfCollider {
    /// Region the field covers: [min corner, max corner].
    pub bounds: [[f32; 3]; 2],
    /// Texture size per axis.
    pub resolution: u32,
    /// Spheres [x, y, z, radius] united into the shape.
    #[serde(default)]
    pub spheres: Vec<[f32; 4]>,
    /// Boxes [min x, min y, min z, max x, max y, max z] united into the shape.
    #[serde(default)]
    pub boxes: Vec<[f32; 6]>,
    /// Friction μ in [0, 1] (Latta eq. 5).
    #[serde(default)]
    pub friction: f32,
    /// Resilience ε in [0, 1] (Latta eq. 5).
    #[serde(default = "one")]
    pub resilience: f32,
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
    /// Lattice mesh size g0 (m); default 2 radius.
    pub cell: Option<f32>,
    /// Region the lattice covers: [min corner, max corner]; outside, cells are clamped.
    pub bounds: [[f32; 3]; 2],
    /// A second sort and detection on a lattice shifted by g0/2 (UberFlow Fig. 3).
    #[serde(default = "yes")]
    pub staggered: bool,
    /// Sort only within sets of this many consecutive rows (1 = rows only, UberFlow §5); default
    /// the whole texture.
    pub rows_only: Option<u32>,
}

fn eight() -> u32 {
    8
}
fn yes() -> bool {
    true
}

/// The thesis's fire (see `crate::sim::FireParams`).
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

/// How particles are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DrawMode {
    /// Points of `point_size` pixels.
    #[default]
    Points,
    /// Textured point sprites with rotation (Latta §3.4.6).
    Sprites,
}

/// Where the vertex stage gets positions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RenderPath {
    /// Vertex texture fetch (thesis Listing 3).
    #[default]
    TextureFetch,
    /// Positions copied on the GPU into a vertex buffer (UberFlow §4.7, Latta §3.4.5).
    VertexBuffer,
}

/// Blending.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Blending {
    /// Order-independent: no sort.
    #[default]
    Additive,
    /// Order-independent: no sort.
    Multiplicative,
    /// Order-dependent: drawn back to front after a GPU sort by viewer distance.
    Alpha,
}

/// Order of sorted drawing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum DrawOrder {
    /// Farthest first, composited with the over operator.
    #[default]
    BackToFront,
    /// Nearest first, composited with the under operator.
    FrontToBack,
}

/// The camera.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct CameraSection {
    /// Point looked at.
    #[serde(default)]
    pub target: [f32; 3],
    /// Distance from the target.
    #[serde(default = "four")]
    pub distance: f32,
    /// Orbit angle around +y, degrees.
    #[serde(default)]
    pub azimuth: f32,
    /// Angle above the horizon, degrees.
    #[serde(default = "ten")]
    pub elevation: f32,
    /// Vertical field of view, degrees.
    #[serde(default = "fortyfive")]
    pub fov: f32,
    /// Orbit speed around +y, degrees per second of simulated time (0: a still camera). A moving
    /// camera is what a sort spread over frames (Latta §3.4.4) has to keep up with.
    #[serde(default)]
    pub orbit: f32,
}

fn four() -> f32 {
    4.0
}
fn ten() -> f32 {
    10.0
}
fn fortyfive() -> f32 {
    45.0
}

impl Default for CameraSection {
    fn default() -> Self {
        CameraSection {
            target: [0.0; 3],
            distance: four(),
            azimuth: 0.0,
            elevation: ten(),
            fov: fortyfive(),
            orbit: 0.0,
        }
    }
}

/// One colour keyframe: at relative age `age`, colour and opacity `rgba`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// Relative age in [0, 1].
    pub age: f32,
    /// Colour and opacity.
    pub rgba: [f32; 4],
}

/// Sorting for alpha blending.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SortSection {
    /// Sort variant (`fp`, `gpfp`, `packed`, `oddeven`, `multistep`); default `oddeven`.
    pub variant: Option<String>,
    /// Spread one sort over frames with this many passes per frame (Latta).
    pub passes_per_frame: Option<u32>,
}

/// Render settings.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Render {
    /// Frame size [width, height].
    #[serde(default = "resolution")]
    pub resolution: [u32; 2],
    /// Camera.
    #[serde(default)]
    pub camera: CameraSection,
    /// Points or sprites.
    #[serde(default)]
    pub mode: DrawMode,
    /// Texture fetch or vertex buffer.
    #[serde(default)]
    pub path: RenderPath,
    /// Point or sprite size in pixels.
    #[serde(default = "two")]
    pub point_size: f32,
    /// Opacity scale.
    #[serde(default = "one")]
    pub intensity: f32,
    /// Blending.
    #[serde(default)]
    pub blending: Blending,
    /// Four keyframes of relative age (three linear segments, Latta §3.4.6); empty: the fire ramp.
    #[serde(default)]
    pub keyframes: Vec<Keyframe>,
    /// Drawing order of alpha blending: `back_to_front` (the over operator) or `front_to_back`
    /// (the under operator, UberFlow's E3).
    #[serde(default)]
    pub order: DrawOrder,
    /// Sort settings (alpha blending only).
    #[serde(default)]
    pub sort: SortSection,
    /// Background colour; multiplicative blending needs a light one.
    #[serde(default)]
    pub background: [f32; 3],
}

fn resolution() -> [u32; 2] {
    [512, 512]
}
fn two() -> f32 {
    2.0
}

impl Default for Render {
    fn default() -> Self {
        Render {
            resolution: resolution(),
            camera: CameraSection::default(),
            mode: DrawMode::default(),
            path: RenderPath::default(),
            point_size: two(),
            intensity: 1.0,
            blending: Blending::default(),
            order: DrawOrder::default(),
            keyframes: Vec::new(),
            sort: SortSection::default(),
            background: [0.0; 3],
        }
    }
}

/// One step of a path into the TOML document, for locating an error.
#[derive(Debug, Clone, PartialEq)]
pub enum Key {
    /// A table key.
    Name(&'static str),
    /// An array index.
    Index(usize),
}

/// A validation failure: where (a path into the document) and what.
#[derive(Debug, Clone, PartialEq)]
pub struct Invalid {
    /// Path to the offending value.
    pub at: Vec<Key>,
    /// What is wrong and what to do.
    pub message: String,
}

fn line_column(src: &str, offset: usize) -> (usize, usize) {
    let mut end = offset.min(src.len());
    while !src.is_char_boundary(end) {
        end -= 1;
    }
    let before = &src[..end];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

fn scene_error(path: &str, src: &str, offset: usize, message: String) -> Error {
    let (line, column) = line_column(src, offset);
    Error::Scene {
        path: path.to_owned(),
        line,
        column,
        message,
    }
}

/// Finds where `at` starts in the untyped document (the deepest part that exists): a plain
/// value or an array of plain values at the value, like the parser's own type errors; a table or
/// an array of tables at its key (in its first header); an array element at the element.
fn locate(doc: &Spanned<DeTable<'_>>, at: &[Key]) -> usize {
    fn holds_tables(v: &DeValue<'_>) -> bool {
        match v {
            DeValue::Table(_) => true,
            DeValue::Array(a) => a.iter().any(|e| holds_tables(e.get_ref())),
            _ => false,
        }
    }
    let mut span = doc.span().start;
    let mut value: Option<&DeValue<'_>> = None;
    let mut table = Some(doc.get_ref());
    for key in at {
        let next = match (key, table, value) {
            (Key::Name(n), Some(t), _) => {
                t.iter()
                    .find(|(k, _)| k.get_ref().as_ref() == *n)
                    .map(|(k, v)| {
                        let start = if holds_tables(v.get_ref()) {
                            k.span().start
                        } else {
                            v.span().start
                        };
                        (start, v)
                    })
            }
            (Key::Index(i), _, Some(DeValue::Array(a))) => a.get(*i).map(|v| (v.span().start, v)),
            _ => None,
        };
        let Some((start, v)) = next else { break };
        span = start;
        value = Some(v.get_ref());
        table = match v.get_ref() {
            DeValue::Table(t) => Some(t),
            _ => None,
        };
    }
    span
}

/// Reports the first float that is NaN, infinite or beyond f32's range.
fn find_non_finite(doc: &DeTable<'_>) -> Option<(usize, String)> {
    fn walk(v: &Spanned<DeValue<'_>>) -> Option<(usize, String)> {
        match v.get_ref() {
            DeValue::Float(f) => {
                let text = f.as_str();
                let value: f64 = text.replace('_', "").parse().unwrap_or(f64::NAN);
                (!value.is_finite() || value.abs() > f32::MAX as f64).then(|| {
                    (
                        v.span().start,
                        format!(
                            "`{text}` is not a finite 32-bit number: scene values must be finite"
                        ),
                    )
                })
            }
            DeValue::Array(a) => a.iter().find_map(walk),
            DeValue::Table(t) => t.iter().find_map(|(_, v)| walk(v)),
            _ => None,
        }
    }
    doc.iter().find_map(|(_, v)| walk(v))
}

/// Parses and validates a scene file; `path` names it in errors.
pub fn parse(path: &str, src: &str) -> Result<SceneFile> {
    let doc = DeTable::parse(src).map_err(|e| {
        let at = e.span().map_or(0, |s| s.start);
        let mut message = e.message().trim().to_owned();
        if message == "duplicate key" {
            // Name the key: the parser's message does not.
            let key: String = src
                .get(at..)
                .unwrap_or_default()
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '-')
                .collect();
            if !key.is_empty() {
                message = format!("duplicate key `{key}`: each key may be set only once");
            }
        }
        scene_error(path, src, at, message)
    })?;
    if let Some((at, message)) = find_non_finite(doc.get_ref()) {
        return Err(scene_error(path, src, at, message));
    }
    let scene: SceneFile = toml::from_str(src).map_err(|e| {
        scene_error(
            path,
            src,
            e.span().map_or(0, |s| s.start),
            e.message().trim().to_owned(),
        )
    })?;
    if let Err(invalid) = scene.validate() {
        return Err(scene_error(
            path,
            src,
            locate(&doc, &invalid.at),
            invalid.message,
        ));
    }
    Ok(scene)
}

type Check = std::result::Result<(), Invalid>;

fn fail(at: Vec<Key>, message: impl Into<String>) -> Check {
    Err(Invalid {
        at,
        message: message.into(),
    })
}

fn path(parts: &[Key]) -> Vec<Key> {
    parts.to_vec()
}

use Key::{Index as I, Name as N};

fn check_response(at: Vec<Key>, friction: f32, resilience: f32) -> Check {
    if !(0.0..=1.0).contains(&friction) {
        let mut p = at.clone();
        p.push(N("friction"));
        return fail(p, format!("friction {friction} is outside [0, 1]"));
    }
    if !(0.0..=1.0).contains(&resilience) {
        let mut p = at;
        p.push(N("resilience"));
        return fail(p, format!("resilience {resilience} is outside [0, 1]"));
    }
    Ok(())
}

fn nonzero(v: [f32; 3]) -> bool {
    v.iter().any(|x| *x != 0.0)
}

fn check_spawn(at: &[Key], s: &Emitter) -> Check {
    let p = |k| {
        let mut v = at.to_vec();
        v.push(N(k));
        v
    };
    if s.tile.is_some_and(|t| t > 3) {
        return fail(
            p("tile"),
            "tile must be 0, 1, 2 or 3 (the atlas has four tiles)",
        );
    }
    if let Some(life) = s.life {
        if !(life[0] > 0.0 && life[0] <= life[1]) {
            return fail(p("life"), "life must be [min, max] with 0 < min <= max");
        }
    }
    if let Some(m) = s.mass.filter(|m| *m <= 0.0) {
        return fail(p("mass"), format!("mass {m} must be above 0 kg"));
    }
    if s.sprite_scale <= 0.0 {
        return fail(
            p("sprite_scale"),
            format!("sprite_scale {} must be above 0", s.sprite_scale),
        );
    }
    if !(s.speed[0] >= 0.0 && s.speed[0] <= s.speed[1]) {
        return fail(p("speed"), "speed must be [min, max] with 0 <= min <= max");
    }
    if !nonzero(s.direction) {
        return fail(p("direction"), "direction must not be zero");
    }
    if !(0.0..=180.0).contains(&s.cone_degrees) {
        return fail(p("cone_degrees"), "cone_degrees must lie in [0, 180]");
    }
    match s.shape {
        Shape::Sphere | Shape::Disc if s.radius <= 0.0 => fail(
            p("radius"),
            "a sphere or disc emitter needs a radius above 0",
        ),
        Shape::Box if s.size.iter().any(|x| *x < 0.0) => {
            fail(p("size"), "box size must not be negative")
        }
        Shape::Disc if s.normal.is_some_and(|n| !nonzero(n)) => {
            fail(p("normal"), "normal must not be zero")
        }
        _ => Ok(()),
    }
}

impl SceneFile {
    /// Checks the values a scene cannot give a meaning to (device limits are checked later).
    pub fn validate(&self) -> Check {
        if self.name.trim().is_empty() {
            return fail(path(&[N("name")]), "name must not be empty");
        }
        if let Some(i) = self.particles.size.iter().position(|s| *s == 0) {
            return fail(
                path(&[N("particles"), N("size"), I(i)]),
                "both sides of size must be at least 1 texel",
            );
        }
        if self.particles.mass <= 0.0 {
            return fail(
                path(&[N("particles"), N("mass")]),
                format!("mass {} must be above 0 kg", self.particles.mass),
            );
        }
        // Finite already in a parsed file; `render --dt` overrides it after parsing.
        if !(self.time.dt.is_finite() && self.time.dt > 0.0) {
            return fail(
                path(&[N("time"), N("dt")]),
                format!(
                    "time step dt {} must be a finite number of seconds above 0",
                    self.time.dt
                ),
            );
        }
        if self.time.substeps == 0 {
            return fail(
                path(&[N("time"), N("substeps")]),
                "substeps must be at least 1",
            );
        }
        let em = &self.emitters;
        let kinds = [
            !em.allocator.is_empty(),
            !em.timestamp.is_empty(),
            !em.initial.is_empty(),
        ];
        if kinds.iter().filter(|k| **k).count() > 1 {
            let second = ["allocator", "timestamp", "initial"]
                .into_iter()
                .zip(kinds)
                .filter(|k| k.1)
                .nth(1)
                .map_or("emitters", |k| k.0);
            return fail(
                path(&[N("emitters"), N(second)]),
                "use one kind of emitter per scene (allocator, timestamp or initial): they \
                 manage the state texture in different ways",
            );
        }
        if em.len() > MAX_EMITTERS {
            // Only one kind is present here: the first emitter over the limit is its element.
            let kind = if !em.allocator.is_empty() {
                "allocator"
            } else if !em.timestamp.is_empty() {
                "timestamp"
            } else {
                "initial"
            };
            return fail(
                path(&[N("emitters"), N(kind), I(MAX_EMITTERS)]),
                format!(
                    "{} emitters: at most {MAX_EMITTERS} (one particle type and atlas tile each)",
                    em.len()
                ),
            );
        }
        for (kind, list) in [("allocator", &em.allocator), ("timestamp", &em.timestamp)] {
            for (i, e) in list.iter().enumerate() {
                if e.life.is_none() {
                    return fail(
                        vec![N("emitters"), N(kind), I(i)],
                        format!("a {kind} emitter needs `life` = [min, max] seconds"),
                    );
                }
            }
        }
        for (i, e) in em.initial.iter().enumerate() {
            let at = [N("emitters"), N("initial"), I(i)];
            if let Some(k) = [
                ("rate", e.rate.is_some()),
                ("allocator", e.allocator.is_some()),
                ("cycle", e.cycle.is_some()),
            ]
            .iter()
            .find(|k| k.1)
            {
                return fail(
                    [&at[..], &[N(k.0)]].concat(),
                    format!("`{}` does not apply to initial emitters", k.0),
                );
            }
            check_spawn(&at, e)?;
        }
        if self.fire.is_some() && !em.is_empty() {
            return fail(
                path(&[N("fire")]),
                "[fire] respawns its particles in the shader: remove the emitters, or [fire]",
            );
        }
        for (i, e) in self.emitters.allocator.iter().enumerate() {
            let at = [N("emitters"), N("allocator"), I(i)];
            let key = |k| [&at[..], &[N(k)]].concat();
            match e.rate {
                None => {
                    return fail(
                        at.to_vec(),
                        "an allocator emitter needs `rate` (particles per second)",
                    )
                }
                Some(r) if r <= 0.0 => {
                    return fail(key("rate"), "rate must be above 0 particles per second")
                }
                _ => {}
            }
            if e.cycle.is_some() {
                return fail(
                    key("cycle"),
                    "`cycle` belongs to timestamp emitters ([[emitters.timestamp]])",
                );
            }
            check_spawn(&at, e)?;
        }
        for (i, e) in self.emitters.timestamp.iter().enumerate() {
            let at = [N("emitters"), N("timestamp"), I(i)];
            let key = |k| [&at[..], &[N(k)]].concat();
            if e.rate.is_some() || e.allocator.is_some() {
                return fail(
                    key(if e.rate.is_some() {
                        "rate"
                    } else {
                        "allocator"
                    }),
                    "`rate` and `allocator` belong to allocator emitters ([[emitters.allocator]])",
                );
            }
            check_spawn(&at, e)?;
            match e.cycle {
                None => return fail(at.to_vec(), "a timestamp emitter needs `cycle` (seconds)"),
                Some(c) if e.life.is_some_and(|l| c < l[1]) => {
                    return fail(key("cycle"), "cycle must be at least the longest life")
                }
                _ => {}
            }
        }
        for (i, sp) in self.forces.spring.iter().enumerate() {
            if sp.stiffness < 0.0 {
                return fail(
                    path(&[N("forces"), N("spring"), I(i), N("stiffness")]),
                    format!("stiffness {} N/m must not be negative", sp.stiffness),
                );
            }
        }
        for (i, v) in self.forces.vortex.iter().enumerate() {
            if !nonzero(v.axis) {
                return fail(
                    path(&[N("forces"), N("vortex"), I(i), N("axis")]),
                    "axis must not be zero",
                );
            }
        }
        for (i, a) in self.forces.attractor.iter().enumerate() {
            if a.softening <= 0.0 {
                return fail(
                    path(&[N("forces"), N("attractor"), I(i), N("softening")]),
                    "softening must be above 0",
                );
            }
            if a.max_distance.is_some_and(|d| d <= 0.0) {
                return fail(
                    path(&[N("forces"), N("attractor"), I(i), N("max_distance")]),
                    "max_distance must be above 0",
                );
            }
        }
        for (i, wnd) in self.forces.wind.iter().enumerate() {
            let at = |k| path(&[N("forces"), N("wind"), I(i), N(k)]);
            if wnd.drag < 0.0 {
                return fail(at("drag"), "drag must not be negative");
            }
            if wnd.turbulence < 0.0 {
                return fail(at("turbulence"), "turbulence must not be negative");
            }
            if !(2..=256).contains(&wnd.resolution) {
                return fail(at("resolution"), "resolution must lie in 2..=256");
            }
            if (0..3).any(|k| wnd.bounds[0][k] >= wnd.bounds[1][k]) {
                return fail(
                    at("bounds"),
                    "bounds must be [min corner, max corner] with min < max",
                );
            }
        }
        if self.forces.wind.len() > 1 {
            return fail(
                path(&[N("forces"), N("wind"), I(1)]),
                "one wind field per scene (it is one 3D texture)",
            );
        }
        let c = &self.colliders;
        for (kind, n) in [("heightfield", c.heightfield.len()), ("sdf", c.sdf.len())] {
            if n > 1 {
                return fail(
                    path(&[N("colliders"), N(kind), I(1)]),
                    format!("one {kind} per scene (it is one texture)"),
                );
            }
        }
        if c.slow_speed < 0.0 {
            return fail(
                path(&[N("colliders"), N("slow_speed")]),
                "slow_speed must not be negative",
            );
        }
        for (i, p) in c.plane.iter().enumerate() {
            if !nonzero(p.normal) {
                return fail(
                    path(&[N("colliders"), N("plane"), I(i), N("normal")]),
                    "normal must not be zero",
                );
            }
            check_response(
                path(&[N("colliders"), N("plane"), I(i)]),
                p.friction,
                p.resilience,
            )?;
        }
        for (i, s) in c.sphere.iter().enumerate() {
            if s.radius <= 0.0 {
                return fail(
                    path(&[N("colliders"), N("sphere"), I(i), N("radius")]),
                    "radius must be above 0",
                );
            }
            check_response(
                path(&[N("colliders"), N("sphere"), I(i)]),
                s.friction,
                s.resilience,
            )?;
        }
        for (i, b) in c.boxes.iter().enumerate() {
            if (0..3).any(|k| b.min[k] >= b.max[k]) {
                return fail(
                    path(&[N("colliders"), N("box"), I(i), N("max")]),
                    "max must exceed min on every axis",
                );
            }
            check_response(
                path(&[N("colliders"), N("box"), I(i)]),
                b.friction,
                b.resilience,
            )?;
        }
        for (i, hf) in c.heightfield.iter().enumerate() {
            if !(2..=4096).contains(&hf.resolution) {
                return fail(
                    path(&[N("colliders"), N("heightfield"), I(i), N("resolution")]),
                    "resolution must lie in 2..=4096",
                );
            }
            if hf.extent[0] >= hf.extent[2] || hf.extent[1] >= hf.extent[3] {
                return fail(
                    path(&[N("colliders"), N("heightfield"), I(i), N("extent")]),
                    "extent must be [min x, min z, max x, max z] with min < max",
                );
            }
            check_response(
                path(&[N("colliders"), N("heightfield"), I(i)]),
                hf.friction,
                hf.resilience,
            )?;
        }
        for (i, sdf) in c.sdf.iter().enumerate() {
            if !(2..=256).contains(&sdf.resolution) {
                return fail(
                    path(&[N("colliders"), N("sdf"), I(i), N("resolution")]),
                    "resolution must lie in 2..=256",
                );
            }
            if sdf.spheres.is_empty() && sdf.boxes.is_empty() {
                return fail(
                    path(&[N("colliders"), N("sdf"), I(i)]),
                    "a distance field needs at least one sphere or box",
                );
            }
            check_response(
                path(&[N("colliders"), N("sdf"), I(i)]),
                sdf.friction,
                sdf.resilience,
            )?;
        }
        if let Some(c) = &self.collisions {
            let at = |k| path(&[N("collisions"), N(k)]);
            if c.radius <= 0.0 {
                return fail(
                    at("radius"),
                    format!("radius {} m must be above 0", c.radius),
                );
            }
            if !(0.0..=1.0).contains(&c.restitution) {
                return fail(
                    at("restitution"),
                    format!("restitution {} is outside [0, 1]", c.restitution),
                );
            }
            if !(1..=32).contains(&c.neighbours) {
                return fail(at("neighbours"), "neighbours must lie in 1..=32");
            }
            if c.cell.is_some_and(|g| g <= 0.0) {
                return fail(at("cell"), "cell must be above 0 m");
            }
            if (0..3).any(|k| c.bounds[0][k] >= c.bounds[1][k]) {
                return fail(
                    at("bounds"),
                    "bounds must be [min corner, max corner] with min < max",
                );
            }
            let [w, h] = self.particles.size;
            if !w.is_power_of_two() || !h.is_power_of_two() {
                return fail(
                    path(&[N("particles"), N("size")]),
                    "collisions sort the state texture: both sides must be powers of two",
                );
            }
            if let Some(k) = c.rows_only {
                if !k.is_power_of_two() || k > h {
                    return fail(
                        at("rows_only"),
                        format!("rows_only must be a power of two up to the height {h}"),
                    );
                }
            }
            if self.integrator == Integrator::Verlet {
                return fail(
                    path(&[N("integrator")]),
                    "collisions exchange momentum through velocities: use euler or uberflow",
                );
            }
            if !self.emitters.allocator.is_empty() {
                return fail(
                    path(&[N("emitters"), N("allocator")]),
                    "collisions reorder the state every step, which the CPU allocator's indices \
                     cannot follow: use timestamp or initial emitters",
                );
            }
            if self.fire.is_some() {
                return fail(path(&[N("collisions")]), "the fire has no collisions");
            }
        }
        if let Some(f) = &self.fire {
            let at = |k| path(&[N("fire"), N(k)]);
            if !(f.life[0] > 0.0 && f.life[0] <= f.life[1] && f.life[1] <= f.max_age) {
                return fail(
                    at("life"),
                    "life must be [min, max] with 0 < min <= max <= max_age",
                );
            }
            for (key, v) in [
                ("emitter_radius", f.emitter_radius),
                ("damping", f.damping),
                ("turbulence", f.turbulence),
            ] {
                if v < 0.0 {
                    return fail(at(key), format!("{key} {v} must not be negative"));
                }
            }
        } else if self.emitters.is_empty() {
            return fail(
                path(&[N("emitters")]),
                "the scene has no emitter and no [fire] model: nothing would ever be born",
            );
        }
        let r = &self.render;
        if let Some(i) = r.resolution.iter().position(|s| *s == 0) {
            return fail(
                path(&[N("render"), N("resolution"), I(i)]),
                "both sides of resolution must be at least 1 pixel",
            );
        }
        if r.point_size <= 0.0 {
            return fail(
                path(&[N("render"), N("point_size")]),
                format!("point_size {} must be above 0 pixels", r.point_size),
            );
        }
        if r.intensity < 0.0 {
            return fail(
                path(&[N("render"), N("intensity")]),
                format!("intensity {} must not be negative", r.intensity),
            );
        }
        if !(r.camera.fov > 0.0 && r.camera.fov < 180.0) {
            return fail(
                path(&[N("render"), N("camera"), N("fov")]),
                format!("fov {} must lie in (0, 180) degrees", r.camera.fov),
            );
        }
        if r.camera.distance <= 0.0 {
            return fail(
                path(&[N("render"), N("camera"), N("distance")]),
                format!("distance {} must be above 0", r.camera.distance),
            );
        }
        if !r.keyframes.is_empty() {
            if r.keyframes.len() != 4 {
                return fail(
                    path(&[N("render"), N("keyframes")]),
                    "give exactly four keyframes (three linear segments, Latta §3.4.6)",
                );
            }
            let ages: Vec<f32> = r.keyframes.iter().map(|k| k.age).collect();
            let bad_age = if ages[0] != 0.0 {
                Some(0)
            } else {
                (1..4)
                    .find(|&i| ages[i] < ages[i - 1])
                    .or((ages[3] != 1.0).then_some(3))
            };
            if let Some(i) = bad_age {
                return fail(
                    path(&[N("render"), N("keyframes"), I(i), N("age")]),
                    format!(
                        "keyframe ages must ascend from 0 to 1 (the first 0, the last 1); \
                         keyframe {} has age {}",
                        i + 1,
                        ages[i]
                    ),
                );
            }
            for (i, k) in r.keyframes.iter().enumerate() {
                if let Some(c) = k.rgba.iter().position(|v| *v < 0.0) {
                    return fail(
                        path(&[N("render"), N("keyframes"), I(i), N("rgba"), I(c)]),
                        "keyframe colours and opacities must not be negative",
                    );
                }
            }
        }
        if let Some(v) = &r.sort.variant {
            if let Err(e) = crate::sort::Variant::from_name(v) {
                return fail(path(&[N("render"), N("sort"), N("variant")]), e.to_string());
            }
        }
        if r.sort.passes_per_frame == Some(0) {
            return fail(
                path(&[N("render"), N("sort"), N("passes_per_frame")]),
                "passes_per_frame must be at least 1",
            );
        }
        Ok(())
    }

    /// Number of particles.
    pub fn particle_count(&self) -> u64 {
        self.particles.size[0] as u64 * self.particles.size[1] as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_count_from_one() {
        assert_eq!(line_column("ab\ncd", 0), (1, 1));
        assert_eq!(line_column("ab\ncd", 4), (2, 2));
        // Columns count characters; an offset inside a character counts from its start.
        assert_eq!(line_column("é = 1", 3), (1, 3));
        assert_eq!(line_column("é = 1", 1), (1, 1));
        assert_eq!(line_column("a", 99), (1, 2));
    }

    #[test]
    fn locate_points_at_values_elements_and_table_keys() {
        let src = "[a]\nx = 1.0\nv = [1, 2]\n[[t]]\ny = 2\n";
        let doc = DeTable::parse(src).unwrap();
        let at = |keys: &[Key]| line_column(src, locate(&doc, keys));
        assert_eq!(at(&[N("a"), N("x")]), (2, 5));
        assert_eq!(at(&[N("a"), N("v"), I(1)]), (3, 9));
        assert_eq!(at(&[N("a"), N("missing")]), (1, 2));
        assert_eq!(at(&[N("t"), I(0), N("y")]), (5, 5));
        assert_eq!(at(&[N("t")]).0, 4);
    }
}

/// Texture size limits of a device, for [`check_limits`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SizeLimits {
    /// GL_MAX_TEXTURE_SIZE.
    pub max_texture: u32,
    /// GL_MAX_3D_TEXTURE_SIZE.
    pub max_3d_texture: u32,
}

/// Checks the sizes a scene asks of the device (state and sort textures, frame, fields) and
/// reports the first one over the limit at its file, line and column. `skip` names keys whose
/// values came from elsewhere (command-line overrides), which the caller checks itself.
pub fn check_limits(
    path: &str,
    src: &str,
    scene: &SceneFile,
    limits: SizeLimits,
    skip: &[&str],
) -> Result<()> {
    let mut over: Vec<(Vec<Key>, &str, u32, u32)> = Vec::new();
    let t = limits.max_texture;
    let [w, h] = scene.particles.size;
    if !skip.contains(&"particles.size") {
        let sort = if scene.render.blending == Blending::Alpha {
            w.next_power_of_two().max(h.next_power_of_two())
        } else {
            0
        };
        over.push((
            vec![N("particles"), N("size")],
            "state texture side",
            w.max(h),
            t,
        ));
        over.push((
            vec![N("particles"), N("size")],
            "sort texture side (the state's, rounded up to a power of two)",
            sort,
            t,
        ));
    }
    if !skip.contains(&"render.resolution") {
        let [rw, rh] = scene.render.resolution;
        over.push((
            vec![N("render"), N("resolution")],
            "frame side",
            rw.max(rh),
            t,
        ));
    }
    for (i, hf) in scene.colliders.heightfield.iter().enumerate() {
        over.push((
            vec![N("colliders"), N("heightfield"), I(i), N("resolution")],
            "height-field texture side",
            hf.resolution,
            t,
        ));
    }
    for (i, s) in scene.colliders.sdf.iter().enumerate() {
        over.push((
            vec![N("colliders"), N("sdf"), I(i), N("resolution")],
            "distance-field 3D texture side",
            s.resolution,
            limits.max_3d_texture,
        ));
    }
    for (i, wnd) in scene.forces.wind.iter().enumerate() {
        over.push((
            vec![N("forces"), N("wind"), I(i), N("resolution")],
            "flow-field 3D texture side",
            wnd.resolution,
            limits.max_3d_texture,
        ));
    }
    let Some((at, what, value, max)) = over.into_iter().find(|o| o.2 > o.3) else {
        return Ok(());
    };
    let doc = DeTable::parse(src).map_err(|e| {
        scene_error(
            path,
            src,
            e.span().map_or(0, |s| s.start),
            e.message().into(),
        )
    })?;
    Err(scene_error(
        path,
        src,
        locate(&doc, &at),
        format!("{what} {value} is over this device's limit of {max}: use a smaller size"),
    ))
}
