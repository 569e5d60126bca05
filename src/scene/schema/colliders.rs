//! `[colliders]`: what particles bounce off, one kind per array table.
//!
//! [`ColliderKind`] names the kinds and [`Collider`] views one collider of any kind: the GPU
//! packing (`src/sim/params/`), the CPU twin (`src/sim/reference/`), the validation, the plan's
//! wording and the drawn geometry (`src/render/geometry.rs`) each match on them without a
//! catch-all arm, so a new kind makes the compiler list every place to fill.

use serde::{Deserialize, Serialize};

use super::{one, FieldData, Wall};

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
    /// With `[fluid]`: the velocity of the fluid's ghosts in this plane, mirrored
    /// (`"free_slip"`, default: a symmetry plane) or reversed (`"no_slip"`: a wall at rest).
    #[serde(default)]
    pub wall: Wall,
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

/// The kinds of collider, in the order the integration pass tests them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum ColliderKind {
    /// `[[colliders.plane]]`.
    Plane,
    /// `[[colliders.sphere]]`.
    Sphere,
    /// `[[colliders.box]]`.
    Box,
    /// `[[colliders.heightfield]]`.
    HeightField,
    /// `[[colliders.sdf]]`.
    Sdf,
}

impl ColliderKind {
    /// Every kind, in the order the integration pass tests them (a new kind: add it here and in
    /// [`ColliderKind::position`]).
    pub const ALL: [ColliderKind; 5] = [
        ColliderKind::Plane,
        ColliderKind::Sphere,
        ColliderKind::Box,
        ColliderKind::HeightField,
        ColliderKind::Sdf,
    ];

    /// Its place in [`ColliderKind::ALL`].
    pub fn position(self) -> usize {
        match self {
            ColliderKind::Plane => 0,
            ColliderKind::Sphere => 1,
            ColliderKind::Box => 2,
            ColliderKind::HeightField => 3,
            ColliderKind::Sdf => 4,
        }
    }

    /// The kind's key in `[[colliders.KEY]]`.
    pub fn key(self) -> &'static str {
        match self {
            ColliderKind::Plane => "plane",
            ColliderKind::Sphere => "sphere",
            ColliderKind::Box => "box",
            ColliderKind::HeightField => "heightfield",
            ColliderKind::Sdf => "sdf",
        }
    }

    /// The kind in words, for plans and messages.
    pub fn noun(self) -> &'static str {
        match self {
            ColliderKind::Plane => "plane",
            ColliderKind::Sphere => "sphere",
            ColliderKind::Box => "box",
            ColliderKind::HeightField => "height field",
            ColliderKind::Sdf => "distance field",
        }
    }

    /// Whether a particle's path is replayed against it after a response (`bounce_on` in
    /// `glsl/sim/colliders.glsl`): the analytic shapes.
    pub fn bounces(self) -> bool {
        match self {
            ColliderKind::Plane | ColliderKind::Sphere | ColliderKind::Box => true,
            ColliderKind::HeightField | ColliderKind::Sdf => false,
        }
    }

    /// Whether the integration pass reads at most one of this kind (a texture of its own).
    pub fn single(self) -> bool {
        match self {
            ColliderKind::Plane | ColliderKind::Sphere | ColliderKind::Box => false,
            ColliderKind::HeightField | ColliderKind::Sdf => true,
        }
    }
}

/// One collider of any kind, borrowed from [`Colliders`].
#[derive(Debug, Clone, Copy)]
pub enum Collider<'a> {
    /// A plane.
    Plane(&'a PlaneCollider),
    /// A sphere.
    Sphere(&'a SphereCollider),
    /// An axis-aligned box.
    Box(&'a BoxCollider),
    /// A height field.
    HeightField(&'a HeightFieldCollider),
    /// A signed distance field.
    Sdf(&'a SdfCollider),
}

impl Collider<'_> {
    /// Its kind.
    pub fn kind(&self) -> ColliderKind {
        match self {
            Collider::Plane(_) => ColliderKind::Plane,
            Collider::Sphere(_) => ColliderKind::Sphere,
            Collider::Box(_) => ColliderKind::Box,
            Collider::HeightField(_) => ColliderKind::HeightField,
            Collider::Sdf(_) => ColliderKind::Sdf,
        }
    }

    /// Latta's response (eq. 5): `[friction μ, resilience ε]`.
    pub fn response(&self) -> [f32; 2] {
        match self {
            Collider::Plane(c) => [c.friction, c.resilience],
            Collider::Sphere(c) => [c.friction, c.resilience],
            Collider::Box(c) => [c.friction, c.resilience],
            Collider::HeightField(c) => [c.friction, c.resilience],
            Collider::Sdf(c) => [c.friction, c.resilience],
        }
    }
}

impl Colliders {
    /// How many colliders of `kind` the scene has.
    pub fn count(&self, kind: ColliderKind) -> usize {
        match kind {
            ColliderKind::Plane => self.plane.len(),
            ColliderKind::Sphere => self.sphere.len(),
            ColliderKind::Box => self.boxes.len(),
            ColliderKind::HeightField => self.heightfield.len(),
            ColliderKind::Sdf => self.sdf.len(),
        }
    }

    /// Whether the scene has no collider.
    pub fn is_empty(&self) -> bool {
        ColliderKind::ALL.iter().all(|&k| self.count(k) == 0)
    }

    /// Every collider, kind by kind in [`ColliderKind::ALL`]'s order, each kind in scene order.
    pub fn iter(&self) -> impl Iterator<Item = Collider<'_>> {
        ColliderKind::ALL.into_iter().flat_map(move |k| self.of(k))
    }

    /// Every collider with its index among those of its kind (`[[colliders.KEY]]` number `i`),
    /// in [`Colliders::iter`]'s order.
    pub fn indexed(&self) -> impl Iterator<Item = (usize, Collider<'_>)> {
        ColliderKind::ALL
            .into_iter()
            .flat_map(move |k| self.of(k).enumerate())
    }

    /// The colliders of `kind`, in scene order.
    pub fn of(&self, kind: ColliderKind) -> Box<dyn Iterator<Item = Collider<'_>> + '_> {
        match kind {
            ColliderKind::Plane => Box::new(self.plane.iter().map(Collider::Plane)),
            ColliderKind::Sphere => Box::new(self.sphere.iter().map(Collider::Sphere)),
            ColliderKind::Box => Box::new(self.boxes.iter().map(Collider::Box)),
            ColliderKind::HeightField => {
                Box::new(self.heightfield.iter().map(Collider::HeightField))
            }
            ColliderKind::Sdf => Box::new(self.sdf.iter().map(Collider::Sdf)),
        }
    }
}

/// How many colliders of each kind a scene has (what the integration pass compiles for).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize)]
pub struct ColliderCounts([usize; ColliderKind::ALL.len()]);

impl ColliderCounts {
    /// The counts of `c`.
    pub fn of(c: &Colliders) -> Self {
        ColliderCounts(ColliderKind::ALL.map(|k| c.count(k)))
    }

    /// How many of `kind`.
    pub fn get(&self, kind: ColliderKind) -> usize {
        self.0[kind.position()]
    }

    /// Whether there is any collider.
    pub fn any(&self) -> bool {
        self.0.iter().any(|&n| n > 0)
    }

    /// Whether there is any collider whose paths are replayed after a response
    /// ([`ColliderKind::bounces`]).
    pub fn any_bouncing(&self) -> bool {
        ColliderKind::ALL
            .iter()
            .any(|&k| k.bounces() && self.get(k) > 0)
    }
}

#[cfg(test)]
mod tests {
    use super::ColliderKind;

    #[test]
    fn all_lists_every_kind_at_its_position() {
        for (i, k) in ColliderKind::ALL.into_iter().enumerate() {
            assert_eq!(k.position(), i, "{k:?}");
        }
    }
}
