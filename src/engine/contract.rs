//! The one engine trait: what the frame loop, `render`, `view`, every benchmark and the report
//! ask of an engine, whichever runs the scene (the GPU engine over either simulation, or the
//! CPU engine of UberFlow's E5).

use super::{CpuEngine, GpuEngine, ParticleEngine};
use crate::error::Result;
use crate::gl::{Context, PassTimer};
use crate::render::{FrameTarget, ViewOffset};
use crate::scene::SceneFile;
use crate::sim::collide::PairCensus;
use crate::sim::nonfinite::{NonFiniteCount, NonFiniteCounter};

/// The names of the arrays a dump may hold, in the order they are written: each is written as
/// `NAME_NNNNN.npy` (N×4 float32, row i the same particle in each). `positions` (xyz, remaining
/// life) and `velocities` (xyz, 0) always; the other state textures the scene has: `statics`
/// (birth time or phase, type, total life, random number), `previous` (Verlet's previous
/// position and life) and `spins` (angular velocity xyz in rad/s, angle about z in rad).
pub const DUMP_NAMES: [&str; 5] = ["positions", "velocities", "statics", "previous", "spins"];

/// Live particles' state, N×4 each, for `--dump-state`.
#[derive(Debug, Clone, PartialEq)]
pub struct StateDump {
    /// xyz and remaining life of every live particle.
    pub positions: Vec<[f32; 4]>,
    /// Velocity (xyz, 0) of the same particles.
    pub velocities: Vec<[f32; 4]>,
    /// The scene's other state textures for the same particles, by their names in
    /// [`DUMP_NAMES`] (empty where the engine has none to give).
    pub more: Vec<(&'static str, Vec<[f32; 4]>)>,
    /// Live particles with a NaN or infinite component in any of the arrays: kept in the dump,
    /// and counted so that the CLI reports them rather than hiding them.
    pub non_finite: usize,
}

impl StateDump {
    /// The live particles (remaining life above 0) of RGBA position and velocity arrays; the
    /// velocities' w (the fire's wait) is dropped.
    pub fn of_live(positions: &[f32], velocities: &[f32]) -> StateDump {
        Self::of_live_with(positions, velocities, &[])
    }

    /// [`of_live`](Self::of_live), with the same rows of the other state arrays `more`
    /// (RGBA each, by name).
    pub fn of_live_with(
        positions: &[f32],
        velocities: &[f32],
        more: &[(&'static str, Vec<f32>)],
    ) -> StateDump {
        let mut d = StateDump {
            positions: Vec::new(),
            velocities: Vec::new(),
            more: more.iter().map(|(n, _)| (*n, Vec::new())).collect(),
            non_finite: 0,
        };
        let texel = |a: &[f32], i: usize| [a[4 * i], a[4 * i + 1], a[4 * i + 2], a[4 * i + 3]];
        for (i, (p, v)) in positions
            .chunks_exact(4)
            .zip(velocities.chunks_exact(4))
            .enumerate()
        {
            if p[3] > 0.0 {
                let rows: Vec<[f32; 4]> = (more.iter())
                    .filter(|(_, a)| a.len() >= 4 * (i + 1))
                    .map(|(_, a)| texel(a, i))
                    .collect();
                let finite = (p.iter().chain(&v[..3]))
                    .chain(rows.iter().flatten())
                    .all(|x| x.is_finite());
                d.non_finite += usize::from(!finite);
                d.positions.push([p[0], p[1], p[2], p[3]]);
                d.velocities.push([v[0], v[1], v[2], 0.0]);
                for ((_, out), (_, a)) in d.more.iter_mut().zip(more) {
                    if a.len() >= 4 * (i + 1) {
                        out.push(texel(a, i));
                    }
                }
            }
        }
        d
    }
}

/// Which engine runs a scene: the GPU pipeline (the papers'), or the CPU engine UberFlow
/// compares it with (E5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum EngineKind {
    /// The GPU engine: fragment passes over state textures.
    #[default]
    Gpu,
    /// UberFlow's E5: the same physics on every CPU core, a quicksort, points uploaded each
    /// frame (see [`CpuEngine`]).
    Cpu,
}

/// A scene being run: frames simulated, ordered and drawn. Everything above the engines holds
/// a `Box<dyn Engine>` made by [`build`].
///
/// ```
/// use texflow::{engine, gl::Context, scene};
/// let ctx = Context::new(0)?;
/// for name in ["fire", "fountain"] {
///     let mut s = scene::load(name)?;
///     s.particles.size = [16, 16];
///     s.render.resolution = [16, 16];
///     let mut e = engine::build(&ctx, &s, 1, engine::EngineKind::Gpu)?;
///     e.advance_frame()?;
///     assert_eq!(e.state_size(), [16, 16]);
///     assert!(e.dump()?.non_finite == 0);
/// }
/// # Ok::<(), texflow::Error>(())
/// ```
pub trait Engine {
    /// Advances the simulation by one frame: `substeps` steps of `dt`.
    fn advance_frame(&mut self) -> Result<()>;

    /// One frame of a benchmark's warm-up: the motion without the collision stage between
    /// particles where there is one (its sorts and searches are data-oblivious, so what it
    /// costs later does not depend on it).
    fn warm_up_frame(&mut self) -> Result<()> {
        self.advance_frame()
    }

    /// The frame's ordering (the sort alpha blending needs), run once every frame, drawn or
    /// not, so that a sort spread over frames advances with the simulation.
    fn order_for_drawing(&mut self) -> Result<()> {
        Ok(())
    }

    /// Draws the current state into the frame target, without reading it back.
    fn draw(&mut self) -> Result<()>;

    /// Draws the current state and reads the frame back.
    fn render(&mut self) -> Result<image::RgbImage> {
        self.draw()?;
        self.target().read_rgb()
    }

    /// The frame target the engine draws into.
    fn target(&self) -> &FrameTarget;

    /// Sets the viewer's change to the scene's camera (the live window).
    fn set_view(&mut self, view: ViewOffset);

    /// Simulation steps taken.
    fn steps(&self) -> u64;

    /// State size: one particle per texel (or array element).
    fn state_size(&self) -> [u32; 2];

    /// Births dropped because the state was full.
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

    /// With distance constraints: the constraints stretched past the scene's bound now.
    fn stretched(&self) -> Result<Option<crate::sim::Stretched>> {
        Ok(None)
    }

    /// With `[fluid]`: the density error and energy now.
    fn fluid_stats(&self) -> Result<Option<crate::sim::fluid::FluidStats>> {
        Ok(None)
    }

    /// Paths that still entered a collider after the bound on bounces per step (one
    /// read-back, for a run's end).
    fn truncated_bounces(&self) -> Result<u64> {
        Ok(0)
    }

    /// Live particles with a NaN or infinite component; `counter` counts GPU state.
    fn non_finite(&self, counter: &NonFiniteCounter) -> Result<NonFiniteCount>;

    /// The live particles read back.
    fn dump(&self) -> Result<StateDump>;

    /// The scene key of each particle type's emitter (`emitters.timestamp.0`), in type order,
    /// for naming where non-finite values came from; empty where the engine cannot tell.
    fn emitter_keys(&self) -> Vec<String> {
        Vec::new()
    }

    /// Particles alive now (drawn: finite and with life left).
    fn live(&self) -> Result<u64> {
        Ok(self
            .dump()?
            .positions
            .iter()
            .filter(|p| p.iter().all(|x| x.is_finite()))
            .count() as u64)
    }

    /// One whole frame timed in parts, each finished before the next starts: names and
    /// milliseconds.
    fn timed_frame(&mut self, timer: &PassTimer) -> Result<Vec<(&'static str, f64)>>;

    /// With collisions between particles: the pairs the last step's detection found.
    fn census(&self) -> Result<Option<PairCensus>> {
        Ok(None)
    }

    /// The passes of one frame, in order, from what the engine holds.
    fn plan(&self) -> super::plan::Plan;

    /// The passes of one frame with the programs each draws (the plan's list): what `texflow
    /// scene passes`, `trace` and `bench scene` print.
    fn passes(&self) -> Vec<crate::gl::PassInfo> {
        self.plan().passes
    }

    /// The frame in its stages, for the measuring floor (the benchmarks, `trace`, the
    /// report): the GPU engine's; `None` for the CPU engine, whose frame is one piece.
    fn stages(&mut self) -> Option<&mut dyn super::Stages> {
        None
    }

    /// [`stages`](Self::stages), to read.
    fn stages_ref(&self) -> Option<&dyn super::Stages> {
        None
    }
}

/// The GPU engine of `scene`, in its stages ([`build`] with [`EngineKind::Gpu`]): what the
/// measuring floor times and pictures.
pub fn build_gpu(ctx: &Context, scene: &SceneFile, seed: u64) -> Result<Box<dyn super::Stages>> {
    Ok(match scene.fire.is_some() {
        true => Box::new(GpuEngine::<crate::sim::FireSim>::new(ctx, scene, seed)?),
        false => Box::new(ParticleEngine::new(ctx, scene, seed)?),
    })
}

/// The engine that runs `scene`: the GPU engine over the fire's simulation or the particle
/// pipeline's, or with [`EngineKind::Cpu`] the CPU engine (E5), which covers part of the
/// pipeline and says which part a scene needs that it lacks.
pub fn build(
    ctx: &Context,
    scene: &SceneFile,
    seed: u64,
    kind: EngineKind,
) -> Result<Box<dyn Engine>> {
    Ok(match kind {
        EngineKind::Cpu => Box::new(CpuEngine::new(ctx, scene, seed)?),
        EngineKind::Gpu => build_gpu(ctx, scene, seed)?,
    })
}

/// Times `f` with `timer`, passing its error on.
pub fn timed(timer: &PassTimer, f: impl FnOnce() -> Result<()>) -> Result<f64> {
    let mut res = Ok(());
    let t = timer.time(|| res = f())?;
    res.map(|_| t)
}
