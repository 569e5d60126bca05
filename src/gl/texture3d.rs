//! 3D textures holding lookup fields (signed distance fields, wind flow fields): nearest
//! filtering, clamp to edge, read in shaders with `texelFetch` only (the interpolation is done by
//! hand in `glsl/sim/fields.glsl`, so that the CPU twins in `sim::fields` give the same numbers).

use glow::HasContext;

use super::{Context, TextureFormat};
use crate::error::{Error, Result};

/// An owned 3D texture, deleted on drop.
///
/// Texel `(i, j, k)` is `i` along x (width), `j` along y (height), `k` along z (depth); uploads
/// are x-fastest, then y, then z: value `c` of texel `(i, j, k)` is at
/// `((k * height + j) * width + i) * channels + c`.
pub struct Texture3D {
    ctx: Context,
    raw: glow::Texture,
    /// Its serial number (see [`RecordedTexture`](super::RecordedTexture)).
    serial: u64,
    size: [u32; 3],
    format: TextureFormat,
    label: String,
}

impl std::fmt::Debug for Texture3D {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [w, h, d] = self.size;
        write!(
            f,
            "Texture3D({} {w}x{h}x{d} {})",
            self.label,
            self.format.name()
        )
    }
}

/// Checks a 3D texture size against `GL_MAX_3D_TEXTURE_SIZE`, naming the limit in the error.
pub fn check_size_3d(ctx: &Context, what: &str, size: [u32; 3]) -> Result<()> {
    let max = ctx.limits().max_3d_texture_size;
    let [w, h, d] = size;
    if size.contains(&0) {
        return Err(Error::InvalidInput(format!(
            "{what} {w}x{h}x{d} is empty: every side must be at least 1"
        )));
    }
    if size.iter().any(|&s| s > max) {
        return Err(Error::InvalidInput(format!(
            "{what} {w}x{h}x{d} exceeds this device's GL_MAX_3D_TEXTURE_SIZE of {max}: \
             use sides of at most {max}"
        )));
    }
    Ok(())
}

impl Texture3D {
    /// Allocates a `size = [width, height, depth]` texture of a float `format` (the fields use
    /// RGBA32F and R32F), filled with `data` if given (see the type for the layout), else
    /// uninitialised; or of RGBA32UI, uninitialised (render targets of the compact sort).
    pub fn new(
        ctx: &Context,
        label: &str,
        format: TextureFormat,
        size: [u32; 3],
        data: Option<&[f32]>,
    ) -> Result<Self> {
        let targets_only = format == TextureFormat::Rgba32Ui && data.is_none();
        if !format.is_float() && !targets_only {
            return Err(Error::InvalidInput(format!(
                "3D texture {label}: {} is not a float format (use RGBA32F or R32F)",
                format.name()
            )));
        }
        check_size_3d(ctx, label, size)?;
        if let Some(data) = data {
            expect_len(label, format, size, data.len())?;
        }
        let [w, h, d] = size;
        // SAFETY: a fresh texture object is configured on a current context; the data length was
        // checked against the size.
        let raw = unsafe {
            let raw = ctx.gl().create_texture().map_err(Error::Gl)?;
            ctx.gl().pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            ctx.gl().bind_texture(glow::TEXTURE_3D, Some(raw));
            ctx.gl().tex_image_3d(
                glow::TEXTURE_3D,
                0,
                format.internal() as i32,
                w as i32,
                h as i32,
                d as i32,
                0,
                format.client_format(),
                format.client_type(),
                glow::PixelUnpackData::Slice(data.map(bytemuck::cast_slice)),
            );
            for (p, v) in [
                (glow::TEXTURE_MIN_FILTER, glow::NEAREST),
                (glow::TEXTURE_MAG_FILTER, glow::NEAREST),
                (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE),
                (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE),
                (glow::TEXTURE_WRAP_R, glow::CLAMP_TO_EDGE),
            ] {
                ctx.gl().tex_parameter_i32(glow::TEXTURE_3D, p, v as i32);
            }
            ctx.gl()
                .tex_parameter_i32(glow::TEXTURE_3D, glow::TEXTURE_MAX_LEVEL, 0);
            ctx.gl().bind_texture(glow::TEXTURE_3D, None);
            raw
        };
        let tex = Texture3D {
            ctx: ctx.clone(),
            raw,
            serial: super::record::made(raw),
            size,
            format,
            label: label.to_owned(),
        };
        ctx.label(glow::TEXTURE, raw.0.get(), label);
        ctx.check_error(&format!("allocating 3D texture {label}"))?;
        Ok(tex)
    }

    /// `[width, height, depth]` in texels.
    pub fn size(&self) -> [u32; 3] {
        self.size
    }
    /// Number of texels.
    pub fn texels(&self) -> usize {
        self.size.iter().map(|&s| s as usize).product()
    }
    /// Texel format.
    pub fn format(&self) -> TextureFormat {
        self.format
    }
    /// The label given at creation.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// Replaces the whole texture with `data` (layout: see the type).
    pub fn upload_f32(&self, data: &[f32]) -> Result<()> {
        if !self.format.is_float() {
            return Err(Error::InvalidInput(format!(
                "3D texture {}: {} holds no floats",
                self.label,
                self.format.name()
            )));
        }
        expect_len(&self.label, self.format, self.size, data.len())?;
        let [w, h, d] = self.size;
        // SAFETY: the data length was checked against the texture.
        unsafe {
            self.ctx.gl().pixel_store_i32(glow::UNPACK_ALIGNMENT, 1);
            self.ctx.gl().bind_texture(glow::TEXTURE_3D, Some(self.raw));
            self.ctx.gl().tex_sub_image_3d(
                glow::TEXTURE_3D,
                0,
                0,
                0,
                0,
                w as i32,
                h as i32,
                d as i32,
                self.format.client_format(),
                glow::FLOAT,
                glow::PixelUnpackData::Slice(Some(bytemuck::cast_slice(data))),
            );
            self.ctx.gl().bind_texture(glow::TEXTURE_3D, None);
        }
        self.ctx
            .check_error(&format!("uploading 3D texture {}", self.label))
    }

    /// Reads the whole texture back as floats (layout: see the type). For tests.
    pub fn read_f32(&self) -> Result<Vec<f32>> {
        if !self.format.is_float() {
            return Err(Error::InvalidInput(format!(
                "3D texture {}: {} holds no floats",
                self.label,
                self.format.name()
            )));
        }
        let mut out = vec![0f32; self.texels() * self.format.channels()];
        // SAFETY: `out` holds exactly the texture's texels in its client format.
        unsafe {
            self.ctx.gl().pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            self.ctx.gl().bind_texture(glow::TEXTURE_3D, Some(self.raw));
            self.ctx.gl().get_tex_image(
                glow::TEXTURE_3D,
                0,
                self.format.client_format(),
                glow::FLOAT,
                glow::PixelPackData::Slice(Some(bytemuck::cast_slice_mut(&mut out))),
            );
            self.ctx.gl().bind_texture(glow::TEXTURE_3D, None);
        }
        self.ctx
            .check_error(&format!("reading 3D texture {}", self.label))?;
        Ok(out)
    }

    /// The GL name, for the GL layer.
    pub(crate) fn raw(&self) -> glow::Texture {
        self.raw
    }

    /// This texture by name, as a recorded draw names what it read (a floor that reads the
    /// same data binds it by name while it lives).
    pub fn recorded(&self) -> super::RecordedTexture {
        super::RecordedTexture {
            raw: self.raw,
            serial: self.serial,
            shape: super::ReadShape {
                size: self.size(),
                three_d: true,
                format: self.format(),
            },
        }
    }

    /// Binds the texture to texture unit `unit` (a `sampler3D` uniform set to `unit` reads it).
    pub(super) fn bind(&self, unit: u32) {
        // SAFETY: the texture is alive and belongs to this context.
        unsafe {
            self.ctx.gl().active_texture(glow::TEXTURE0 + unit);
            self.ctx.gl().bind_texture(glow::TEXTURE_3D, Some(self.raw));
        }
    }
}

fn expect_len(label: &str, format: TextureFormat, size: [u32; 3], len: usize) -> Result<()> {
    let want = size.iter().map(|&s| s as usize).product::<usize>() * format.channels();
    if len != want {
        let [w, h, d] = size;
        return Err(Error::InvalidInput(format!(
            "3D texture {label}: data has {len} values, a {w}x{h}x{d} {} texture needs {want}",
            format.name()
        )));
    }
    Ok(())
}

impl Drop for Texture3D {
    fn drop(&mut self) {
        super::record::freed(self.raw);
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe { gl.delete_texture(self.raw) }
        }
    }
}
