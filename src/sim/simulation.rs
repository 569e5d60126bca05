//! What the one GPU engine asks of a simulation, whichever model it runs: the particle pipeline
//! of UberFlow and Latta ([`ParticleSim`](super::ParticleSim)) or the thesis's fire
//! ([`FireSim`](super::FireSim)). The engine steps it, sorts and draws its state textures, and
//! counts what it reports; it never needs to know which model it holds.

use crate::error::Result;
use crate::gl::{Context, Texture};
use crate::scene::SceneFile;

use super::nonfinite::{NonFiniteCount, NonFiniteCounter};
use super::HeightField;

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

/// A particle model whose state lives in textures and changes only by fragment passes.
pub trait Simulation: std::fmt::Debug {
    /// Builds the model `scene` describes on `ctx`, its random streams from `seed`.
    fn from_scene(ctx: &Context, scene: &SceneFile, seed: u32) -> Result<Self>
    where
        Self: Sized;

    /// One time step of the scene's `dt`.
    fn step(&mut self) -> Result<()>;

    /// One step without the collision stage between particles: the collisionless motion, what
    /// a benchmark's warm-up runs (the stage's sorts and searches are data-oblivious, so what
    /// they cost later does not depend on it). The same as [`step`](Self::step) for models
    /// without one.
    fn step_without_collisions(&mut self) -> Result<()> {
        self.step()
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

    /// With collisions between particles: the pairs the last step's detection found.
    fn census(&self) -> Result<Option<super::collide::PairCensus>> {
        Ok(None)
    }

    /// The height field, for drawing the terrain under the particles.
    fn height_field(&self) -> Option<&HeightField> {
        None
    }

    /// The passes of one step, in order, in the papers' words, made from what the model
    /// compiled: what `texflow scene passes` prints.
    fn passes(&self) -> Vec<String>;
}
