//! Ping-pong state: two framebuffers with the same set of state textures. A pass reads the
//! textures of [`PingPong::front`] and writes those of [`PingPong::back`]; [`PingPong::swap`]
//! once per step makes what was written the new front (thesis §3.4, Latta §3.3).

use super::{Context, Framebuffer, Texture, TextureDesc, TextureFormat};
use crate::error::Result;

/// Double-buffered state of N textures.
#[derive(Debug)]
pub struct PingPong {
    sides: [Framebuffer; 2],
    front: usize,
    swaps: u64,
}

impl PingPong {
    /// Makes two framebuffers of `formats.len()` textures of `width`×`height`.
    /// `names` label the textures (`"position"`, `"velocity"`).
    pub fn new(
        ctx: &Context,
        label: &str,
        names: &[&str],
        formats: &[TextureFormat],
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let side = |s: usize| -> Result<Framebuffer> {
            let textures = formats
                .iter()
                .zip(names)
                .map(|(&format, name)| {
                    Texture::new(
                        ctx,
                        TextureDesc {
                            width,
                            height,
                            format,
                            label: &format!("{name}:{s}"),
                        },
                    )
                })
                .collect::<Result<Vec<_>>>()?;
            Framebuffer::new(ctx, &format!("{label}:{s}"), textures)
        };
        Ok(PingPong {
            sides: [side(0)?, side(1)?],
            front: 0,
            swaps: 0,
        })
    }

    /// The current state: read it.
    pub fn front(&self) -> &Framebuffer {
        &self.sides[self.front]
    }

    /// The next state: write it.
    pub fn back(&self) -> &Framebuffer {
        &self.sides[1 - self.front]
    }

    /// Makes the back the front. Call once per step, after the passes that write the back.
    pub fn swap(&mut self) {
        self.front = 1 - self.front;
        self.swaps += 1;
    }

    /// How many swaps happened.
    pub fn swaps(&self) -> u64 {
        self.swaps
    }

    /// Width of the state textures.
    pub fn width(&self) -> u32 {
        self.sides[0].width()
    }

    /// Height of the state textures.
    pub fn height(&self) -> u32 {
        self.sides[0].height()
    }
}
