//! Rendering particles from their state textures into offscreen frames, and writing frames.

mod camera;
mod frames;
mod points;
mod target;

pub use camera::Camera;
pub use frames::{write_png_atomic, FrameWriter};
pub use points::{PointRenderer, PointStyle};
pub use target::FrameTarget;
