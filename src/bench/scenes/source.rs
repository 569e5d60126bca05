//! What runs an experiment's frames: the one [`Engine`] trait, over the GPU engine (E1-E4) or
//! the CPU engine (E5), timed the same way.

use super::ScenesOptions;
use crate::engine::{build, Engine, EngineKind};
use crate::error::Result;
use crate::gl::Context;
use crate::scene::SceneFile;

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
) -> Result<Box<dyn Engine>> {
    build(ctx, &sized(scene, size, opts), opts.seed, EngineKind::Gpu)
}

/// The CPU engine on `scene` at size × size particles.
pub fn cpu_scene(
    ctx: &Context,
    scene: SceneFile,
    size: u32,
    opts: &ScenesOptions,
) -> Result<Box<dyn Engine>> {
    build(ctx, &sized(scene, size, opts), opts.seed, EngineKind::Cpu)
}
