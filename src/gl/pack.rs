//! The texture-to-vertex copy of UberFlow §4.7 and Latta §3.4.5: rows of a state texture copied
//! into a buffer on the GPU (`glReadPixels` into a `GL_PIXEL_PACK_BUFFER`), which a vertex array
//! then reads as vertices.

use glow::HasContext;

use super::{Buffer, Context, Texture};
use crate::error::{Error, Result};

/// A framebuffer used only as the read source of the copy: the texture is attached for the copy
/// and detached after it, so it owns no attachment.
pub struct PixelPack {
    ctx: Context,
    raw: glow::Framebuffer,
}

impl std::fmt::Debug for PixelPack {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("PixelPack")
    }
}

impl PixelPack {
    /// Makes the read framebuffer.
    pub fn new(ctx: &Context) -> Result<Self> {
        // SAFETY: a fresh framebuffer object.
        let raw = unsafe { ctx.gl().create_framebuffer().map_err(Error::Gl)? };
        Ok(PixelPack {
            ctx: ctx.clone(),
            raw,
        })
    }

    /// Copies rows `0..rows` of `texture` (RGBA, floats) into `buffer` at offset 0 on the GPU.
    pub fn copy_rows(&self, texture: &Texture, buffer: &Buffer, rows: u32) -> Result<()> {
        let gl = &self.ctx;
        let bytes = texture.width() as usize * rows as usize * 16;
        if bytes > buffer.size() {
            return Err(Error::InvalidInput(format!(
                "pixel pack of {bytes} bytes into a buffer of {}",
                buffer.size()
            )));
        }
        // SAFETY: the texture and buffer are alive; the buffer holds the copied rows (checked
        // above); every binding changed here is reset before returning.
        let status = unsafe {
            gl.gl()
                .bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.raw));
            gl.gl().framebuffer_texture_2d(
                glow::READ_FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(texture.raw()),
                0,
            );
            gl.gl().read_buffer(glow::COLOR_ATTACHMENT0);
            let status = gl.gl().check_framebuffer_status(glow::READ_FRAMEBUFFER);
            if status == glow::FRAMEBUFFER_COMPLETE {
                gl.gl()
                    .bind_buffer(glow::PIXEL_PACK_BUFFER, Some(buffer.raw()));
                gl.gl().pixel_store_i32(glow::PACK_ALIGNMENT, 4);
                gl.gl().read_pixels(
                    0,
                    0,
                    texture.width() as i32,
                    rows as i32,
                    glow::RGBA,
                    glow::FLOAT,
                    glow::PixelPackData::BufferOffset(0),
                );
                gl.gl().bind_buffer(glow::PIXEL_PACK_BUFFER, None);
            }
            gl.gl().framebuffer_texture_2d(
                glow::READ_FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                None,
                0,
            );
            gl.gl().bind_framebuffer(glow::READ_FRAMEBUFFER, None);
            status
        };
        if status != glow::FRAMEBUFFER_COMPLETE {
            return Err(Error::Gl(format!(
                "a {:?} cannot be read by glReadPixels (framebuffer status {status:#x})",
                texture
            )));
        }
        gl.check_error("copying a state texture into a vertex buffer (pixel pack)")
    }
}

impl Drop for PixelPack {
    fn drop(&mut self) {
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe { gl.delete_framebuffer(self.raw) }
        }
    }
}
