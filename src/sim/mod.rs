//! Particle simulation passes: state in RGBA float textures, updated by full-screen fragment
//! passes into ping-pong framebuffers.

pub mod allocator;
pub mod fire;

pub use fire::{FireParams, FireSim};
