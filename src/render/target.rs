//! The offscreen RGBA8 framebuffer frames are rendered into, and its read-back as an image.

use crate::error::{Error, Result};
use crate::gl::{Context, Framebuffer, Texture, TextureDesc, TextureFormat};

/// An RGBA8 colour target of the frame's resolution.
#[derive(Debug)]
pub struct FrameTarget {
    fb: Framebuffer,
}

impl FrameTarget {
    /// Makes a `width`×`height` target; the size must fit the viewport and texture limits.
    pub fn new(ctx: &Context, width: u32, height: u32) -> Result<Self> {
        Self::make(ctx, width, height, false)
    }

    /// Like [`new`](Self::new), with a depth attachment: the target of a scene that draws its
    /// geometry, which the particles are depth-tested against.
    pub fn with_depth(ctx: &Context, width: u32, height: u32) -> Result<Self> {
        Self::make(ctx, width, height, true)
    }

    fn make(ctx: &Context, width: u32, height: u32, depth: bool) -> Result<Self> {
        let [vw, vh] = ctx.limits().max_viewport;
        if width > vw || height > vh {
            return Err(Error::InvalidInput(format!(
                "resolution {width}x{height} exceeds this device's GL_MAX_VIEWPORT_DIMS of {vw}x{vh}"
            )));
        }
        let tex = Texture::new(
            ctx,
            TextureDesc {
                width,
                height,
                format: TextureFormat::Rgba8,
                label: "frame",
            },
        )?;
        let fb = if depth {
            Framebuffer::with_depth(ctx, "frame", vec![tex])?
        } else {
            Framebuffer::new(ctx, "frame", vec![tex])?
        };
        Ok(FrameTarget { fb })
    }

    /// The framebuffer.
    pub fn framebuffer(&self) -> &Framebuffer {
        &self.fb
    }

    /// Whether it has a depth attachment ([`with_depth`](Self::with_depth)).
    pub fn has_depth(&self) -> bool {
        self.fb.has_depth()
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.fb.width()
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.fb.height()
    }

    /// Clears to opaque black (and the depth, if any, to the far plane).
    pub fn clear(&self) {
        self.fb.clear([0.0, 0.0, 0.0, 1.0]);
    }

    /// Clears to `rgba` (the under operator starts from alpha 0).
    pub fn clear_to(&self, rgba: [f32; 4]) {
        self.fb.clear(rgba);
    }

    /// Reads the frame back as an RGB image with the first row at the top (GL's is at the bottom).
    pub fn read_rgb(&self) -> Result<image::RgbImage> {
        let (w, h) = (self.width(), self.height());
        let rgba = self.fb.only_texture().read_u8()?;
        let mut out = image::RgbImage::new(w, h);
        for (y, row) in rgba.chunks_exact(4 * w as usize).enumerate() {
            let out_y = h - 1 - y as u32;
            for (x, px) in row.chunks_exact(4).enumerate() {
                out.put_pixel(x as u32, out_y, image::Rgb([px[0], px[1], px[2]]));
            }
        }
        Ok(out)
    }
}
