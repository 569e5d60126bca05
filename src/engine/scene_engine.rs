//! The engine a scene asks for: the fire of the thesis, or the particle pipeline.

use super::{Engine, FireEngine};
use crate::error::Result;
use crate::gl::Context;
use crate::scene::Scene;

/// Either engine, chosen by the scene: the thesis's fire or the particle pipeline.
///
/// ```
/// use texflow::{gl::Context, scene, SceneEngine};
/// let ctx = Context::new(0)?;
/// for name in ["fire", "fountain"] {
///     let mut s = scene::load(name)?;
///     s.particles.size = [16, 16];
///     s.render.resolution = [16, 16];
///     let mut engine = SceneEngine::new(&ctx, &s, 1)?;
///     engine.advance_frame()?;
///     assert_eq!(engine.state_size(), [16, 16]);
///     assert!(engine.dump()?.non_finite == 0);
/// }
/// # Ok::<(), texflow::Error>(())
/// ```
#[derive(Debug)]
pub enum SceneEngine {
    /// A scene with a `[fire]` section.
    Fire(Box<FireEngine>),
    /// Every other scene.
    Particles(Box<Engine>),
}

/// Live particles' positions and velocities, N×4 each, for `--dump-state`.
#[derive(Debug, Clone, PartialEq)]
pub struct StateDump {
    /// xyz and remaining life of every live particle.
    pub positions: Vec<[f32; 4]>,
    /// Velocity (xyz, 0) of the same particles.
    pub velocities: Vec<[f32; 4]>,
    /// Live particles with a NaN or infinite component: kept in the dump, and counted so that
    /// the CLI reports them rather than hiding them.
    pub non_finite: usize,
}

impl SceneEngine {
    /// Builds the engine `scene` needs.
    pub fn new(ctx: &Context, scene: &crate::scene::SceneFile, seed: u64) -> Result<Self> {
        Ok(if scene.fire.is_some() {
            SceneEngine::Fire(Box::new(FireEngine::new(
                ctx,
                Scene::from_file(scene)?,
                seed,
            )?))
        } else {
            SceneEngine::Particles(Box::new(Engine::new(ctx, scene, seed)?))
        })
    }

    /// Advances one frame.
    pub fn advance_frame(&mut self) -> Result<()> {
        match self {
            SceneEngine::Fire(e) => {
                e.advance_frame();
                Ok(())
            }
            SceneEngine::Particles(e) => e.advance_frame(),
        }
    }

    /// The sort stage of the frame just simulated (see [`Engine::order_for_drawing`]); the
    /// fire draws additively and has none.
    pub fn order_for_drawing(&mut self) -> Result<()> {
        match self {
            SceneEngine::Fire(_) => Ok(()),
            SceneEngine::Particles(e) => e.order_for_drawing().map(drop),
        }
    }

    /// Births the allocator has dropped so far because the state texture was full (the fire
    /// respawns in place and drops none).
    pub fn dropped_births(&self) -> u64 {
        match self {
            SceneEngine::Fire(_) => 0,
            SceneEngine::Particles(e) => e.sim().dropped_births(),
        }
    }

    /// Births that child emitters' texels could not take (see
    /// [`ParticleSim::dropped_child_births`](crate::sim::ParticleSim::dropped_child_births): one
    /// read-back, for the end of a run).
    pub fn dropped_child_births(&self) -> Result<u64> {
        match self {
            SceneEngine::Fire(_) => Ok(0),
            SceneEngine::Particles(e) => e.sim().dropped_child_births(),
        }
    }

    /// Exact collision searches that hit their bound over the run so far (see
    /// [`Collisions::truncated_searches`](crate::sim::collide::Collisions::truncated_searches):
    /// one read-back, for the end of a run).
    pub fn truncated_searches(&self) -> Result<u64> {
        match self {
            SceneEngine::Fire(_) => Ok(0),
            SceneEngine::Particles(e) => e
                .sim()
                .collisions()
                .map_or(Ok(0), |c| c.truncated_searches()),
        }
    }

    /// Sets the viewer's change to the scene's camera (see [`Engine::set_view`]).
    pub fn set_view(&mut self, view: crate::render::ViewOffset) {
        match self {
            SceneEngine::Fire(e) => e.set_view(view),
            SceneEngine::Particles(e) => e.set_view(view),
        }
    }

    /// Draws the current state into the frame target, without reading it back.
    pub fn draw(&mut self) -> Result<()> {
        match self {
            SceneEngine::Fire(e) => {
                e.draw();
                Ok(())
            }
            SceneEngine::Particles(e) => e.draw(),
        }
    }

    /// The frame target the engine draws into.
    pub fn target(&self) -> &crate::render::FrameTarget {
        match self {
            SceneEngine::Fire(e) => e.target(),
            SceneEngine::Particles(e) => e.target(),
        }
    }

    /// Renders the current state.
    pub fn render(&mut self) -> Result<image::RgbImage> {
        match self {
            SceneEngine::Fire(e) => e.render(),
            SceneEngine::Particles(e) => e.render(),
        }
    }

    /// Simulation steps taken.
    pub fn steps(&self) -> u64 {
        match self {
            SceneEngine::Fire(e) => e.sim().steps(),
            SceneEngine::Particles(e) => e.sim().steps(),
        }
    }

    /// State texture size.
    pub fn state_size(&self) -> [u32; 2] {
        match self {
            SceneEngine::Fire(e) => e.scene().particles,
            SceneEngine::Particles(e) => e.sim().size().to_array(),
        }
    }

    /// Counts the live particles with a NaN or infinite component on the GPU (a reduction by
    /// fragment passes), so that garbage is reported instead of rendered silently.
    pub fn non_finite(
        &self,
        counter: &crate::sim::nonfinite::NonFiniteCounter,
    ) -> Result<crate::sim::nonfinite::NonFiniteCount> {
        match self {
            SceneEngine::Fire(e) => counter.count(e.sim().positions(), Some(e.sim().velocities())),
            SceneEngine::Particles(e) => counter.count_sim(e.sim()),
        }
    }

    /// Reads back the live particles (remaining life > 0).
    pub fn dump(&self) -> Result<StateDump> {
        let (pos, vel) = match self {
            SceneEngine::Fire(e) => (
                e.sim().positions().read_f32()?,
                e.sim().velocities().read_f32()?,
            ),
            SceneEngine::Particles(e) => (e.sim().read_positions()?, e.sim().read_velocities()?),
        };
        let mut d = StateDump {
            positions: Vec::new(),
            velocities: Vec::new(),
            non_finite: 0,
        };
        for (p, v) in pos.chunks_exact(4).zip(vel.chunks_exact(4)) {
            if p[3] > 0.0 {
                if !p.iter().chain(&v[..3]).all(|x| x.is_finite()) {
                    d.non_finite += 1;
                }
                d.positions.push([p[0], p[1], p[2], p[3]]);
                // The fire keeps its wait counter in velocity.w; the dump holds velocities only.
                d.velocities.push([v[0], v[1], v[2], 0.0]);
            }
        }
        Ok(d)
    }
}
