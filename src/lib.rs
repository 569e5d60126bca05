//! texflow: the 2004 GPU particle engines (UberFlow, Latta's million-particle system, the GLSL
//! fire thesis) reproduced faithfully: particle state lives in RGBA float textures and changes
//! only by full-screen fragment passes into ping-pong framebuffers with multiple render targets.
//!
//! Layers, one way (an arrow points at what a layer may import):
//! `gl ← scene ← sim, sort, render ← engine ← bench, report ← cli`.
//! - [`gl`]: the only code that calls GL: a headless EGL context, one owning type per GL object,
//!   programs built from the embedded `glsl/` files, the full-screen pass, ping-pong state.
//! - [`scene`]: scene files as data: schema, validation with line and column, built-ins.
//! - [`sim`], [`sort`], [`render`]: the papers' passes (emit, integrate, collide, boundary;
//!   bitonic and odd-even merge sorts; point sprites and vertex texture fetch).
//! - [`engine`]: the engines that run a scene's passes, the pass plan and the frame loop.
//! - [`mod@bench`] and [`report`]: timings against floors, the papers' tables, error against run time.
//! - [`trace`]: the state textures drawn pass by pass (`texflow trace`).
//! - [`output`], [`npy`], [`error`]: files written atomically, `.npy` arrays, the error type.
//!
//! ```
//! use texflow::{engine, gl::Context, scene};
//! let ctx = Context::new(0)?;                       // first EGL device
//! let mut fire = scene::load("fire")?;
//! fire.particles.size = [64, 64];                   // small, so that the example runs fast
//! fire.render.resolution = [64, 48];
//! let mut engine = engine::build(&ctx, &fire, 7, engine::EngineKind::Gpu)?;
//! for _ in 0..30 {
//!     engine.advance_frame()?;
//! }
//! let frame = engine.render()?;
//! assert_eq!(frame.dimensions(), (64, 48));
//! frame.save(std::env::temp_dir().join("texflow-doc-fire.png")).expect("write");
//! # Ok::<(), texflow::Error>(())
//! ```

#![warn(missing_docs)]

pub mod bench;
pub mod engine;
pub mod error;
pub mod gl;
pub mod input;
pub mod npy;
pub mod output;
pub mod render;
pub mod report;
pub mod scene;
pub mod sim;
pub mod sort;
pub mod trace;

#[cfg(test)]
mod test_rng;

pub use engine::{CpuEngine, Engine, EngineKind, GpuEngine, ParticleEngine};
pub use error::{Error, Result};
