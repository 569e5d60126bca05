//! What the one GPU engine asks of a simulation, whichever model it runs: the particle pipeline
//! of UberFlow and Latta ([`ParticleSim`](super::ParticleSim)) or the thesis's fire
//! ([`FireSim`](super::FireSim)). The engine steps it, sorts and draws its state textures, and
//! counts what it reports; it never needs to know which model it holds.

use crate::error::Result;
use crate::gl::{Context, Texture};
use crate::scene::SceneFile;

use super::nonfinite::{NonFiniteCount, NonFiniteCounter};
use super::{DistanceField, HeightField};

/// The state textures a frame is drawn from, in the renderer's layout (see
/// `glsl/render/particle.vert`): particle `i` is texel `(i % width, i / width)` of each.
#[derive(Debug, Clone, Copy)]
pub struct DrawnState<'a> {
    /// xyz position, w remaining life.
    pub positions: &'a Texture,
    /// The per-particle data the renderer colours by: the particle pipeline's statics (birth
    /// time, type, total life, random number), or the fire's velocities, whose w is the wait
    /// that, with the cycle length, gives the particle's total life.
    pub statics: &'a Texture,
    /// Velocities (xyz), where the model keeps them.
    pub velocities: Option<&'a Texture>,
    /// Verlet's previous positions, where the model integrates with Verlet.
    pub previous: Option<&'a Texture>,
    /// Spinning spheres' spins.
    pub spins: Option<&'a Texture>,
    /// Particles `0..count` may be alive; the rest of the texture is never drawn.
    pub count: usize,
}

/// The parts of a step, in the order a step runs them. Each runs alone through
/// [`Simulation::run`]: a step is its passes' stages run in order, and the benchmarks time the
/// same stages one by one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Stage {
    /// The allocator's births: new particles drawn as single pixels (Latta §3.2).
    Births,
    /// The integration pass (or its velocity and position halves): forces, colliders, time-stamp
    /// birth and death, children (UberFlow §4.1-4.2, Latta §3.1, the thesis's fire).
    Integrate,
    /// The constraint relaxation after the Verlet step (Latta §3.4.3).
    Relax,
    /// The collision stage between particles: sorts, detection, response or neighbour forces
    /// (UberFlow §4.3-4.5, §6).
    Collide,
}

impl Stage {
    /// The stage's name in pass lists and phase tables (its serialized name too).
    pub fn label(self) -> &'static str {
        match self {
            Stage::Births => "births",
            Stage::Integrate => "integrate",
            Stage::Relax => "relax",
            Stage::Collide => "collide",
        }
    }
}

/// One pass, or one group of like passes, of a step: its stage and what it does in the
/// papers' words (with their sections).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Pass {
    /// The stage that runs it.
    pub stage: Stage,
    /// What it does, what it reads and writes.
    pub name: String,
}

/// The stages of `passes`, each once, in order.
pub fn stages_of(passes: &[Pass]) -> Vec<Stage> {
    let mut out: Vec<Stage> = Vec::new();
    for p in passes {
        if !out.contains(&p.stage) {
            out.push(p.stage);
        }
    }
    out
}

/// A particle model whose state lives in textures and changes only by fragment passes.
pub trait Simulation: std::fmt::Debug {
    /// Builds the model `scene` describes on `ctx`, its random streams from `seed`.
    fn from_scene(ctx: &Context, scene: &SceneFile, seed: u32) -> Result<Self>
    where
        Self: Sized;

    /// Runs `stage` of one step alone (the integration advances the clock). A stage the model
    /// does not have is an error.
    fn run(&mut self, stage: Stage) -> Result<()>;

    /// The stages of [`passes`](Self::passes), each once, in order (a model may keep them, so
    /// that a step does not word its passes again).
    fn stages(&self) -> Vec<Stage> {
        stages_of(&self.passes())
    }

    /// One time step of the scene's `dt`: the stages of [`passes`](Self::passes), in order.
    fn step(&mut self) -> Result<()> {
        for stage in self.stages() {
            self.run(stage)?;
        }
        Ok(())
    }

    /// One step without the collision stage between particles: the collisionless motion, what
    /// a benchmark's warm-up runs (the stage's sorts and searches are data-oblivious, so what
    /// they cost later does not depend on it).
    fn step_without_collisions(&mut self) -> Result<()> {
        for stage in self.stages() {
            if stage != Stage::Collide {
                self.run(stage)?;
            }
        }
        Ok(())
    }

    /// Steps taken.
    fn steps(&self) -> u64;

    /// Simulated seconds since the start.
    fn time(&self) -> f64;

    /// The time step in seconds.
    fn time_step(&self) -> f32;

    /// Steps per rendered frame.
    fn substeps(&self) -> u32;

    /// State texture size: one particle per texel.
    fn size(&self) -> [u32; 2];

    /// The textures a frame is drawn from.
    fn drawn(&self) -> DrawnState<'_>;

    /// Positions and velocities read back, RGBA each, for dumps (the fire's velocity w is its
    /// wait; callers keep xyz).
    fn read_state(&self) -> Result<(Vec<f32>, Vec<f32>)>;

    /// The other state textures read back, 4 floats per texel each, by the name a dump gives
    /// them: the static texture (`statics`: birth time or phase, type, total life, random), the
    /// previous positions of Verlet (`previous`), the spins (`spins`: ω xyz, angle about z), the
    /// user's states (`state_NAME`, `[[state]]`).
    fn read_more(&self) -> Result<Vec<(&'static str, Vec<f32>)>> {
        Ok(Vec::new())
    }

    /// The user's own states (`[[state]]`), in the order of the scene's tables.
    fn user_states(&self) -> Vec<&Texture> {
        Vec::new()
    }

    /// Live particles with a NaN or infinite component, counted on the GPU by `counter`.
    fn non_finite(&self, counter: &NonFiniteCounter) -> Result<NonFiniteCount> {
        let d = self.drawn();
        counter.count(d.positions, d.velocities.or(d.previous))
    }

    /// Births dropped because the state was full (models that allocate).
    fn dropped_births(&self) -> u64 {
        0
    }

    /// Child emitters' births their texels could not take (one read-back, for a run's end).
    fn dropped_child_births(&self) -> Result<u64> {
        Ok(0)
    }

    /// Exact collision searches that hit their bound (one read-back, for a run's end).
    fn truncated_searches(&self) -> Result<u64> {
        Ok(0)
    }

    /// With distance constraints: the constraints stretched past the scene's `stretch_bound`
    /// and how many there are (one read-back of the positions).
    fn stretched(&self) -> Result<Option<super::Stretched>> {
        Ok(None)
    }

    /// Paths that still entered a collider after the bound on bounces per step (one read-back,
    /// for a run's end).
    fn truncated_bounces(&self) -> Result<u64> {
        Ok(0)
    }

    /// With `[fluid]`: the density error and energy now (read-backs, once per written frame).
    fn fluid_stats(&self) -> Result<Option<super::fluid::FluidStats>> {
        Ok(None)
    }

    /// With collisions between particles: the pairs the last step's detection found.
    fn census(&self) -> Result<Option<super::collide::PairCensus>> {
        Ok(None)
    }

    /// The height field, for drawing the terrain under the particles.
    fn height_field(&self) -> Option<&HeightField> {
        None
    }

    /// The distance field the colliders sample, for drawing its surface.
    fn distance_field(&self) -> Option<&DistanceField> {
        None
    }

    /// The passes of one step, in order, in the papers' words, made from what the model
    /// compiled: what a step runs, what `texflow scene passes` prints and what the benchmarks
    /// time.
    fn passes(&self) -> Vec<Pass>;

    /// The state framebuffer a step reads now: its formats and size are what the step's
    /// passes write (the benchmarks' floors write the same).
    fn state_target(&self) -> &crate::gl::Framebuffer;

    /// The collision stage between particles, where the model has one (`texflow trace`
    /// pictures its lattice and partners).
    fn collision_stage(&self) -> Option<&super::collide::CollisionStage> {
        None
    }
    /// The passes of one step with the programs each draws per step (`texflow scene passes`,
    /// checked against the draws of a frame by tests/pass_list.rs).
    fn pass_list(&self) -> Vec<crate::gl::PassInfo>;
}
