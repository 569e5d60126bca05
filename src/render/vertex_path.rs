//! The particle renderer's vertex-buffer path (UberFlow §4.7, Latta §3.4.5): the state textures
//! copied into vertex buffers on the GPU (pixel pack), read as attributes.

use crate::error::{Error, Result};
use crate::gl::{Attribute, Buffer, BufferKind, BufferUsage, Context, PixelPack, VertexArray};

/// The vertex-buffer path's objects: the two buffers, the read framebuffer, the vertex array.
pub(super) struct VertexPath {
    pub(super) pack: PixelPack,
    pub(super) positions: Buffer,
    pub(super) statics: Buffer,
    pub(super) vao: VertexArray,
}

/// The vertex-buffer path: two buffers of `state_width`×`state_height` RGBA float vertices
/// (positions and statics, packed from the state textures each frame) and their vertex array.
pub(super) fn vertex_path(
    ctx: &Context,
    state_width: u32,
    state_height: u32,
) -> Result<VertexPath> {
    let bytes = state_width as u64 * state_height as u64 * 16;
    if bytes > i32::MAX as u64 {
        return Err(Error::InvalidInput(format!(
            "particle state {state_width}x{state_height} needs vertex buffers of {bytes} \
             bytes, over GL's limit of {} for one buffer: use the texture_fetch path or \
             a smaller state",
            i32::MAX
        )));
    }
    let buffer = |label| {
        Buffer::with_size(
            ctx,
            label,
            BufferKind::PixelPack,
            bytes as usize,
            BufferUsage::StreamCopy,
        )
    };
    let positions = buffer("position vertices")?;
    let statics = buffer("static vertices")?;
    let attribute = |buffer, location| Attribute {
        buffer,
        location,
        components: 4,
        stride: 16,
        offset: 0,
    };
    let vao = VertexArray::with_attributes(
        ctx,
        "particle vertices",
        &[attribute(&positions, 0), attribute(&statics, 1)],
    )?;
    Ok(VertexPath {
        pack: PixelPack::new(ctx)?,
        positions,
        statics,
        vao,
    })
}
