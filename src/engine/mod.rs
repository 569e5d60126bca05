//! The engines and the frame loop: what runs a scene's passes frame after frame.
//!
//! - [`Engine`]: the one trait everything above this module uses (the frame loop, `render`,
//!   `view`, the benchmarks, the report); [`build`] makes the engine a scene asks for.
//! - [`GpuEngine`]: the one GPU engine, over a [`Simulation`](crate::sim::Simulation): the
//!   particle pipeline of UberFlow and Latta ([`ParticleEngine`]: births, forces, colliders,
//!   collisions, the sort alpha blending needs, sprites) or the GLSL fire thesis (its in-shader
//!   respawn, drawn by the same particle renderer with the fire's colour ramp).
//! - [`CpuEngine`]: the same pipeline on the CPU (UberFlow's E5), drawing through GL so that
//!   the frames can be compared pixel for pixel.
//! - [`Stages`]: a GPU engine's frame taken apart (the simulation's stages, the sort's key
//!   pass, network and gather, the render pass), which the benchmarks, `trace` and the report
//!   time and picture; [`build_gpu`] makes the engine with them.
//! - [`plan`]: the passes a scene runs per frame.
//! - [`FrameLoop`]: frames, `every`, dumps and the non-finite census, shared by the CLI, the
//!   examples and the tests.

pub mod compare;
mod contract;
pub mod cpu;
mod gpu;
mod lit;
pub mod plan;
mod run;
mod stages;

pub use contract::{build, build_gpu, timed, Engine, EngineKind, StateDump, DUMP_NAMES};
pub use cpu::{CpuEngine, CpuSim, FramePhases};
pub use gpu::{
    compact_depth_range, gather_target, key_mode, sort_layout, sorter_for, GpuEngine,
    ParticleEngine,
};
pub use lit::{half_angle_keys, lit_renderer};
pub use run::{
    Event, FolderSink, FrameLoop, FrameSink, FrameTimes, LoopOptions, LoopSummary, MemorySink,
    NonFinitePolicy,
};
pub use stages::Stages;

/// Folds a 64-bit seed into the 32 bits the shader hash takes.
pub fn shader_seed(seed: u64) -> u32 {
    (seed as u32) ^ ((seed >> 32) as u32)
}
