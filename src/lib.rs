//! texflow: the 2004 GPU particle engines (UberFlow, Latta's million-particle system, the GLSL
//! fire thesis) reproduced faithfully: particle state lives in RGBA float textures and changes
//! only by full-screen fragment passes into ping-pong framebuffers with multiple render targets.
//!
//! Layers, bottom up:
//! - [`gl`]: a thin safe layer over glow (headless EGL context, textures, framebuffers, programs
//!   built from the embedded `glsl/` files, the full-screen pass, ping-pong state, timer queries).
//! - [`sim`]: the simulation passes (the fire of the thesis).
//! - [`render`]: vertex-texture-fetch point rendering into offscreen frames, PNG output.
//! - [`scene`]: scene descriptions, built-in scenes.
//! - [`engine`]: a scene's simulation and renderer together; [`bench`]: GPU timings.
//!
//! ```no_run
//! use texflow::{gl::Context, scene, Engine};
//! let ctx = Context::new(0)?;                       // first EGL device
//! let mut engine = Engine::new(&ctx, scene::builtin("fire")?, 7)?;
//! for _ in 0..30 {
//!     engine.advance_frame();
//! }
//! engine.render()?.save("fire.png").expect("write");
//! # Ok::<(), texflow::Error>(())
//! ```

#![warn(missing_docs)]

pub mod bench;
pub mod bench_scenes;
pub mod cpu_engine;
pub mod engine;
pub mod error;
pub mod gl;
pub mod npy;
pub mod render;
pub mod report;
pub mod scene;
pub mod sim;
pub mod sort;

pub use engine::{Engine, ParticleEngine, SceneRunner};
pub use error::{Error, Result};
