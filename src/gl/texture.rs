//! 2D textures holding particle state or rendered images: nearest filtering, clamp to edge,
//! read in shaders with `texelFetch` only.

use glow::HasContext;

use super::Context;
use crate::error::{Error, Result};

/// The texel formats texflow uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
pub enum TextureFormat {
    /// Four 32-bit floats: positions, and full-precision velocities.
    Rgba32F,
    /// Four 16-bit floats: Latta's velocities.
    Rgba16F,
    /// Two 32-bit floats: (key, id) pairs of the sort.
    Rg32F,
    /// One 32-bit float.
    R32F,
    /// Four 8-bit normalised channels: rendered frames.
    Rgba8,
    /// Four 32-bit unsigned integers: the compact blocked sort's packed entries (bit patterns
    /// that a float format might canonicalise or flush). Render targets only: no upload.
    Rgba32Ui,
}

impl TextureFormat {
    /// The sized internal format.
    pub fn internal(self) -> u32 {
        match self {
            TextureFormat::Rgba32F => glow::RGBA32F,
            TextureFormat::Rgba16F => glow::RGBA16F,
            TextureFormat::Rg32F => glow::RG32F,
            TextureFormat::R32F => glow::R32F,
            TextureFormat::Rgba8 => glow::RGBA8,
            TextureFormat::Rgba32Ui => glow::RGBA32UI,
        }
    }

    /// The client format of uploads and read-backs.
    pub fn client_format(self) -> u32 {
        match self {
            TextureFormat::Rgba32F | TextureFormat::Rgba16F | TextureFormat::Rgba8 => glow::RGBA,
            TextureFormat::Rg32F => glow::RG,
            TextureFormat::R32F => glow::RED,
            TextureFormat::Rgba32Ui => glow::RGBA_INTEGER,
        }
    }

    /// The client type of uploads and read-backs.
    pub fn client_type(self) -> u32 {
        match self {
            TextureFormat::Rgba8 => glow::UNSIGNED_BYTE,
            TextureFormat::Rgba32Ui => glow::UNSIGNED_INT,
            TextureFormat::Rgba32F
            | TextureFormat::Rgba16F
            | TextureFormat::Rg32F
            | TextureFormat::R32F => glow::FLOAT,
        }
    }

    /// Channels per texel.
    pub fn channels(self) -> usize {
        match self {
            TextureFormat::Rgba32F
            | TextureFormat::Rgba16F
            | TextureFormat::Rgba8
            | TextureFormat::Rgba32Ui => 4,
            TextureFormat::Rg32F => 2,
            TextureFormat::R32F => 1,
        }
    }

    /// Bytes one texel occupies on the GPU, which is what a pass writing it costs.
    pub fn bytes_per_texel(self) -> usize {
        match self {
            TextureFormat::Rgba32F | TextureFormat::Rgba32Ui => 16,
            TextureFormat::Rgba16F | TextureFormat::Rg32F => 8,
            TextureFormat::R32F | TextureFormat::Rgba8 => 4,
        }
    }

    /// Whether the channels are floats (read back as `f32`).
    pub fn is_float(self) -> bool {
        !matches!(self, TextureFormat::Rgba8 | TextureFormat::Rgba32Ui)
    }

    /// A short name for tables and labels.
    pub fn name(self) -> &'static str {
        match self {
            TextureFormat::Rgba32F => "RGBA32F",
            TextureFormat::Rgba16F => "RGBA16F",
            TextureFormat::Rg32F => "RG32F",
            TextureFormat::R32F => "R32F",
            TextureFormat::Rgba8 => "RGBA8",
            TextureFormat::Rgba32Ui => "RGBA32UI",
        }
    }
}

/// What to make.
#[derive(Debug, Clone, Copy)]
pub struct TextureDesc<'a> {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Texel format.
    pub format: TextureFormat,
    /// Debug label, e.g. `"position:0"`.
    pub label: &'a str,
}

/// An owned 2D texture, deleted on drop.
pub struct Texture {
    ctx: Context,
    raw: glow::Texture,
    /// Its serial number (see [`RecordedTexture`](super::RecordedTexture)).
    serial: u64,
    width: u32,
    height: u32,
    format: TextureFormat,
}

impl std::fmt::Debug for Texture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Texture({}x{} {})",
            self.width,
            self.height,
            self.format.name()
        )
    }
}

/// Checks a texture size against the context's limit, naming the limit in the error.
pub fn check_size(ctx: &Context, what: &str, width: u32, height: u32) -> Result<()> {
    let max = ctx.limits().max_texture_size;
    if width == 0 || height == 0 {
        return Err(Error::InvalidInput(format!(
            "{what} {width}x{height} is empty: both sides must be at least 1"
        )));
    }
    if width > max || height > max {
        return Err(Error::InvalidInput(format!(
            "{what} {width}x{height} exceeds this device's GL_MAX_TEXTURE_SIZE of {max}: \
             use sides of at most {max}"
        )));
    }
    Ok(())
}

impl Texture {
    /// Allocates an uninitialised texture.
    pub fn new(ctx: &Context, desc: TextureDesc<'_>) -> Result<Self> {
        check_size(ctx, desc.label, desc.width, desc.height)?;
        // SAFETY: a fresh texture object is configured on a current context.
        let raw = unsafe {
            let raw = ctx.gl().create_texture().map_err(Error::Gl)?;
            ctx.gl().bind_texture(glow::TEXTURE_2D, Some(raw));
            ctx.gl().tex_image_2d(
                glow::TEXTURE_2D,
                0,
                desc.format.internal() as i32,
                desc.width as i32,
                desc.height as i32,
                0,
                desc.format.client_format(),
                desc.format.client_type(),
                glow::PixelUnpackData::Slice(None),
            );
            for (p, v) in [
                (glow::TEXTURE_MIN_FILTER, glow::NEAREST),
                (glow::TEXTURE_MAG_FILTER, glow::NEAREST),
                (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE),
                (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE),
            ] {
                ctx.gl().tex_parameter_i32(glow::TEXTURE_2D, p, v as i32);
            }
            ctx.gl().bind_texture(glow::TEXTURE_2D, None);
            raw
        };
        let tex = Texture {
            ctx: ctx.clone(),
            raw,
            serial: super::record::made(raw),
            width: desc.width,
            height: desc.height,
            format: desc.format,
        };
        ctx.label(glow::TEXTURE, raw.0.get(), desc.label);
        ctx.check_error(&format!("allocating texture {}", desc.label))?;
        Ok(tex)
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Number of texels.
    pub fn texels(&self) -> usize {
        self.width as usize * self.height as usize
    }
    /// Texel format.
    pub fn format(&self) -> TextureFormat {
        self.format
    }
    /// The GL name, for the GL layer.
    pub(crate) fn raw(&self) -> glow::Texture {
        self.raw
    }

    /// Switches from the state textures' nearest filtering to trilinear filtering: mipmaps of
    /// levels `1..=max_level` generated from the current contents, `LINEAR_MIPMAP_LINEAR` for
    /// minification, `LINEAR` for magnification (the sprite atlas, Latta §3.4.6).
    pub fn filter_linear_mipmapped(&self, max_level: u32) -> Result<()> {
        let gl = &self.ctx;
        // SAFETY: the texture is alive; these are plain parameter settings on it.
        unsafe {
            gl.gl().bind_texture(glow::TEXTURE_2D, Some(self.raw));
            gl.gl()
                .tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAX_LEVEL, max_level as i32);
            gl.gl().generate_mipmap(glow::TEXTURE_2D);
            gl.gl().tex_parameter_i32(
                glow::TEXTURE_2D,
                glow::TEXTURE_MIN_FILTER,
                glow::LINEAR_MIPMAP_LINEAR as i32,
            );
            gl.gl().tex_parameter_i32(
                glow::TEXTURE_2D,
                glow::TEXTURE_MAG_FILTER,
                glow::LINEAR as i32,
            );
            gl.gl().bind_texture(glow::TEXTURE_2D, None);
        }
        gl.check_error("generating mipmaps")
    }

    fn expect_len(&self, len: usize) -> Result<()> {
        let want = self.texels() * self.format.channels();
        if len != want {
            return Err(Error::InvalidInput(format!(
                "texture data has {len} values, a {}x{} {} texture needs {want}",
                self.width,
                self.height,
                self.format.name()
            )));
        }
        Ok(())
    }

    /// Replaces the whole texture with `data` (row-major from the bottom row, `channels` floats a
    /// texel). Used for initial states and tests; the pipeline itself changes state by drawing.
    pub fn upload_f32(&self, data: &[f32]) -> Result<()> {
        self.expect_len(data.len())?;
        if !self.format.is_float() {
            return Err(Error::InvalidInput(format!(
                "float upload into a {} texture",
                self.format.name()
            )));
        }
        self.upload_raw(0, self.height, bytemuck::cast_slice(data), glow::FLOAT)
    }

    /// Replaces rows `y0..y0+rows` with `data`.
    pub fn upload_rows_f32(&self, y0: u32, rows: u32, data: &[f32]) -> Result<()> {
        if y0 + rows > self.height
            || data.len() != (rows * self.width) as usize * self.format.channels()
        {
            return Err(Error::InvalidInput("row upload out of range".into()));
        }
        self.upload_raw(y0, rows, bytemuck::cast_slice(data), glow::FLOAT)
    }

    fn upload_raw(&self, y0: u32, rows: u32, bytes: &[u8], ty: u32) -> Result<()> {
        // SAFETY: the data length was checked against the region.
        unsafe {
            self.ctx.gl().pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            self.ctx.gl().bind_texture(glow::TEXTURE_2D, Some(self.raw));
            self.ctx.gl().tex_sub_image_2d(
                glow::TEXTURE_2D,
                0,
                0,
                y0 as i32,
                self.width as i32,
                rows as i32,
                self.format.client_format(),
                ty,
                glow::PixelUnpackData::Slice(Some(bytes)),
            );
            self.ctx.gl().bind_texture(glow::TEXTURE_2D, None);
        }
        self.ctx.check_error("texture upload")
    }

    /// Reads the whole texture back as floats (any float format, converted by GL).
    pub fn read_f32(&self) -> Result<Vec<f32>> {
        let mut out = vec![0f32; self.texels() * self.format.channels()];
        if !self.format.is_float() {
            return Err(Error::InvalidInput(format!(
                "float read-back of a {} texture",
                self.format.name()
            )));
        }
        self.read_raw(bytemuck::cast_slice_mut(&mut out), glow::FLOAT)?;
        Ok(out)
    }

    /// Reads an RGBA8 texture back as bytes.
    pub fn read_u8(&self) -> Result<Vec<u8>> {
        let mut out = vec![0u8; self.texels() * self.format.channels()];
        self.read_raw(&mut out, glow::UNSIGNED_BYTE)?;
        Ok(out)
    }

    fn read_raw(&self, out: &mut [u8], ty: u32) -> Result<()> {
        // SAFETY: `out` holds exactly the texture's texels in the requested client format.
        unsafe {
            self.ctx.gl().pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            self.ctx.gl().bind_texture(glow::TEXTURE_2D, Some(self.raw));
            self.ctx.gl().get_tex_image(
                glow::TEXTURE_2D,
                0,
                self.format.client_format(),
                ty,
                glow::PixelPackData::Slice(Some(out)),
            );
            self.ctx.gl().bind_texture(glow::TEXTURE_2D, None);
        }
        self.ctx.check_error("texture read-back")
    }

    /// This texture by name, as a recorded draw names what it read (a floor that reads the
    /// same data binds it by name while it lives).
    pub fn recorded(&self) -> super::RecordedTexture {
        super::RecordedTexture {
            raw: self.raw,
            serial: self.serial,
            shape: super::ReadShape {
                size: [self.width, self.height, 1],
                three_d: false,
                format: self.format,
            },
        }
    }

    /// Binds the texture to texture unit `unit`.
    pub(super) fn bind(&self, unit: u32) {
        // SAFETY: the texture is alive and belongs to this context.
        unsafe {
            self.ctx.gl().active_texture(glow::TEXTURE0 + unit);
            self.ctx.gl().bind_texture(glow::TEXTURE_2D, Some(self.raw));
        }
    }
}

impl Drop for Texture {
    fn drop(&mut self) {
        super::record::freed(self.raw);
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe { gl.delete_texture(self.raw) }
        }
    }
}
