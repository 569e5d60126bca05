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

/// How the relaxation passes solve the distance constraints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RelaxScheme {
    /// Every texel moves by the mean of its constraints' corrections, all texels at once (one
    /// pass per iteration).
    Jacobi,
    /// Constraints in sets that share no particle (graph colouring: 8 sets for cloth, 2 for
    /// hair), one set per pass, each seeing the last set's result (Gauss-Seidel).
    #[default]
    GaussSeidel,
}

impl RelaxScheme {
    /// The key's value in a scene file.
    pub fn name(self) -> &'static str {
        match self {
            RelaxScheme::Jacobi => "jacobi",
            RelaxScheme::GaussSeidel => "gauss-seidel",
        }
    }
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
    /// `gauss-seidel` (sets of constraints that share no particle, one per pass) or `jacobi`
    /// (every texel by the mean of its corrections).
    #[serde(default)]
    pub scheme: RelaxScheme,
    /// Long-range attachments (Kim, Chentanez, Müller-Fischer 2012): after each iteration's
    /// edge passes, one pass keeps every free particle within its rest distance of the pins
    /// (cloth: every pinned texel; hair: its strand's root).
    #[serde(default = "yes")]
    pub attachments: bool,
    /// Relative stretch past which an edge counts as overstretched in the run's census
    /// (`(length - rest) / rest`; 0.1 is 10 %).
    #[serde(default = "tenth")]
    pub stretch_bound: f32,
    /// Share of a pass's correction applied (Jacobi: of the averaged one), in (0, 1].
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
    /// Texels `[x, y]` held where the layout puts them (hair: every root is held). A negative
    /// coordinate counts from the far side (`-1` is the last column or row), so a pin stays at
    /// its corner when the state texture is resized.
    #[serde(default)]
    pub pinned: Vec<[i64; 2]>,
    /// Hair: the `[[colliders.sphere]]` (index) the roots sit on; they follow its orbit.
    pub root_sphere: Option<usize>,
}

fn four() -> u32 {
    4
}
fn yes() -> bool {
    true
}
fn tenth() -> f32 {
    0.1
}
fn x_axis() -> [f32; 3] {
    [1.0, 0.0, 0.0]
}
fn z_axis() -> [f32; 3] {
    [0.0, 0.0, 1.0]
}

/// Most relaxation passes per step.
pub const MAX_CONSTRAINT_ITERATIONS: u32 = 64;

impl Constraints {
    /// The texels [`pinned`](Self::pinned) names in a `size` state texture (negative coordinates
    /// counted from the far side), or `None` for one outside it.
    pub fn pinned_texel(p: [i64; 2], size: [u32; 2]) -> Option<[u32; 2]> {
        let at = |c: i64, n: u32| {
            let c = if c < 0 { c + n as i64 } else { c };
            (0..n as i64).contains(&c).then_some(c as u32)
        };
        Some([at(p[0], size[0])?, at(p[1], size[1])?])
    }
}
