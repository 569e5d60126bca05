//! Buffer objects: vertex data for GP/FP geometry and the texture-to-vertex copy path.

use glow::HasContext;

use super::Context;
use crate::error::{Error, Result};

/// What a buffer is bound as when it is filled (a hint to the driver; GL buffers are typeless,
/// a vertex array can read any of them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BufferKind {
    /// `GL_ARRAY_BUFFER`: vertex data written by the CPU.
    Vertex,
    /// `GL_PIXEL_PACK_BUFFER`: written on the GPU by [`PixelPack`](super::PixelPack).
    PixelPack,
}

impl BufferKind {
    fn target(self) -> u32 {
        match self {
            BufferKind::Vertex => glow::ARRAY_BUFFER,
            BufferKind::PixelPack => glow::PIXEL_PACK_BUFFER,
        }
    }
}

/// How often the contents change and who writes them (GL's usage hint).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BufferUsage {
    /// Written once by the CPU, drawn many times.
    StaticDraw,
    /// Written by the CPU for about one draw.
    StreamDraw,
    /// Written by GL for about one draw.
    StreamCopy,
}

impl BufferUsage {
    fn gl(self) -> u32 {
        match self {
            BufferUsage::StaticDraw => glow::STATIC_DRAW,
            BufferUsage::StreamDraw => glow::STREAM_DRAW,
            BufferUsage::StreamCopy => glow::STREAM_COPY,
        }
    }
}

/// An owned buffer object, deleted on drop.
pub struct Buffer {
    ctx: Context,
    raw: glow::Buffer,
    size: usize,
    kind: BufferKind,
    usage: BufferUsage,
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
        kind: BufferKind,
        data: &[u8],
        usage: BufferUsage,
    ) -> Result<Self> {
        let target = kind.target();
        // SAFETY: a fresh buffer object filled from a live slice.
        let raw = unsafe {
            let raw = ctx.gl().create_buffer().map_err(Error::Gl)?;
            ctx.gl().bind_buffer(target, Some(raw));
            ctx.gl().buffer_data_u8_slice(target, data, usage.gl());
            ctx.gl().bind_buffer(target, None);
            raw
        };
        ctx.label(glow::BUFFER, raw.0.get(), label);
        ctx.check_error(&format!("creating buffer {label}"))?;
        Ok(Buffer {
            ctx: ctx.clone(),
            raw,
            size: data.len(),
            kind,
            usage,
        })
    }

    /// Makes a buffer of `size` uninitialised bytes.
    pub fn with_size(
        ctx: &Context,
        label: &str,
        kind: BufferKind,
        size: usize,
        usage: BufferUsage,
    ) -> Result<Self> {
        let target = kind.target();
        // SAFETY: as above, no data.
        let raw = unsafe {
            let raw = ctx.gl().create_buffer().map_err(Error::Gl)?;
            ctx.gl().bind_buffer(target, Some(raw));
            ctx.gl().buffer_data_size(target, size as i32, usage.gl());
            ctx.gl().bind_buffer(target, None);
            raw
        };
        ctx.label(glow::BUFFER, raw.0.get(), label);
        ctx.check_error(&format!("creating buffer {label}"))?;
        Ok(Buffer {
            ctx: ctx.clone(),
            raw,
            size,
            kind,
            usage,
        })
    }

    /// Replaces the contents with `data` (at most [`size`](Self::size) bytes) from offset 0: the
    /// storage is orphaned first, so a draw still reading the old contents does not stall the
    /// write, then refilled with `glBufferSubData`. Bytes past `data` are undefined afterwards.
    pub fn replace(&self, data: &[u8]) -> Result<()> {
        if data.len() > self.size {
            return Err(Error::InvalidInput(format!(
                "{} bytes written into a buffer of {}",
                data.len(),
                self.size
            )));
        }
        let (gl, target) = (&self.ctx, self.kind.target());
        // SAFETY: the buffer is alive; `data` fits its size (checked above).
        unsafe {
            gl.gl().bind_buffer(target, Some(self.raw));
            gl.gl()
                .buffer_data_size(target, self.size as i32, self.usage.gl());
            if !data.is_empty() {
                gl.gl().buffer_sub_data_u8_slice(target, 0, data);
            }
            gl.gl().bind_buffer(target, None);
        }
        Ok(())
    }

    /// Size in bytes.
    pub fn size(&self) -> usize {
        self.size
    }

    /// The GL name, for the GL layer.
    pub(crate) fn raw(&self) -> glow::Buffer {
        self.raw
    }
}

impl Drop for Buffer {
    fn drop(&mut self) {
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe { gl.delete_buffer(self.raw) }
        }
    }
}

/// An owned vertex array object. Core profile needs one bound for every draw, even an
/// attribute-less one.
pub struct VertexArray {
    ctx: Context,
    raw: glow::VertexArray,
    indexed: bool,
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
        Self::make(ctx, label, attributes, None)
    }

    /// A vertex array with `attributes` whose draws read vertex numbers from `indices`
    /// (`u32` each, bound as the element array): a draw's count is then a number of indices,
    /// and `gl_VertexID` the index read.
    pub fn with_indices(
        ctx: &Context,
        label: &str,
        attributes: &[Attribute<'_>],
        indices: &Buffer,
    ) -> Result<Self> {
        Self::make(ctx, label, attributes, Some(indices))
    }

    /// Whether draws read an index buffer ([`with_indices`](Self::with_indices)).
    pub fn indexed(&self) -> bool {
        self.indexed
    }

    fn make(
        ctx: &Context,
        label: &str,
        attributes: &[Attribute<'_>],
        indices: Option<&Buffer>,
    ) -> Result<Self> {
        // SAFETY: the buffers are alive and belong to this context.
        let raw = unsafe {
            let raw = ctx.gl().create_vertex_array().map_err(Error::Gl)?;
            ctx.gl().bind_vertex_array(Some(raw));
            for a in attributes {
                ctx.gl()
                    .bind_buffer(glow::ARRAY_BUFFER, Some(a.buffer.raw()));
                ctx.gl().enable_vertex_attrib_array(a.location);
                ctx.gl().vertex_attrib_pointer_f32(
                    a.location,
                    a.components,
                    glow::FLOAT,
                    false,
                    a.stride,
                    a.offset,
                );
            }
            if let Some(i) = indices {
                // Vertex array state: the binding stays with it when it is unbound.
                ctx.gl()
                    .bind_buffer(glow::ELEMENT_ARRAY_BUFFER, Some(i.raw()));
            }
            ctx.gl().bind_vertex_array(None);
            ctx.gl().bind_buffer(glow::ARRAY_BUFFER, None);
            raw
        };
        ctx.label(glow::VERTEX_ARRAY, raw.0.get(), label);
        ctx.check_error(&format!("creating vertex array {label}"))?;
        Ok(VertexArray {
            ctx: ctx.clone(),
            raw,
            indexed: indices.is_some(),
        })
    }

    /// Binds it for the next draws.
    pub fn bind(&self) {
        // SAFETY: the vertex array is alive.
        unsafe { self.ctx.gl().bind_vertex_array(Some(self.raw)) }
    }
}

impl Drop for VertexArray {
    fn drop(&mut self) {
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe { gl.delete_vertex_array(self.raw) }
        }
    }
}
