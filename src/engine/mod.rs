//! The engines and the frame loop: what runs a scene's passes frame after frame.
//!
//! - [`FireEngine`]: the GLSL fire thesis (in-shader respawn, vertex-texture-fetch points).
//! - [`Engine`]: the particle pipeline of UberFlow and Latta (births, forces, colliders,
//!   collisions, the sort alpha blending needs, sprites).
//! - [`CpuEngine`]: the same pipeline on the CPU (UberFlow's E5), drawing through the same GL
//!   renderer so that the frames can be compared pixel for pixel.
//! - [`SceneEngine`]: whichever of the first two a scene asks for.
//! - [`plan`]: the passes a scene runs per frame, derived from the scene alone.
//! - [`FrameLoop`]: frames, `every`, dumps and the non-finite census, shared by the CLI, the
//!   examples and the tests.

pub mod compare;
pub mod cpu;
mod fire;
mod particles;
pub mod plan;
mod run;
mod scene_engine;

pub use cpu::{CpuEngine, CpuSim, FramePhases};
pub use fire::FireEngine;
pub use particles::{compact_depth_range, key_mode, Engine};
pub use run::{
    Event, FolderSink, FrameLoop, FrameSink, FrameTimes, LoopOptions, LoopSummary, MemorySink,
    NonFinitePolicy,
};
pub use scene_engine::{SceneEngine, StateDump};

/// Folds a 64-bit seed into the 32 bits the shader hash takes.
pub fn shader_seed(seed: u64) -> u32 {
    (seed as u32) ^ ((seed >> 32) as u32)
}
