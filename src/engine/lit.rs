//! The engine's half-angle slicing (`render.lighting = "half_angle"`): the lit renderer a scene
//! asks for, and the sort key that orders the particles for it.

use crate::error::Result;
use crate::gl::Context;
use crate::render::{Camera, HalfAngle, HalfAngleRenderer, ParticleStyle};
use crate::scene::{LightSection, Lighting, SceneFile};
use crate::sort::KeyMode;

/// The lit renderer of `scene` with `style` (`None` when it is unlit): its light buffer covers
/// `render.light.extent` scene units around the camera's target, by default the camera's
/// distance.
pub fn lit_renderer(
    ctx: &Context,
    scene: &SceneFile,
    style: &ParticleStyle,
) -> Result<Option<HalfAngleRenderer>> {
    let r = &scene.render;
    if r.lighting != Lighting::HalfAngle {
        return Ok(None);
    }
    let extent = r.light.extent.unwrap_or(r.camera.distance);
    let lit = HalfAngleRenderer::new(ctx, style.clone(), &r.light, r.slices, extent)?;
    Ok(Some(lit))
}

/// The sort key of half-angle slicing for `camera`: the position along the half-angle vector,
/// ascending (nearest the light first).
pub fn half_angle_keys(camera: &Camera, light: &LightSection) -> KeyMode {
    KeyMode::Axis {
        direction: HalfAngle::of(camera, light).axis,
    }
}
