//! Particle simulation passes: state in RGBA float textures, updated by full-screen fragment
//! passes into ping-pong framebuffers.

pub mod allocator;
pub mod collide;
pub mod constraints;
pub mod emit;
pub mod fields;
pub mod fire;
pub mod nonfinite;
pub mod particles;
pub mod reference;
mod user_glsl;

pub use fields::{DistanceField, FlowField, HeightField};
pub use fire::{FireParams, FireSim};
pub use particles::{ClosedForm, Features, ParticleSim};
