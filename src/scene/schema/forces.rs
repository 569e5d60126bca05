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

/// The kinds of force, in the order the integration pass adds them (`glsl/sim/forces.glsl`;
/// the pair forces run in the collision stage).
///
/// A new kind: add it here, in [`ForceKind::ALL`] and the matches the compiler then lists (the
/// GPU packing in `src/sim/params/`, the defines and the plan's wording in
/// `src/sim/particles/features.rs`, the validation, the CPU twin in `src/sim/reference/`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum ForceKind {
    /// `[[forces.gravity]]`.
    Gravity,
    /// `[[forces.damping]]`.
    Damping,
    /// `[[forces.wind]]`.
    Wind,
    /// `[[forces.attractor]]`.
    Attractor,
    /// `[[forces.spring]]`.
    Spring,
    /// `[[forces.vortex]]`.
    Vortex,
    /// `[[forces.custom]]`.
    Custom,
    /// `[[forces.pair]]`.
    Pair,
}

impl ForceKind {
    /// Every kind, in the order the integration pass adds them (a new kind: add it here and in
    /// [`ForceKind::position`]).
    pub const ALL: [ForceKind; 8] = [
        ForceKind::Gravity,
        ForceKind::Damping,
        ForceKind::Wind,
        ForceKind::Attractor,
        ForceKind::Spring,
        ForceKind::Vortex,
        ForceKind::Custom,
        ForceKind::Pair,
    ];

    /// Its place in [`ForceKind::ALL`].
    pub fn position(self) -> usize {
        match self {
            ForceKind::Gravity => 0,
            ForceKind::Damping => 1,
            ForceKind::Wind => 2,
            ForceKind::Attractor => 3,
            ForceKind::Spring => 4,
            ForceKind::Vortex => 5,
            ForceKind::Custom => 6,
            ForceKind::Pair => 7,
        }
    }

    /// The kind's key in `[[forces.KEY]]`.
    pub fn key(self) -> &'static str {
        match self {
            ForceKind::Gravity => "gravity",
            ForceKind::Damping => "damping",
            ForceKind::Wind => "wind",
            ForceKind::Attractor => "attractor",
            ForceKind::Spring => "spring",
            ForceKind::Vortex => "vortex",
            ForceKind::Custom => "custom",
            ForceKind::Pair => "pair",
        }
    }
}

/// One force of any kind, borrowed from [`Forces`].
#[derive(Debug, Clone, Copy)]
pub enum Force<'a> {
    /// Uniform acceleration.
    Gravity(&'a Gravity),
    /// Linear damping.
    Damping(&'a Damping),
    /// Wind from a flow field.
    Wind(&'a Wind),
    /// A point attractor or repulsor.
    Attractor(&'a Attractor),
    /// A linear spring.
    Spring(&'a Spring),
    /// A vortex.
    Vortex(&'a Vortex),
    /// A user GLSL force.
    Custom(&'a CustomForce),
    /// A user GLSL force between neighbours.
    Pair(&'a super::PairForce),
}

impl Force<'_> {
    /// Its kind.
    pub fn kind(&self) -> ForceKind {
        match self {
            Force::Gravity(_) => ForceKind::Gravity,
            Force::Damping(_) => ForceKind::Damping,
            Force::Wind(_) => ForceKind::Wind,
            Force::Attractor(_) => ForceKind::Attractor,
            Force::Spring(_) => ForceKind::Spring,
            Force::Vortex(_) => ForceKind::Vortex,
            Force::Custom(_) => ForceKind::Custom,
            Force::Pair(_) => ForceKind::Pair,
        }
    }
}

impl Forces {
    /// How many forces of `kind` the list has.
    pub fn count(&self, kind: ForceKind) -> usize {
        match kind {
            ForceKind::Gravity => self.gravity.len(),
            ForceKind::Damping => self.damping.len(),
            ForceKind::Wind => self.wind.len(),
            ForceKind::Attractor => self.attractor.len(),
            ForceKind::Spring => self.spring.len(),
            ForceKind::Vortex => self.vortex.len(),
            ForceKind::Custom => self.custom.len(),
            ForceKind::Pair => self.pair.len(),
        }
    }

    /// Every force, kind by kind in [`ForceKind::ALL`]'s order, each kind in scene order.
    pub fn iter(&self) -> impl Iterator<Item = Force<'_>> {
        ForceKind::ALL.into_iter().flat_map(move |k| self.of(k))
    }

    /// Every force with its index among those of its kind (`[[forces.KEY]]` number `i`), in
    /// [`Forces::iter`]'s order.
    pub fn indexed(&self) -> impl Iterator<Item = (usize, Force<'_>)> {
        ForceKind::ALL
            .into_iter()
            .flat_map(move |k| self.of(k).enumerate())
    }

    /// The forces of `kind`, in scene order.
    pub fn of(&self, kind: ForceKind) -> Box<dyn Iterator<Item = Force<'_>> + '_> {
        match kind {
            ForceKind::Gravity => Box::new(self.gravity.iter().map(Force::Gravity)),
            ForceKind::Damping => Box::new(self.damping.iter().map(Force::Damping)),
            ForceKind::Wind => Box::new(self.wind.iter().map(Force::Wind)),
            ForceKind::Attractor => Box::new(self.attractor.iter().map(Force::Attractor)),
            ForceKind::Spring => Box::new(self.spring.iter().map(Force::Spring)),
            ForceKind::Vortex => Box::new(self.vortex.iter().map(Force::Vortex)),
            ForceKind::Custom => Box::new(self.custom.iter().map(Force::Custom)),
            ForceKind::Pair => Box::new(self.pair.iter().map(Force::Pair)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::ForceKind;

    #[test]
    fn all_lists_every_kind_at_its_position() {
        for (i, k) in ForceKind::ALL.into_iter().enumerate() {
            assert_eq!(k.position(), i, "{k:?}");
        }
    }
}
