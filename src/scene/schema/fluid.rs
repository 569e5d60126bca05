//! `[fluid]`: weakly compressible SPH (Monaghan 1992, 2005; Becker & Teschner 2007) over the
//! cell-sorted state (UberFlow §6: "any physical model that requires access to adjacent
//! particles"). The section sets up its own exact neighbour search: a lattice over `bounds` of
//! cell h (half the kernel's support) for a large fluid or 2h for a small one (`cell`), sorted
//! and searched as `[collisions] detection = "exact"` does (on cells of h only the cells within
//! 2h of a particle are walked).

use serde::{Deserialize, Serialize};

fn water() -> f32 {
    1000.0
}
fn tait() -> f32 {
    7.0
}
fn yes() -> bool {
    true
}

/// `[fluid]`: the fluid's material and discretisation. Every particle is one fluid particle of
/// mass `rest_density · spacing³`; initial box emitters are filled on a cubic lattice of
/// `spacing`.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Fluid {
    /// Rest density ρ0 (kg/m³); default 1000 (water).
    #[serde(default = "water")]
    pub rest_density: f32,
    /// Numerical speed of sound c (m/s): the Tait stiffness is B = ρ0 c² / γ. At least ten
    /// times the fastest flow keeps the density within about 1 % of ρ0.
    pub speed_of_sound: f32,
    /// Tait exponent γ: p = B ((ρ/ρ0)^γ − 1); default 7 (Becker & Teschner); 1 gives the linear
    /// p = c² (ρ − ρ0).
    #[serde(default = "tait")]
    pub gamma: f32,
    /// Monaghan's artificial viscosity α (dimensionless, Becker & Teschner eq. 11); 0: none.
    #[serde(default)]
    pub viscosity: f32,
    /// Particle spacing Δx (m): the lattice initial box emitters are filled on, and with
    /// `rest_density` the particle mass.
    pub spacing: f32,
    /// Smoothing length h (m) of the cubic spline kernel, whose support is 2h (the neighbour
    /// lattice's cell); default `spacing`, at most 1.5 `spacing`.
    pub smoothing: Option<f32>,
    /// Region the neighbour lattice covers: [min corner, max corner]; outside, cells clamp.
    pub bounds: [[f32; 3]; 2],
    /// The wall treatment at plane colliders: ghost particles, the reflections of a particle's
    /// neighbours in each plane closer than 2h, in its density and forces (docs/scenes.md);
    /// default on.
    #[serde(default = "yes")]
    pub wall_correction: bool,
    /// The initial state of the fluid in box emitters: `"uniform"` (default) every particle on
    /// the cubic lattice at ρ0, no pressure; `"hydrostatic"` each box a column at rest, its
    /// layers closer together with depth so that Tait's pressure is the weight above them
    /// (gravity along −y).
    #[serde(default)]
    pub initial: Initial,
    /// How each step re-sorts the particles by cell (Latta §3.4.4's frame coherence):
    /// `"full"` (default) the whole sort; `"coherent"` a cheaper network for a nearly sorted
    /// state, checked, with the full sort whenever the check finds an entry out of order.
    #[serde(default)]
    pub resort: Resort,
    /// With `resort = "coherent"`: entries of the aligned blocks the cheap network sorts
    /// (a power of two from the particle texture's width to half its entries); it is exact
    /// when no entry lies more than half a block from its sorted place. Default two rows.
    pub resort_block: Option<u32>,
    /// The neighbour lattice's cell: `"auto"` (default) h for a fluid of at least
    /// [`FINE_CELL_PARTICLES`] particles, else 2h; `"h"` or `"2h"` to choose.
    #[serde(default)]
    pub cell: FluidCell,
}

/// Fluid particles from which `cell = "auto"` takes cells of h: a large fluid is bound by the
/// particles its searches visit (half as many with cells of h), a small one by each search's
/// chain of runs (fewer with cells of 2h). On an NVIDIA H100 the million-particle dam's fluid
/// stage took 0.70 of its time with cells of h, the 8,192-particle `drop` 1.3 times as long.
pub const FINE_CELL_PARTICLES: u64 = 1 << 18;

/// `fluid.cell`: the neighbour lattice's cell.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum FluidCell {
    /// h from [`FINE_CELL_PARTICLES`] particles on, else 2h.
    #[default]
    #[serde(rename = "auto")]
    Auto,
    /// The smoothing length h: the cells within 2h of a particle, about 84 h³, are walked.
    #[serde(rename = "h")]
    H,
    /// 2h, the kernel's support: the 27 cells around a particle's, 216 h³, are walked.
    #[serde(rename = "2h")]
    TwoH,
}

/// Texels of initial emitter `k` of `kinds` among `texels`: those of rank k modulo the emitters.
pub fn emitter_texels(texels: u64, kinds: u64, k: u64) -> u64 {
    (texels + kinds - 1 - k) / kinds
}

/// The particles `[fluid]` places: each initial box emitter's lattice points, at most its
/// texels (`emitter_texels`); 0 without `[fluid]`.
pub fn fluid_particles(s: &super::SceneFile) -> u64 {
    let Some(f) = &s.fluid else {
        return 0;
    };
    let texels = s.particles.size[0] as u64 * s.particles.size[1] as u64;
    let kinds = s.emitters.initial.len().max(1) as u64;
    (s.emitters.initial.iter().enumerate())
        .map(|(k, e)| {
            let n = f.box_points(e.size);
            let points = (n.iter()).fold(1u64, |p, &a| p.saturating_mul(a as u64));
            points.min(emitter_texels(texels, kinds, k as u64))
        })
        .sum()
}

/// `colliders.plane.wall`: the velocity of the fluid's ghosts in a plane collider.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Wall {
    /// Mirrored in the plane: only the normal component reversed (the plane takes no
    /// tangential force: a symmetry plane).
    #[default]
    FreeSlip,
    /// Reversed: the ghost moves against the particle, as across a wall at rest. The artificial
    /// viscosity acts where particles approach their neighbours' ghosts, which then drag the
    /// fluid along the wall (a particle's own ghost, straight across, adds none along it).
    NoSlip,
}

/// `fluid.initial`: the density the box emitters' lattice starts at.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Initial {
    /// The cubic lattice of `spacing`: density ρ0, no pressure.
    #[default]
    Uniform,
    /// Layers compressed along gravity to the hydrostatic density of their depth.
    Hydrostatic,
}

/// `fluid.resort`: the full sort every step, or the coherent re-sort with its check.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Resort {
    /// The whole blocked sort every step.
    #[default]
    Full,
    /// Blocks of `resort_block` sorted, the blocks at half a block's offset merged, the order
    /// checked; the full sort when the check fails.
    Coherent,
}

impl Fluid {
    /// The smoothing length h (m).
    pub fn h(&self) -> f32 {
        self.smoothing.unwrap_or(self.spacing)
    }

    /// Whether the neighbour lattice of a fluid of `particles` particles has cells of h (else
    /// 2h), as `cell` says.
    pub fn fine_cell(&self, particles: u64) -> bool {
        match self.cell {
            FluidCell::Auto => particles >= FINE_CELL_PARTICLES,
            FluidCell::H => true,
            FluidCell::TwoH => false,
        }
    }

    /// The neighbour lattice's cell (m) for a fluid of `particles` particles (`cell`).
    pub fn cell_size(&self, particles: u64) -> f32 {
        if self.fine_cell(particles) {
            self.h()
        } else {
            2.0 * self.h()
        }
    }

    /// Cells per axis of the neighbour lattice of cell `g` over `bounds` (at least one each).
    pub fn lattice_dims(&self, g: f32) -> [u32; 3] {
        std::array::from_fn(|k| {
            ((self.bounds[1][k] - self.bounds[0][k]) / g)
                .ceil()
                .max(1.0) as u32
        })
    }

    /// Lattice points per axis of an initial box emitter of `size` filled at `spacing`.
    pub fn box_points(&self, size: [f32; 3]) -> [u32; 3] {
        std::array::from_fn(|k| (size[k] / self.spacing + 1e-3).floor().max(0.0) as u32)
    }

    /// The particle mass ρ0 Δx³ (kg).
    pub fn mass(&self) -> f32 {
        self.rest_density * self.spacing.powi(3)
    }

    /// Tait's stiffness B = ρ0 c² / γ (Pa).
    pub fn stiffness(&self) -> f32 {
        self.rest_density * self.speed_of_sound.powi(2) / self.gamma
    }
}
