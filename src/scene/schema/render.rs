//! `[render]`: camera, drawing, blending, keyframes and the sort alpha blending needs.

use serde::{Deserialize, Serialize};

use super::one;
use crate::error::{Error, Result};

/// How particles are drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DrawMode {
    /// Points of `point_size` pixels.
    #[default]
    Points,
    /// Textured point sprites with rotation (Latta §3.4.6).
    Sprites,
    /// Connected geometry over a constraint layout (`[constraints]`): a cloth as a lit surface
    /// of two triangles a grid cell, hair as strands of line segments, both indexed over the
    /// state texture and fetched from it in the vertex stage.
    Surface,
}

/// The geometry each particle is drawn as (Latta §3.4.5-3.4.6: "point sprites, triangles or
/// quads").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum DrawPrimitive {
    /// One point (sprite) per particle; its size is limited by the driver's
    /// `GL_ALIASED_POINT_SIZE_RANGE`.
    #[default]
    Points,
    /// A camera-facing quad per particle by vertex replication: six vertices fetch the same
    /// texel (`gl_VertexID / 6`). Needs the texture-fetch path.
    Quads,
    /// A quad stretched along the particle's screen-space motion over `render.stretch` seconds
    /// (motion blur). Needs the texture-fetch path.
    Stretched,
    /// One triangle per particle by vertex replication (three vertices fetch the same texel):
    /// the equilateral triangle around the sprite's inscribed circle. Needs the texture-fetch
    /// path.
    Triangles,
}

/// What turns a sprite (`render.rotate`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Rotate {
    /// Latta §3.4.6: an initial angle and a rotation speed per type, times the age.
    #[default]
    Age,
    /// The angle the simulation integrates from each particle's angular velocity about the
    /// z axis (`collisions.spin`; UberFlow §4.5's rotation), kept in the spin texture's w.
    Spin,
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

/// The most colour keyframes one ramp takes (`render.keyframes`, an emitter's `keyframes`).
pub const MAX_KEYFRAMES: usize = 8;

/// One colour keyframe: at relative age `age`, colour and opacity `rgba`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// Relative age in [0, 1].
    pub age: f32,
    /// Colour and opacity.
    pub rgba: [f32; 4],
}

/// What alpha blending sorts by: which particles are drawn on top.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SortKey {
    /// The distance to the viewer: the nearest on top (UberFlow §4.3, Latta §3.4.4).
    #[default]
    Distance,
    /// The age (total life minus remaining life): the youngest on top, as bevy_hanabi's and
    /// Unity VFX Graph's sort by age offers.
    YoungestOnTop,
    /// The age: the oldest on top.
    OldestOnTop,
}

impl SortKey {
    /// The name in scene files.
    pub fn name(self) -> &'static str {
        match self {
            SortKey::Distance => "distance",
            SortKey::YoungestOnTop => "youngest_on_top",
            SortKey::OldestOnTop => "oldest_on_top",
        }
    }
}

/// Sorting for alpha blending.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SortSection {
    /// Sort variant (`fp`, `gpfp`, `packed`, `oddeven`, `multistep`, `blocked`); default `oddeven`.
    pub variant: Option<Variant>,
    /// What the sort orders by: `distance` (default), `youngest_on_top` or `oldest_on_top`.
    #[serde(default)]
    pub key: SortKey,
    /// Spread one sort over frames with this many passes per frame (Latta).
    pub passes_per_frame: Option<u32>,
    /// The order of the spread's passes: `even` (default) or `local` (the first merge stages
    /// re-run between later ones; `crate::sort::spread`).
    #[serde(default, skip_serializing_if = "is_even")]
    pub spread: Spread,
    /// The blocked sort's entries: `exact` (default) or `compact` (4 bytes, the depth quantised
    /// beside the identifier: faster, lossy among particles at nearly the same depth).
    pub entries: Option<SortEntries>,
}

/// The order of passes of a sort spread over frames (`render.sort.spread`; the cycles are
/// built in `crate::sort::spread`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Spread {
    /// The network's passes in order (Latta §3.4.4).
    #[default]
    Even,
    /// Weighted towards neighbours in the order (Latta §4's future work): the odd-even merge
    /// sort's first stages, which sort runs of neighbours, re-run before every later stage.
    Local,
}

fn is_even(s: &Spread) -> bool {
    *s == Spread::Even
}

/// How the blocked sort stores an entry (`render.sort.entries`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SortEntries {
    /// Key and identifier as two floats: the exact order.
    #[default]
    Exact,
    /// Key quantised into the bits the identifier leaves of one uint: twice the entries per
    /// pass; particles closer in depth than one level keep the order of their identifiers.
    Compact,
}

/// The sort implementations, named by `render.sort.variant` and `--variant` (the sorter itself,
/// and what each variant lays out, is `crate::sort`). A scene file names them by the same words
/// as the command line ([`Variant::name`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Variant {
    /// UberFlow's FP: everything derived in the fragment program.
    Fp,
    /// UberFlow's GP/FP: offsets' signs and comparisons from the geometry.
    GpFp,
    /// UberFlow's GP/FP packed: two entries per RGBA texel.
    Packed,
    /// Latta's odd-even merge sort.
    OddEven,
    /// Ours: several bitonic steps per pass on the packed layout.
    Multistep,
    /// Ours: a bitonic network in registers, 16 entries per fragment through multiple render
    /// targets, in a layout that changes from pass to pass (`crate::sort::blocked`).
    Blocked,
}

impl Variant {
    /// Every variant, in table order.
    pub const ALL: [Variant; 6] = [
        Variant::Fp,
        Variant::GpFp,
        Variant::Packed,
        Variant::OddEven,
        Variant::Multistep,
        Variant::Blocked,
    ];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Fp => "fp",
            Variant::GpFp => "gpfp",
            Variant::Packed => "packed",
            Variant::OddEven => "oddeven",
            Variant::Multistep => "multistep",
            Variant::Blocked => "blocked",
        }
    }

    /// Parses a CLI name.
    pub fn from_name(s: &str) -> Result<Variant> {
        Variant::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| {
                Error::InvalidInput(format!(
                    "unknown sort variant `{s}`: use one of {}{}",
                    Variant::ALL.map(Variant::name).join(", "),
                    crate::scene::did_you_mean(s, Variant::ALL.map(Variant::name))
                ))
            })
    }
}

/// How alpha-blended particles are lit (`render.lighting`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Lighting {
    /// Unlit: each particle's keyframe colour as it is.
    #[default]
    None,
    /// Half-angle slicing (Kniss et al. 2003; Green 2008): the particles sorted along the
    /// vector halfway between the light and the view direction, drawn in `render.slices`
    /// batches, each into the frame lit by the opacity the batches before it left in a light
    /// buffer, then into that buffer.
    HalfAngle,
}

/// The light of `lighting = "half_angle"` (`render.light`): one directional light.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct LightSection {
    /// The direction the light travels in (from the light into the scene); need not be unit.
    #[serde(default = "downwards")]
    pub direction: [f32; 3],
    /// The light's colour, multiplied by the transmittance the light buffer holds.
    #[serde(default = "white")]
    pub colour: [f32; 3],
    /// Light that reaches every particle unshadowed (sky light).
    #[serde(default = "ambient")]
    pub ambient: [f32; 3],
    /// Opacity scale of the shadow each particle casts (its opacity in the light buffer).
    #[serde(default = "one")]
    pub density: f32,
    /// The light buffer's side in texels.
    #[serde(default = "light_resolution")]
    pub resolution: u32,
    /// Half the side of the square the light buffer covers, in scene units, centred on the
    /// camera's target; default: the camera's distance.
    pub extent: Option<f32>,
}

fn downwards() -> [f32; 3] {
    [0.0, -1.0, 0.0]
}
fn white() -> [f32; 3] {
    [1.0; 3]
}
fn ambient() -> [f32; 3] {
    [0.3; 3]
}
fn light_resolution() -> u32 {
    256
}
fn thirty_two() -> u32 {
    32
}

impl Default for LightSection {
    fn default() -> Self {
        LightSection {
            direction: downwards(),
            colour: white(),
            ambient: ambient(),
            density: 1.0,
            resolution: light_resolution(),
            extent: None,
        }
    }
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
    /// Points, camera-facing quads or velocity-stretched quads (Latta §3.4.5).
    #[serde(default)]
    pub primitive: DrawPrimitive,
    /// Exposure time of `stretched` quads in seconds: each is stretched from where the particle
    /// was `stretch` seconds ago (x − v·stretch) to where it is.
    #[serde(default = "thirtieth")]
    pub stretch: f32,
    /// Point or sprite size in pixels.
    #[serde(default = "two")]
    pub point_size: f32,
    /// Opacity scale.
    #[serde(default = "one")]
    pub intensity: f32,
    /// Blending.
    #[serde(default)]
    pub blending: Blending,
    /// The particles' colour and opacity by a GLSL `vec4` expression of `color` (the
    /// keyframes'), `x`, `life`, `age`, `type` and the user states by name (`[[state]]`),
    /// replacing the keyframes' colour.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<String>,
    /// The particles' size in pixels by a GLSL `float` expression of `size` (the size the other
    /// keys give), `x`, `life`, `age`, `type` and the user states by name (`[[state]]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<String>,
    /// The sprites' screen-space angle in degrees by a GLSL `float` expression of `angle` (the
    /// angle `rotation_speed` or the spin gives, in degrees), `x`, `life`, `age`, `type` and the
    /// user states by name; it replaces that angle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotation: Option<String>,
    /// 1 to [`MAX_KEYFRAMES`] keyframes of relative age, linear between them (Latta §3.4.6 uses
    /// four); empty: white, fading out.
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
    /// Draw the scene's colliders (planes as bounded checker grids, spheres, boxes, the height
    /// field, distance-field shapes and meshes) in the same camera, opaque and depth-tested
    /// against the particles.
    #[serde(default)]
    pub geometry: bool,
    /// What turns sprites: `age` (each type's rotation speed, Latta §3.4.6) or `spin` (the
    /// angle integrated from the angular velocity of spinning spheres; needs `collisions.spin`).
    #[serde(default, skip_serializing_if = "is_age")]
    pub rotate: Rotate,
    /// Lighting of alpha-blended particles: `none`, or `half_angle` (self-shadowing smoke).
    #[serde(default, skip_serializing_if = "unlit")]
    pub lighting: Lighting,
    /// Batches the half-angle sorted particles are drawn in (`lighting = "half_angle"`).
    #[serde(default = "thirty_two")]
    pub slices: u32,
    /// The light of `lighting = "half_angle"`.
    #[serde(default)]
    pub light: LightSection,
    /// How the vertex stage finds the particles of alpha blending in sorted order: `gather`
    /// (default: the state gathered into sorted textures first, UberFlow §4.3.1) or `index`
    /// (Latta §3.4.4: each vertex reads the sorted (key, id) texture and fetches the state at
    /// `id`).
    #[serde(default, skip_serializing_if = "is_gather")]
    pub lookup: Lookup,
    /// Soft particles: within this many metres in front of the drawn geometry a particle's
    /// opacity fades to 0 (its view depth against the geometry's); 0, the default, is off.
    /// Needs `geometry = true`.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub soft: f32,
    /// Child emitters' trails: `none` (default) or `ribbon` (camera-facing quads between
    /// consecutive trail children of one parent, `src/render/ribbons.rs`).
    #[serde(default, skip_serializing_if = "no_trails")]
    pub trails: Trails,
    /// The ribbons' width in metres; absent: each end's point size in pixels.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ribbon_width: Option<f32>,
}

/// How child emitters' trails are drawn (`render.trails`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Trails {
    /// Only the particles.
    #[default]
    None,
    /// The particles, and ribbons between consecutive children of each parent's trail.
    Ribbon,
}

fn no_trails(t: &Trails) -> bool {
    *t == Trails::None
}

fn unlit(l: &Lighting) -> bool {
    *l == Lighting::None
}

fn is_zero(v: &f32) -> bool {
    *v == 0.0
}

/// How sorted particles are found for drawing (`render.lookup`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Lookup {
    /// A gather pass copies the state into sorted textures, which the vertex stage reads at
    /// its own index.
    #[default]
    Gather,
    /// No gather: the vertex stage reads the sorted (key, id) texture at its index and fetches
    /// the state at `id` (Latta §3.4.4's index lookup).
    Index,
}

fn is_gather(l: &Lookup) -> bool {
    *l == Lookup::Gather
}

fn is_age(r: &Rotate) -> bool {
    *r == Rotate::Age
}

fn resolution() -> [u32; 2] {
    [512, 512]
}
fn two() -> f32 {
    2.0
}
fn thirtieth() -> f32 {
    1.0 / 30.0
}

impl Default for Render {
    fn default() -> Self {
        Render {
            resolution: resolution(),
            camera: CameraSection::default(),
            mode: DrawMode::default(),
            path: RenderPath::default(),
            primitive: DrawPrimitive::default(),
            stretch: thirtieth(),
            point_size: two(),
            intensity: 1.0,
            blending: Blending::default(),
            color: None,
            size: None,
            rotation: None,
            order: DrawOrder::default(),
            keyframes: Vec::new(),
            sort: SortSection::default(),
            background: [0.0; 3],
            geometry: false,
            rotate: Rotate::Age,
            lighting: Lighting::None,
            slices: thirty_two(),
            light: LightSection::default(),
            lookup: Lookup::Gather,
            soft: 0.0,
            trails: Trails::None,
            ribbon_width: None,
        }
    }
}
