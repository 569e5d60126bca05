//! Rendering particles from their state textures into offscreen frames, and writing frames.

pub mod atlas;
mod birth_curves;
mod camera;
pub mod connected;
pub mod geometry;
mod halfangle;
mod isosurface;
mod keyframes;
mod lookup;
mod params;
mod particles;
pub mod ribbons;
mod soft;
mod sprite;
mod style;
mod target;
mod user_color;
mod vertex_path;

pub use camera::{Camera, ViewOffset};
pub use connected::{ConnectedRenderer, SURFACE_AMBIENT, SURFACE_LIGHT};
pub use geometry::{GeometryRenderer, Mesh, Terrain, MAX_TERRAIN_CELLS};
pub use halfangle::{light_view, HalfAngle, HalfAngleRenderer, SliceDraws, SlicePasses};
pub use isosurface::Surface;
pub use keyframes::{relative_age, KeyframeRamp};
pub use lookup::SortLayout;
pub use params::RenderParams;
pub use particles::{FrameState, Motion, ParticleRenderer, QUAD_VERTICES};
pub use ribbons::RibbonRenderer;
pub use sprite::{
    age_seconds, flipbook_tile, random_size, second_random, sprite_angle, third_random, SizeCurve,
};
pub use style::{blend_of, clear_of, default_keyframes, FireRamp, ParticleStyle, TypeLook};
pub use target::FrameTarget;
pub use user_color::UserColor;
