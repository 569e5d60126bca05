//! Ping-pong state: two framebuffers with the same set of state textures. A pass reads the
//! textures of [`PingPong::front`] and writes those of [`PingPong::back`]; [`PingPong::swap`]
//! once per step makes what was written the new front (thesis §3.4, Latta §3.3).
//!
//! [`Ring3`] is the Verlet integrator's state (Latta eq. 9): three framebuffers of positions, of
//! which a step reads the current and the previous ones and writes the next;
//! [`Ring3::rotate`] once per step moves every role one place on.

use super::{Attachment, AttachmentKey, Context, Framebuffer, Texture, TextureDesc, TextureFormat};
use crate::error::Result;

/// Double-buffered state of N textures.
#[derive(Debug)]
pub struct PingPong {
    /// Per side, one framebuffer per texture ([`PingPong::with_single_targets`]); declared
    /// first so that they drop before the textures they draw into.
    singles: Option<[Vec<Framebuffer>; 2]>,
    sides: [Framebuffer; 2],
    front: usize,
    swaps: u64,
}

impl PingPong {
    /// Makes two framebuffers of `formats.len()` textures of `width`×`height`.
    /// `names` name the attachments, in the order of the fragment shader's outputs, and label
    /// the textures (`POSITION`, `VELOCITY`: [`Attachment`] handles; `"position"` makes one).
    pub fn new(
        ctx: &Context,
        label: &str,
        names: &[impl Into<Attachment> + Copy],
        formats: &[TextureFormat],
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let side = |s: usize| side(ctx, label, names, formats, width, height, s);
        Ok(PingPong {
            singles: None,
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

    /// Adds, for each side, a framebuffer per texture, for passes that write one texture of the
    /// back alone ([`PingPong::back_single`]).
    pub fn with_single_targets(mut self, ctx: &Context) -> Result<Self> {
        let views = |s: usize| -> Result<Vec<Framebuffer>> {
            let side = &self.sides[s];
            (0..side.textures().len())
                .map(|i| {
                    let name = side.names()[i].map_or(i.to_string(), |a| a.to_string());
                    Framebuffer::attachment(ctx, &format!("{}/{name}", side.label()), side, i)
                })
                .collect()
        };
        self.singles = Some([views(0)?, views(1)?]);
        Ok(self)
    }

    /// A framebuffer of attachment `at` of the back alone. Panics unless made
    /// [`with_single_targets`](PingPong::with_single_targets).
    pub fn back_single(&self, at: impl AttachmentKey) -> &Framebuffer {
        let singles = self
            .singles
            .as_ref()
            .expect("PingPong::with_single_targets before back_single");
        &singles[1 - self.front][at.index_in(self.back())]
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

/// Side `s` of a multi-buffered state: attachments `names`, their textures labelled
/// `"{name}:{s}"`, in a framebuffer labelled `"{label}:{s}"`.
fn side(
    ctx: &Context,
    label: &str,
    names: &[impl Into<Attachment> + Copy],
    formats: &[TextureFormat],
    width: u32,
    height: u32,
    s: usize,
) -> Result<Framebuffer> {
    if names.len() != formats.len() {
        return Err(crate::error::Error::InvalidInput(format!(
            "{label}: {} names for {} formats",
            names.len(),
            formats.len()
        )));
    }
    let attachments = formats
        .iter()
        .zip(names)
        .map(|(&format, &name)| {
            let name: Attachment = name.into();
            let texture = Texture::new(
                ctx,
                TextureDesc {
                    width,
                    height,
                    format,
                    label: &format!("{name}:{s}"),
                },
            )?;
            Ok((name, texture))
        })
        .collect::<Result<Vec<_>>>()?;
    Framebuffer::named(ctx, &format!("{label}:{s}"), attachments)
}

/// Triple-buffered state: the previous, the current and the next of three framebuffers with the
/// same textures. A Verlet step reads [`previous`](Ring3::previous) and
/// [`current`](Ring3::current), writes [`next`](Ring3::next), then [`rotate`](Ring3::rotate)s:
/// the next becomes the current, the current the previous, and the old previous is written next.
#[derive(Debug)]
pub struct Ring3 {
    sides: [Framebuffer; 3],
    /// The sides playing previous, current and next.
    roles: [usize; 3],
}

impl Ring3 {
    /// Makes three framebuffers of `formats.len()` textures of `width`×`height`, labelled as
    /// [`PingPong::new`] names and labels its two. Side 1 starts as the current, side 0 as the
    /// previous.
    pub fn new(
        ctx: &Context,
        label: &str,
        names: &[impl Into<Attachment> + Copy],
        formats: &[TextureFormat],
        width: u32,
        height: u32,
    ) -> Result<Self> {
        let side = |s: usize| side(ctx, label, names, formats, width, height, s);
        Ok(Ring3 {
            sides: [side(0)?, side(1)?, side(2)?],
            roles: [0, 1, 2],
        })
    }

    /// The state of this step: read it.
    pub fn current(&self) -> &Framebuffer {
        &self.sides[self.roles[1]]
    }

    /// The state of the step before: read it.
    pub fn previous(&self) -> &Framebuffer {
        &self.sides[self.roles[0]]
    }

    /// The state of the next step: write it.
    pub fn next(&self) -> &Framebuffer {
        &self.sides[self.roles[2]]
    }

    /// Moves every role one place on. Call once per step, after the pass that writes the next.
    pub fn rotate(&mut self) {
        let [p, c, n] = self.roles;
        self.roles = [c, n, p];
    }

    /// Exchanges the current and the next, keeping the previous: for passes that rewrite the
    /// current positions within a step (constraint relaxation reads the current, writes the
    /// next, then swaps), so that the previous step's positions still imply the velocity.
    pub fn swap_current_next(&mut self) {
        self.roles.swap(1, 2);
    }

    /// The three framebuffers in the order previous, current, next.
    pub fn roles(&self) -> [&Framebuffer; 3] {
        [self.previous(), self.current(), self.next()]
    }
}
