//! What runs an experiment's frames: the GPU engine (E1-E4) or the CPU engine (E5), timed the
//! same way.

use super::ScenesOptions;
use crate::bench::PassTimer;
use crate::engine::cpu::CpuEngine;
use crate::engine::Engine;
use crate::error::Result;
use crate::gl::Context;
use crate::scene::SceneFile;

/// Something that runs whole frames of an experiment at one size.
pub trait FrameSource {
    /// Advances the simulation by `frames` frames without drawing (warm-up).
    fn warm_up(&mut self, frames: usize) -> Result<()>;
    /// Issues one whole frame: the simulation steps of a frame and the drawing (with whatever
    /// sorting the scene's rendering needs). Does not wait for the GPU.
    fn frame(&mut self) -> Result<()>;
    /// Particles alive (drawn) now; reads the state back where it lives on the GPU.
    fn live(&self) -> Result<u64>;
    /// Runs one whole frame timed in parts (each part finished before the next starts): names
    /// and milliseconds.
    fn phases(&mut self, timer: &PassTimer) -> Result<Vec<(&'static str, f64)>>;
    /// With inter-particle collisions: how many overlapping pairs the last step's detection
    /// found (the CPU counts them from a read-back).
    fn census(&self) -> Result<Option<crate::sim::collide::PairCensus>> {
        Ok(None)
    }
}

/// Times `f` with `timer`, passing its error on.
pub(super) fn timed(timer: &PassTimer, f: impl FnOnce() -> Result<()>) -> Result<f64> {
    let mut res = Ok(());
    let t = timer.time(|| res = f())?;
    res.map(|_| t)
}

/// A scene of the GPU particle pipeline: [`Engine`] (E1-E4).
pub struct GpuScene(pub Engine);

impl FrameSource for GpuScene {
    fn warm_up(&mut self, frames: usize) -> Result<()> {
        // E4's collision stage would make the warm-up of a million particles on llvmpipe take
        // most of an hour; its sorts and detection are data-oblivious, so the timed frames (full
        // steps) cost the same after a collisionless warm-up. Births follow time stamps either
        // way, so the same particles are alive.
        for _ in 0..frames {
            self.0.advance_frame_without_collisions()?;
        }
        Ok(())
    }

    fn frame(&mut self) -> Result<()> {
        self.0.advance_frame()?;
        self.0.draw()
    }

    fn census(&self) -> Result<Option<crate::sim::collide::PairCensus>> {
        self.0.sim().collisions().map(|c| c.census()).transpose()
    }

    fn live(&self) -> Result<u64> {
        let p = self.0.sim().read_positions()?;
        Ok(p.chunks_exact(4)
            .filter(|p| p.iter().all(|x| x.is_finite()) && p[3] > 0.0)
            .count() as u64)
    }

    fn phases(&mut self, timer: &PassTimer) -> Result<Vec<(&'static str, f64)>> {
        let simulate = timed(timer, || self.0.advance_frame())?;
        let draw = timed(timer, || self.0.draw())?;
        let name = if self.0.sorted().is_some() {
            "keys, sort, gather and draw"
        } else {
            "draw"
        };
        Ok(vec![("simulate", simulate), (name, draw)])
    }
}

/// The CPU engine (E5).
pub struct CpuScene(pub CpuEngine);

impl FrameSource for CpuScene {
    fn warm_up(&mut self, frames: usize) -> Result<()> {
        for _ in 0..frames {
            self.0.advance_frame();
        }
        Ok(())
    }

    fn frame(&mut self) -> Result<()> {
        self.0.frame()
    }

    fn live(&self) -> Result<u64> {
        Ok(self.0.sim().live_count() as u64)
    }

    fn phases(&mut self, _timer: &PassTimer) -> Result<Vec<(&'static str, f64)>> {
        let p = self.0.timed_frame()?;
        Ok(vec![
            ("simulate", p.simulate_ms),
            ("keys, quicksort and gather", p.sort_ms),
            ("upload", p.upload_ms),
            ("draw", p.draw_ms),
        ])
    }
}

/// `scene` with size × size particles and the options' resolution.
pub fn sized(mut scene: SceneFile, size: u32, opts: &ScenesOptions) -> SceneFile {
    scene.particles.size = [size, size];
    if let Some(r) = opts.resolution {
        scene.render.resolution = r;
    }
    scene
}

/// A GPU experiment of `scene` at size × size particles.
pub fn gpu_scene(
    ctx: &Context,
    scene: SceneFile,
    size: u32,
    opts: &ScenesOptions,
) -> Result<Box<dyn FrameSource>> {
    let s = sized(scene, size, opts);
    Ok(Box::new(GpuScene(Engine::new(ctx, &s, opts.seed)?)))
}

/// The CPU engine on `scene` at size × size particles.
pub fn cpu_scene(
    ctx: &Context,
    scene: SceneFile,
    size: u32,
    opts: &ScenesOptions,
) -> Result<Box<dyn FrameSource>> {
    let s = sized(scene, size, opts);
    Ok(Box::new(CpuScene(CpuEngine::new(ctx, &s, opts.seed)?)))
}
