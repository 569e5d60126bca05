//! Neighbour forces over the sorted grid (UberFlow §6): the penalty response of
//! `[collisions] response = "dem"` and the user's `[[forces.pair]]` hooks, both fed by the exact
//! detection's search of the 27 cells around each particle.

use serde::{Deserialize, Serialize};

/// `collisions.response`: what the exact detection's pairs do to each other.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Response {
    /// UberFlow §4.5: back-tracking to contact and a momentum exchange (an impulse), then the
    /// separation of what still overlaps.
    #[default]
    Impulse,
    /// The discrete-element contact force of NVIDIA's CUDA `particles` sample (`collideSpheres`):
    /// spring, dashpot, shear and attraction between overlapping spheres, summed per particle and
    /// added to its velocity (a penalty method: spheres may overlap while the spring pushes).
    Dem,
}

/// `[collisions.dem]`: the contact force of NVIDIA's `collideSpheres`, on particle i from its
/// neighbour j closer than 2 radius (d = x_j - x_i, n = d / |d|, u = v_j - v_i):
/// `F = -spring (2r - |d|) n + damping u + shear (u - (u·n) n) + attraction d`.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Dem {
    /// Normal stiffness (N/m).
    pub spring: f32,
    /// Dashpot on the whole relative velocity (kg/s).
    #[serde(default)]
    pub damping: f32,
    /// Extra damping of the tangential relative velocity (kg/s).
    #[serde(default)]
    pub shear: f32,
    /// Pull towards the neighbour in contact, per metre of distance (N/m).
    #[serde(default)]
    pub attraction: f32,
}

/// Most `[[forces.pair]]` of one scene.
pub const MAX_PAIR_FORCES: usize = 4;

/// A user pair force (`[[forces.pair]]`): a GLSL file defining
/// `vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, vec3 vj, int type_j,
/// float mass_j, float distance)`, the force in N on a particle (x, v, type, mass) from one
/// neighbour (xj, vj, type_j, mass_j) at `distance` < `radius`. It is called for every such
/// neighbour the exact detection finds, the results are summed, divided by the mass and added
/// to the velocity once per step. Needs `[collisions] detection = "exact"`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct PairForce {
    /// The file, relative to the scene file.
    pub glsl: String,
    /// Neighbours closer than this (m) are passed; at most the collision cell (default 2
    /// collision radius), the reach of the search.
    pub radius: f32,
    /// The file's text, once read and checked ([`crate::scene::load_custom`]).
    #[serde(skip)]
    pub source: Option<String>,
}
