//! Exchanging attachments between framebuffers: a state gathered into a sorted layout becomes
//! the state's own by handing the textures over, where a copy pass would write every texel again.

use glow::HasContext;

use super::{AttachmentKey, Framebuffer};
use crate::error::{Error, Result};

impl Framebuffer {
    /// Exchanges this framebuffer's texture at `at` with `other`'s at `other_at` and attaches
    /// each where the other was: what `other` held there is now read and written through `self`,
    /// and the reverse. Both must own their attachments and agree in size and format; nothing is
    /// drawn or copied.
    ///
    /// # Panics
    /// If either has no attachment of that name (a programming error, as for
    /// [`texture`](Self::texture)).
    pub fn exchange(
        &mut self,
        at: impl AttachmentKey,
        other: &mut Framebuffer,
        other_at: impl AttachmentKey,
    ) -> Result<()> {
        let (i, j) = (at.index_in(self), other_at.index_in(other));
        let (Some(a), Some(b)) = (self.textures.get(i), other.textures.get(j)) else {
            return Err(Error::InvalidInput(format!(
                "framebuffers {} and {} must own the attachments they exchange",
                self.label, other.label
            )));
        };
        if (a.width(), a.height(), a.format()) != (b.width(), b.height(), b.format()) {
            return Err(Error::InvalidInput(format!(
                "framebuffers {} and {}: attachments of different sizes or formats cannot be \
                 exchanged ({a:?} and {b:?})",
                self.label, other.label
            )));
        }
        std::mem::swap(&mut self.textures[i], &mut other.textures[j]);
        self.reattach(i);
        other.reattach(j);
        self.ctx.check_error(&format!(
            "exchanging attachments of {} and {}",
            self.label, other.label
        ))
    }

    /// Attaches texture `i` again at colour attachment `i`.
    fn reattach(&self, i: usize) {
        // SAFETY: the framebuffer and its textures are alive and of this context; the
        // attachment point existed at creation, and a texture of the same size and format
        // keeps the framebuffer complete.
        unsafe {
            let gl = self.ctx.gl();
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.raw));
            gl.framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0 + i as u32,
                glow::TEXTURE_2D,
                Some(self.textures[i].raw()),
                0,
            );
            gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        }
    }
}
