//! Framebuffers that own their colour attachments: one set of state textures written by a pass
//! through multiple render targets; and framebuffers whose one attachment is a layer (z slice)
//! of a 3D texture, for building a field slice by slice (UberFlow §4.6).

use glow::HasContext;

use super::attachment::check_unique;
use super::{Attachment, AttachmentKey, Context, Texture, Texture3D, TextureFormat};
use crate::error::{Error, Incomplete, Result};

/// A framebuffer object with 1 to 8 owned colour attachments, all drawn to by every pass; or
/// (made by [`Framebuffer::layer`]) with one layer of a 3D texture it does not own.
pub struct Framebuffer {
    pub(super) ctx: Context,
    pub(super) raw: glow::Framebuffer,
    pub(super) textures: Vec<Texture>,
    /// The GL names of the textures a draw into it writes, owned or not (for telling a draw
    /// that waits on an earlier one from one that does not: [`DrawStats`](super::DrawStats)).
    pub(super) writes: Vec<glow::Texture>,
    /// The attachments' names, one per attachment (`None`: made by [`Framebuffer::new`]).
    names: Vec<Option<Attachment>>,
    /// Width and height of the attachments.
    size: [u32; 2],
    /// Number of colour attachments.
    attachments: usize,
    /// Bytes per texel of all attachments together.
    bytes_per_texel: usize,
    /// Each attachment's format.
    formats: Vec<TextureFormat>,
    /// Whether the attachments hold unsigned integers (written as `uvec4`).
    integer: bool,
    /// A depth renderbuffer (frame targets that draw geometry only).
    depth: Option<glow::Renderbuffer>,
    pub(super) label: String,
}

impl std::fmt::Debug for Framebuffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Framebuffer({} {:?})", self.label, self.textures)
    }
}

fn incomplete(status: u32) -> Incomplete {
    match status {
        glow::FRAMEBUFFER_INCOMPLETE_ATTACHMENT => Incomplete::Attachment,
        glow::FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT => Incomplete::MissingAttachment,
        glow::FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER => Incomplete::DrawBuffer,
        glow::FRAMEBUFFER_INCOMPLETE_READ_BUFFER => Incomplete::ReadBuffer,
        glow::FRAMEBUFFER_UNSUPPORTED => Incomplete::Unsupported,
        glow::FRAMEBUFFER_INCOMPLETE_MULTISAMPLE => Incomplete::Multisample,
        glow::FRAMEBUFFER_INCOMPLETE_LAYER_TARGETS => Incomplete::LayerTargets,
        other => Incomplete::Other(other),
    }
}

impl Framebuffer {
    /// Attaches `textures` to colour attachments 0.. in order and checks completeness.
    ///
    /// All textures must have the same size.
    pub fn new(ctx: &Context, label: &str, textures: Vec<Texture>) -> Result<Self> {
        let limits = ctx.limits();
        let max = limits
            .max_draw_buffers
            .min(limits.max_color_attachments)
            .min(8) as usize;
        if textures.is_empty() || textures.len() > max {
            return Err(Error::InvalidInput(format!(
                "framebuffer {label} needs 1 to {max} attachments, got {}",
                textures.len()
            )));
        }
        let (w, h) = (textures[0].width(), textures[0].height());
        if textures.iter().any(|t| t.width() != w || t.height() != h) {
            return Err(Error::InvalidInput(format!(
                "framebuffer {label}: attachments differ in size"
            )));
        }
        let raw = attach(ctx, &textures.iter().collect::<Vec<_>>())?;
        let attachments = textures.len();
        let bytes_per_texel = textures.iter().map(|t| t.format().bytes_per_texel()).sum();
        let integer = textures_integer(&textures);
        let formats = textures.iter().map(|t| t.format()).collect();
        Framebuffer {
            ctx: ctx.clone(),
            raw,
            writes: textures.iter().map(|t| t.raw()).collect(),
            textures,
            names: vec![None; attachments],
            size: [w, h],
            attachments,
            bytes_per_texel,
            formats,
            integer,
            depth: None,
            label: label.to_owned(),
        }
        .checked()
    }

    /// Like [`Framebuffer::new`], with every attachment named: `attachments[k]`'s texture is
    /// colour attachment k (the fragment shader's output k) and is reached with
    /// [`texture`](Self::texture)`(name)`. Two attachments of one name are refused.
    pub fn named(
        ctx: &Context,
        label: &str,
        attachments: Vec<(Attachment, Texture)>,
    ) -> Result<Self> {
        let (names, textures): (Vec<_>, Vec<_>) =
            attachments.into_iter().map(|(a, t)| (Some(a), t)).unzip();
        check_unique(label, &names)?;
        let mut fb = Framebuffer::new(ctx, label, textures)?;
        fb.names = names;
        Ok(fb)
    }

    /// Like [`Framebuffer::new`], plus a 24-bit depth renderbuffer of the same size, for draws
    /// with a [`Depth`](super::Depth) test; [`clear`](Self::clear) resets it to the far plane.
    pub fn with_depth(ctx: &Context, label: &str, textures: Vec<Texture>) -> Result<Self> {
        let mut fb = Framebuffer::new(ctx, label, textures)?;
        let [w, h] = fb.size;
        // SAFETY: a fresh renderbuffer attached to a framebuffer this function owns.
        let raw = unsafe {
            let raw = ctx.gl().create_renderbuffer().map_err(Error::Gl)?;
            ctx.gl().bind_renderbuffer(glow::RENDERBUFFER, Some(raw));
            ctx.gl().renderbuffer_storage(
                glow::RENDERBUFFER,
                glow::DEPTH_COMPONENT24,
                w as i32,
                h as i32,
            );
            ctx.gl().bind_renderbuffer(glow::RENDERBUFFER, None);
            ctx.gl().bind_framebuffer(glow::FRAMEBUFFER, Some(fb.raw));
            ctx.gl().framebuffer_renderbuffer(
                glow::FRAMEBUFFER,
                glow::DEPTH_ATTACHMENT,
                glow::RENDERBUFFER,
                Some(raw),
            );
            raw
        };
        fb.depth = Some(raw);
        fb.checked()
    }

    /// Whether it has a depth attachment ([`Framebuffer::with_depth`]).
    pub fn has_depth(&self) -> bool {
        self.depth.is_some()
    }

    /// A framebuffer whose one colour attachment is layer `layer` (the z slice `k = layer`) of
    /// `texture`, checked for completeness: a full-screen pass into it writes texel `(i, j)` of
    /// that slice at `gl_FragCoord.xy = (i, j) + 0.5`.
    ///
    /// It does not own the texture; drop it before the texture (GL keeps an attached image alive
    /// until it is detached, so the other order leaks the storage for a moment but is not
    /// undefined).
    pub fn layer(ctx: &Context, label: &str, texture: &Texture3D, layer: u32) -> Result<Self> {
        let d = texture.size()[2];
        if layer >= d {
            return Err(Error::InvalidInput(format!(
                "framebuffer {label}: layer {layer} of a 3D texture of depth {d}"
            )));
        }
        Self::of_layers(ctx, label, texture, layer..layer + 1)
    }

    /// A framebuffer whose colour attachments `0..depth` are the layers of `texture` in order,
    /// checked for completeness: one pass writes every layer through multiple render targets
    /// (output `i` into layer `i`). Like [`Framebuffer::layer`], it does not own the texture.
    pub fn layers(ctx: &Context, label: &str, texture: &Texture3D) -> Result<Self> {
        let d = texture.size()[2];
        let limits = ctx.limits();
        let max = limits
            .max_draw_buffers
            .min(limits.max_color_attachments)
            .min(8);
        if d == 0 || d > max {
            return Err(Error::InvalidInput(format!(
                "framebuffer {label}: {d} layers as render targets (1 to {max})"
            )));
        }
        Self::of_layers(ctx, label, texture, 0..d)
    }

    /// Attaches `layers` of `texture` (checked by the callers) to colour attachments 0.. in order.
    fn of_layers(
        ctx: &Context,
        label: &str,
        texture: &Texture3D,
        layers: std::ops::Range<u32>,
    ) -> Result<Self> {
        let [w, h, _] = texture.size();
        let n = layers.len();
        // SAFETY: a fresh framebuffer; the texture is alive and belongs to this context, and
        // every layer lies inside it (the callers check).
        let raw = unsafe {
            let raw = ctx.gl().create_framebuffer().map_err(Error::Gl)?;
            ctx.gl().bind_framebuffer(glow::FRAMEBUFFER, Some(raw));
            let mut draw = Vec::with_capacity(n);
            for (k, layer) in layers.enumerate() {
                let point = glow::COLOR_ATTACHMENT0 + k as u32;
                ctx.gl().framebuffer_texture_layer(
                    glow::FRAMEBUFFER,
                    point,
                    Some(texture.raw()),
                    0,
                    layer as i32,
                );
                draw.push(point);
            }
            ctx.gl().draw_buffers(&draw);
            raw
        };
        Framebuffer {
            ctx: ctx.clone(),
            raw,
            textures: Vec::new(),
            writes: vec![texture.raw()],
            names: vec![None; n],
            size: [w, h],
            attachments: n,
            bytes_per_texel: n * texture.format().bytes_per_texel(),
            formats: vec![texture.format(); n],
            integer: texture.format() == TextureFormat::Rgba32Ui,
            depth: None,
            label: label.to_owned(),
        }
        .checked()
    }

    /// A framebuffer whose one colour attachment is attachment `at` of `source` (its name
    /// kept), which it does not own: a pass into it writes that texture alone (a pass without
    /// multiple render targets, Latta §3.1). Drop it before `source`, as for
    /// [`Framebuffer::layer`].
    pub fn attachment(
        ctx: &Context,
        label: &str,
        source: &Framebuffer,
        at: impl AttachmentKey,
    ) -> Result<Self> {
        let i = at.index_in(source);
        let Some(texture) = source.textures.get(i) else {
            return Err(Error::InvalidInput(format!(
                "framebuffer {label}: {} has no texture of its own at {at:?}",
                source.label
            )));
        };
        // SAFETY: a fresh framebuffer; the texture is alive and belongs to this context.
        let raw = unsafe {
            let raw = ctx.gl().create_framebuffer().map_err(Error::Gl)?;
            ctx.gl().bind_framebuffer(glow::FRAMEBUFFER, Some(raw));
            ctx.gl().framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                glow::COLOR_ATTACHMENT0,
                glow::TEXTURE_2D,
                Some(texture.raw()),
                0,
            );
            ctx.gl().draw_buffers(&[glow::COLOR_ATTACHMENT0]);
            raw
        };
        Framebuffer {
            ctx: ctx.clone(),
            raw,
            textures: Vec::new(),
            writes: vec![texture.raw()],
            names: vec![source.names[i]],
            size: source.size,
            attachments: 1,
            bytes_per_texel: texture.format().bytes_per_texel(),
            formats: vec![texture.format()],
            integer: texture.format() == TextureFormat::Rgba32Ui,
            depth: None,
            label: label.to_owned(),
        }
        .checked()
    }

    /// A framebuffer whose colour attachments are, in order, attachment `k` of each
    /// `(framebuffer, k)` of `sources`, which it does not own: one pass writes textures of
    /// several framebuffers through multiple render targets (the integration pass and the user
    /// states it updates). Refused past `GL_MAX_DRAW_BUFFERS` or `GL_MAX_COLOR_ATTACHMENTS`.
    /// Drop it before the sources, as for [`Framebuffer::layer`].
    pub fn views(ctx: &Context, label: &str, sources: &[(&Framebuffer, usize)]) -> Result<Self> {
        let limits = ctx.limits();
        let max = limits.max_draw_buffers.min(limits.max_color_attachments) as usize;
        if sources.is_empty() || sources.len() > max {
            return Err(Error::InvalidInput(format!(
                "framebuffer {label} needs 1 to {max} attachments (GL_MAX_DRAW_BUFFERS, \
                 GL_MAX_COLOR_ATTACHMENTS), got {}",
                sources.len()
            )));
        }
        let mut textures = Vec::with_capacity(sources.len());
        for (fb, k) in sources {
            let Some(t) = fb.textures.get(*k) else {
                return Err(Error::InvalidInput(format!(
                    "framebuffer {label}: {} has no texture of its own at {k}",
                    fb.label
                )));
            };
            textures.push(t);
        }
        let size = sources[0].0.size;
        if sources.iter().any(|(fb, _)| fb.size != size) {
            return Err(Error::InvalidInput(format!(
                "framebuffer {label}: attachments differ in size"
            )));
        }
        let raw = attach(ctx, &textures)?;
        Framebuffer {
            ctx: ctx.clone(),
            raw,
            textures: Vec::new(),
            writes: textures.iter().map(|t| t.raw()).collect(),
            names: (sources.iter()).map(|(fb, k)| fb.names[*k]).collect(),
            size,
            attachments: textures.len(),
            bytes_per_texel: textures.iter().map(|t| t.format().bytes_per_texel()).sum(),
            integer: textures
                .iter()
                .any(|t| t.format() == TextureFormat::Rgba32Ui),
            formats: textures.iter().map(|t| t.format()).collect(),
            depth: None,
            label: label.to_owned(),
        }
        .checked()
    }

    /// Labels the (bound) framebuffer, checks its completeness and unbinds it.
    fn checked(self) -> Result<Self> {
        let (ctx, label) = (&self.ctx, &self.label);
        ctx.label(glow::FRAMEBUFFER, self.raw.0.get(), label);
        // SAFETY: the framebuffer is bound.
        let status = unsafe { ctx.gl().check_framebuffer_status(glow::FRAMEBUFFER) };
        // SAFETY: unbinding has no preconditions.
        unsafe { ctx.gl().bind_framebuffer(glow::FRAMEBUFFER, None) };
        if status != glow::FRAMEBUFFER_COMPLETE {
            return Err(Error::FramebufferIncomplete {
                label: label.to_owned(),
                reason: incomplete(status),
            });
        }
        ctx.check_error(&format!("creating framebuffer {label}"))?;
        Ok(self)
    }

    /// Number of colour attachments (render targets).
    pub fn attachments(&self) -> usize {
        self.attachments
    }
    /// Whether the attachments hold unsigned integers: a pass into it writes `uvec4`s.
    pub fn integer(&self) -> bool {
        self.integer
    }
    /// Bytes a fragment writes into all attachments.
    pub fn bytes_per_texel(&self) -> usize {
        self.bytes_per_texel
    }
    /// Each attachment's format, in order.
    pub fn formats(&self) -> &[TextureFormat] {
        &self.formats
    }
    /// Width of the attachments.
    pub fn width(&self) -> u32 {
        self.size[0]
    }
    /// Height of the attachments.
    pub fn height(&self) -> u32 {
        self.size[1]
    }
    /// The texture of attachment `at`: an [`Attachment`] handle of a framebuffer made with
    /// names ([`Framebuffer::named`], [`PingPong::new`](super::PingPong::new)). Owned
    /// attachments only: a [`Framebuffer::layer`] has none.
    ///
    /// # Panics
    /// If the framebuffer has no attachment `at` (a handle of another kind of state).
    pub fn texture(&self, at: impl AttachmentKey) -> &Texture {
        let i = at.index_in(self);
        match self.textures.get(i) {
            Some(t) => t,
            None => panic!(
                "framebuffer {} does not own its attachments (layers of a 3D texture)",
                self.label
            ),
        }
    }
    /// The texture of a framebuffer with one attachment, which needs no name.
    ///
    /// # Panics
    /// If it has more than one attachment, or does not own it.
    pub fn only_texture(&self) -> &Texture {
        assert!(
            self.textures.len() == 1,
            "framebuffer {} has {} attachments: name the one meant",
            self.label,
            self.attachments
        );
        &self.textures[0]
    }
    /// All owned attachments in order (none for a [`Framebuffer::layer`]).
    pub fn textures(&self) -> &[Texture] {
        &self.textures
    }
    /// The attachments' names in order (`None` for attachments made without one).
    pub fn names(&self) -> &[Option<Attachment>] {
        &self.names
    }
    /// The label given at creation.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// Binds it as the draw target with a viewport over all of it.
    pub fn bind(&self) {
        self.bind_rect(0, 0, self.width(), self.height());
    }

    /// Binds it as the draw target with a viewport over a rectangle: `gl_FragCoord` stays in
    /// texel coordinates of the whole attachment, so `texelFetch` needs no offset.
    pub fn bind_rect(&self, x: u32, y: u32, w: u32, h: u32) {
        // SAFETY: the framebuffer is alive and complete.
        unsafe {
            self.ctx
                .gl()
                .bind_framebuffer(glow::FRAMEBUFFER, Some(self.raw));
            self.ctx
                .gl()
                .viewport(x as i32, y as i32, w as i32, h as i32);
        }
    }

    /// Copies attachment 0 into the rectangle `dst` = `[x, y, width, height]` (from the bottom
    /// left) of the default framebuffer (a window's back buffer, see
    /// [`Context::from_current`]), scaled linearly when the sizes differ, then leaves framebuffer
    /// 0 bound for the caller's own drawing.
    pub fn blit_to_default(&self, dst: [u32; 4]) -> Result<()> {
        let [x, y, w, h] = dst.map(|v| v as i32);
        let same = (w, h) == (self.width() as i32, self.height() as i32);
        // SAFETY: both framebuffers exist; attachment 0 is a colour texture of this size.
        unsafe {
            self.ctx
                .gl()
                .bind_framebuffer(glow::READ_FRAMEBUFFER, Some(self.raw));
            self.ctx.gl().read_buffer(glow::COLOR_ATTACHMENT0);
            self.ctx.gl().bind_framebuffer(glow::DRAW_FRAMEBUFFER, None);
            self.ctx.gl().disable(glow::SCISSOR_TEST);
            self.ctx.gl().blit_framebuffer(
                0,
                0,
                self.width() as i32,
                self.height() as i32,
                x,
                y,
                x + w,
                y + h,
                glow::COLOR_BUFFER_BIT,
                if same { glow::NEAREST } else { glow::LINEAR },
            );
            self.ctx.gl().bind_framebuffer(glow::FRAMEBUFFER, None);
        }
        self.ctx.check_error(&format!(
            "blitting {} to the default framebuffer",
            self.label
        ))
    }

    /// Clears every colour attachment to `rgba`, and the depth attachment (if any) to the far
    /// plane.
    pub fn clear(&self, rgba: [f32; 4]) {
        self.bind();
        let texels = self.width() as u64 * self.height() as u64 * self.attachments as u64;
        self.ctx.count_clear(texels);
        // SAFETY: the framebuffer is bound.
        unsafe {
            for i in 0..self.attachments {
                self.ctx
                    .gl()
                    .clear_buffer_f32_slice(glow::COLOR, i as u32, &rgba);
            }
            if self.depth.is_some() {
                // A clear obeys the depth mask, which the last draw may have turned off.
                self.ctx.gl().depth_mask(true);
                self.ctx.gl().clear_buffer_f32_slice(glow::DEPTH, 0, &[1.0]);
            }
        }
    }
}

impl Drop for Framebuffer {
    fn drop(&mut self) {
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe {
                gl.delete_framebuffer(self.raw);
                if let Some(d) = self.depth {
                    gl.delete_renderbuffer(d);
                }
            }
        }
    }
}

impl Context {
    /// Reads the bottom-left `width`×`height` pixels of the default framebuffer's back buffer
    /// (a window's frame before the swap) as RGB with the first row at the top.
    pub fn read_default_rgb(&self, width: u32, height: u32) -> Result<image::RgbImage> {
        let mut rgba = vec![0u8; 4 * width as usize * height as usize];
        // SAFETY: framebuffer 0 exists on a window's context; the buffer holds w*h RGBA texels.
        unsafe {
            self.gl().bind_framebuffer(glow::FRAMEBUFFER, None);
            self.gl().read_buffer(glow::BACK);
            self.gl().pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            self.gl().read_pixels(
                0,
                0,
                width as i32,
                height as i32,
                glow::RGBA,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut rgba)),
            );
        }
        self.check_error("reading the default framebuffer")?;
        let mut out = image::RgbImage::new(width, height);
        for (y, row) in rgba.chunks_exact(4 * width as usize).enumerate() {
            for (x, px) in row.chunks_exact(4).enumerate() {
                out.put_pixel(
                    x as u32,
                    height - 1 - y as u32,
                    image::Rgb([px[0], px[1], px[2]]),
                );
            }
        }
        Ok(out)
    }
}

fn textures_integer(textures: &[Texture]) -> bool {
    textures
        .iter()
        .any(|t| t.format() == TextureFormat::Rgba32Ui)
}

/// A fresh framebuffer object with `textures` as colour attachments 0.. in order, all drawn
/// into (left bound: the caller checks completeness).
fn attach(ctx: &Context, textures: &[&Texture]) -> Result<glow::Framebuffer> {
    // SAFETY: a fresh framebuffer; the textures are alive and belong to this context.
    unsafe {
        let raw = ctx.gl().create_framebuffer().map_err(Error::Gl)?;
        ctx.gl().bind_framebuffer(glow::FRAMEBUFFER, Some(raw));
        let mut draw = Vec::with_capacity(textures.len());
        for (i, t) in textures.iter().enumerate() {
            let point = glow::COLOR_ATTACHMENT0 + i as u32;
            (ctx.gl()).framebuffer_texture_2d(
                glow::FRAMEBUFFER,
                point,
                glow::TEXTURE_2D,
                Some(t.raw()),
                0,
            );
            draw.push(point);
        }
        ctx.gl().draw_buffers(&draw);
        Ok(raw)
    }
}
