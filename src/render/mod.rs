//! Rendering particles from their state textures into offscreen frames, and writing frames.

pub mod atlas;
mod camera;
mod keyframes;
mod particles;
mod points;
mod target;

pub use camera::Camera;
pub use keyframes::{relative_age, KeyframeRamp};
pub use particles::{default_keyframes, ParticleRenderer, ParticleStyle};
pub use points::{PointRenderer, PointStyle};
pub use target::FrameTarget;
