//! Soft particles (`render.soft`): the drawn geometry's view depth, rendered into a float
//! texture before the particles, which their fragment stage fetches at its pixel to fade the
//! opacity as a particle nears the surface behind it (no hard line where a sprite cuts a plane).

use std::cell::OnceCell;

use super::{Camera, FrameTarget, GeometryRenderer};
use crate::error::{Error, Result};
use crate::gl::{Context, Framebuffer, Texture, TextureDesc, TextureFormat};

/// No geometry at a pixel: farther than any particle.
const FAR: f32 = 1e30;

/// The geometry's view depth per pixel, in a target made at the first frame's size.
#[derive(Default)]
pub(super) struct SoftDepth {
    fb: OnceCell<Framebuffer>,
}

impl SoftDepth {
    /// Renders `geometry`'s view depth for a frame of `target`'s size; gives the texture.
    pub(super) fn draw(
        &self,
        ctx: &Context,
        geometry: &GeometryRenderer,
        target: &FrameTarget,
        camera: &Camera,
    ) -> Result<&Texture> {
        let (w, h) = (target.width(), target.height());
        if self.fb.get().is_none() {
            let desc = TextureDesc {
                width: w,
                height: h,
                format: TextureFormat::R32F,
                label: "soft particles: geometry depth",
            };
            let fb = Framebuffer::with_depth(ctx, "soft depth", vec![Texture::new(ctx, desc)?])?;
            let _ = self.fb.set(fb);
        }
        let fb = (self.fb.get())
            .filter(|fb| fb.width() == w && fb.height() == h)
            .ok_or_else(|| {
                Error::InvalidInput(format!(
                    "soft particles were set up for another frame size than {w}x{h}"
                ))
            })?;
        fb.clear([FAR; 4]);
        geometry.draw_depth(fb, &camera.view_projection(w as f32 / h as f32))?;
        Ok(fb.only_texture())
    }
}
