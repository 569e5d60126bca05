//! `[[state]]`: per-particle state of the user's own, beyond position, velocity and the static
//! texel (three.js's `GPUComputationRenderer.addVariable`; Latta §3.4.2's "other operations in
//! separate passes"; the thesis asks for more than 32 bytes per particle). Each is an RGBA
//! texture, one texel per particle, updated by a full-screen pass of its own after the
//! integration (src/sim/particles/user_state.rs), or with `pass = "integrate"` inside the
//! integration pass (src/sim/particles/user_state_mrt.rs).

use serde::{Deserialize, Serialize};

/// Most `[[state]]` of one scene.
pub const MAX_USER_STATES: usize = 4;

/// Longest GLSL expression of `init` or `update`, in bytes.
pub const MAX_STATE_EXPRESSION: usize = 4000;

/// One user state: a `vec4` per particle with a value at birth and an update per step.
///
/// The expressions are GLSL of type `vec4`. They may read `x` and `v` (the particle's position
/// and velocity after this step's integration, `vec3`), `life` (remaining seconds), `age`
/// (seconds since birth), `type` (`int`), `random` (the particle's number in [0, 1)), `index`
/// (`int`), `time` (the time at the end of the step), `dt`, every user state by its name (the
/// previous step's value, `vec4`), and the functions of `glsl`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct UserState {
    /// The name GLSL reads it by: lower case letters, digits and `_`, starting with a letter.
    pub name: String,
    /// Texel format: `rgba32f` (the default) or `rgba16f` (half floats, Latta §3.3).
    #[serde(default)]
    pub format: StateFormat,
    /// The value at birth (and at the start for particles alive then): a GLSL `vec4`
    /// expression.
    pub init: String,
    /// The value after each step: a GLSL `vec4` expression of the previous values; without it
    /// the state keeps its value at birth.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub update: Option<String>,
    /// Where `update` runs: `own` (the default), a full-screen pass of its own after the
    /// integration; or `integrate`, inside the integration pass, its value written as one more
    /// render target of that pass (a pass and a read of position and velocity fewer, Latta
    /// §3.1's MRT). Both evaluate the same expression of the same inputs (with `rgba16f`
    /// velocities the integrated update rounds them as llvmpipe stores half floats, toward
    /// zero; a driver that rounds to nearest may differ by one half-float step).
    #[serde(default, skip_serializing_if = "StatePassKind::is_own")]
    pub pass: StatePassKind,
    /// The exchange with the neighbours: a GLSL `vec4` expression evaluated for every live
    /// neighbour closer than `radius`, summed and added to the state after the collision sort
    /// of each step (`[collisions]` with the exact detection; src/sim/collide/carry.rs) or
    /// after the fluid's sort (`[fluid]`; src/sim/particles/fluid.rs). It
    /// reads the particle's own inputs and states, the neighbour's as `other.x`,
    /// `other.temperature`, ..., and their distance `r`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pair: Option<String>,
    /// The reach of `pair` (m): above 0, at most the neighbour search's cell (the collision
    /// cell, or the fluid's 2h).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f32>,
    /// A GLSL file of helper functions for the expressions, relative to the scene file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub glsl: Option<String>,
    /// The helper file's text once read and checked ([`crate::scene::load_custom`]).
    #[serde(skip)]
    pub source: Option<String>,
}

/// The texel format of a user state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StateFormat {
    /// Four 32-bit floats.
    #[default]
    Rgba32f,
    /// Four 16-bit floats: up to 65504, about three decimal digits.
    Rgba16f,
}

/// Where a user state's `update` is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StatePassKind {
    /// A full-screen pass of its own after the integration.
    #[default]
    Own,
    /// Inside the integration pass, as a further render target.
    Integrate,
}

impl StatePassKind {
    /// Whether it is the default, `own`.
    pub fn is_own(&self) -> bool {
        *self == StatePassKind::Own
    }
}
