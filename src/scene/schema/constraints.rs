//! `[constraints]`: distance constraints between particles of the state texture (Latta §3.4.3:
//! "other constraints can be used to limit the distance between a pair or group of particles,
//! which is useful for particle simulation of cloth or hair").

use serde::{Deserialize, Serialize};

/// Which texels a constraint joins.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ConstraintKind {
    /// A sheet: every texel joined to its four grid neighbours (structural) and its four
    /// diagonal ones (shear).
    Cloth,
    /// Strands: every row is a chain, texel 0 its root.
    Hair,
}

/// `[constraints]`: the layout of the constrained particles (it places every particle, in place
/// of emitters) and the relaxation that keeps their distances.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Constraints {
    /// `cloth` or `hair`.
    pub kind: ConstraintKind,
    /// Relaxation passes per time step (1 to 64).
    #[serde(default = "four")]
    pub iterations: u32,
    /// Share of the averaged correction applied per pass, in (0, 1].
    #[serde(default = "super::one")]
    pub stiffness: f32,
    /// Distance between neighbouring texels in the initial layout (m): the structural rest
    /// length (diagonals: the layout's diagonal).
    pub spacing: f32,
    /// Cloth: position of texel (0, 0).
    #[serde(default)]
    pub origin: [f32; 3],
    /// Cloth: direction of increasing texel x.
    #[serde(default = "x_axis")]
    pub u: [f32; 3],
    /// Cloth: direction of increasing texel y.
    #[serde(default = "z_axis")]
    pub v: [f32; 3],
    /// Texels `[x, y]` held where the layout puts them (hair: every root is held).
    #[serde(default)]
    pub pinned: Vec<[u32; 2]>,
    /// Hair: the `[[colliders.sphere]]` (index) the roots sit on; they follow its orbit.
    pub root_sphere: Option<usize>,
}

fn four() -> u32 {
    4
}
fn x_axis() -> [f32; 3] {
    [1.0, 0.0, 0.0]
}
fn z_axis() -> [f32; 3] {
    [0.0, 0.0, 1.0]
}

/// Most relaxation passes per step.
pub const MAX_CONSTRAINT_ITERATIONS: u32 = 64;
