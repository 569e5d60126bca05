//! Buffer objects: vertex data for GP/FP geometry and the texture-to-vertex copy path.

use glow::HasContext;

use super::Context;
use crate::error::{Error, Result};

/// An owned buffer object, deleted on drop.
pub struct Buffer {
    ctx: Context,
    raw: glow::Buffer,
    size: usize,
}

impl std::fmt::Debug for Buffer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Buffer({} bytes)", self.size)
    }
}

impl Buffer {
    /// Makes a buffer holding `data`, bound once to `target` to give it storage.
    pub fn with_data(
        ctx: &Context,
        label: &str,
        target: u32,
        data: &[u8],
        usage: u32,
    ) -> Result<Self> {
        // SAFETY: a fresh buffer object filled from a live slice.
        let raw = unsafe {
            let raw = ctx.create_buffer().map_err(Error::Gl)?;
            ctx.bind_buffer(target, Some(raw));
            ctx.buffer_data_u8_slice(target, data, usage);
            ctx.bind_buffer(target, None);
            raw
        };
        ctx.label(glow::BUFFER, raw.0.get(), label);
        ctx.check_error(&format!("creating buffer {label}"))?;
        Ok(Buffer {
            ctx: ctx.clone(),
            raw,
            size: data.len(),
        })
    }

    /// Makes a buffer of `size` uninitialised bytes.
    pub fn with_size(
        ctx: &Context,
        label: &str,
        target: u32,
        size: usize,
        usage: u32,
    ) -> Result<Self> {
        // SAFETY: as above, no data.
        let raw = unsafe {
            let raw = ctx.create_buffer().map_err(Error::Gl)?;
            ctx.bind_buffer(target, Some(raw));
            ctx.buffer_data_size(target, size as i32, usage);
            ctx.bind_buffer(target, None);
            raw
        };
        ctx.label(glow::BUFFER, raw.0.get(), label);
        ctx.check_error(&format!("creating buffer {label}"))?;
        Ok(Buffer {
            ctx: ctx.clone(),
            raw,
            size,
        })
    }

    /// Size in bytes.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The GL name.
    pub fn raw(&self) -> glow::Buffer {
        self.raw
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        // SAFETY: the context outlives the buffer.
        unsafe { self.ctx.delete_buffer(self.raw) }
    }
}

/// An owned vertex array object. Core profile needs one bound for every draw, even an
/// attribute-less one.
pub struct VertexArray {
    ctx: Context,
    raw: glow::VertexArray,
}

impl std::fmt::Debug for VertexArray {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("VertexArray")
    }
}

/// One float vertex attribute read from a buffer.
#[derive(Debug, Clone, Copy)]
pub struct Attribute<'a> {
    /// The buffer holding the data.
    pub buffer: &'a Buffer,
    /// Attribute location in the program (`layout(location = N)`).
    pub location: u32,
    /// Floats per vertex (1 to 4).
    pub components: i32,
    /// Bytes between consecutive vertices.
    pub stride: i32,
    /// Byte offset of the first vertex.
    pub offset: i32,
}

impl VertexArray {
    /// A vertex array with no attributes, for draws that use `gl_VertexID`.
    pub fn empty(ctx: &Context, label: &str) -> Result<Self> {
        Self::with_attributes(ctx, label, &[])
    }

    /// A vertex array reading float attributes from buffers.
    pub fn with_attributes(
        ctx: &Context,
        label: &str,
        attributes: &[Attribute<'_>],
    ) -> Result<Self> {
        // SAFETY: the buffers are alive and belong to this context.
        let raw = unsafe {
            let raw = ctx.create_vertex_array().map_err(Error::Gl)?;
            ctx.bind_vertex_array(Some(raw));
            for a in attributes {
                ctx.bind_buffer(glow::ARRAY_BUFFER, Some(a.buffer.raw()));
                ctx.enable_vertex_attrib_array(a.location);
                ctx.vertex_attrib_pointer_f32(
                    a.location,
                    a.components,
                    glow::FLOAT,
                    false,
                    a.stride,
                    a.offset,
                );
            }
            ctx.bind_vertex_array(None);
            ctx.bind_buffer(glow::ARRAY_BUFFER, None);
            raw
        };
        ctx.label(glow::VERTEX_ARRAY, raw.0.get(), label);
        ctx.check_error(&format!("creating vertex array {label}"))?;
        Ok(VertexArray {
            ctx: ctx.clone(),
            raw,
        })
    }

    /// Binds it for the next draws.
    pub fn bind(&self) {
        // SAFETY: the vertex array is alive.
        unsafe { self.ctx.bind_vertex_array(Some(self.raw)) }
    }
}

impl Drop for VertexArray {
    fn drop(&mut self) {
        // SAFETY: the context outlives the vertex array.
        unsafe { self.ctx.delete_vertex_array(self.raw) }
    }
}
