//! Rendering particles from their state textures into offscreen frames, and writing frames.

pub mod atlas;
mod camera;

mod particles;
mod points;
mod target;

pub use camera::Camera;

pub use particles::{
    default_keyframes, relative_age, KeyframeRamp, ParticleRenderer, ParticleStyle,
};
pub use points::{PointRenderer, PointStyle};
pub use target::FrameTarget;
