//! The geometry of UberFlow's GP/FP passes: quads whose vertices carry the comparison's sign,
//! direction and partner, so that the fragment program derives nothing per texel (§4.3).

use super::Sorter;
use crate::error::Result;
use crate::gl::{Attribute, Buffer, BufferKind, BufferUsage, VertexArray};
use crate::sort::network::Step;

/// The three programs of the GP/FP variants: partners at a fixed offset, partners mirrored in the
/// block (a merge stage's first pass), both partners in one texel (packed, distance 1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(super) enum GpProgram {
    Plain,
    Mirror,
    SameTexel,
}

/// The geometry of one GP/FP pass: a key naming its shape (passes of the same shape share one
/// vertex buffer), the vertex data, the partner offset and the program.
pub(super) struct PassShape {
    pub(super) key: (u8, u32, u32),
    pub(super) vertices: Vec<f32>,
    pub(super) offset: (i32, i32),
    pub(super) program: GpProgram,
}

/// One shape's vertex buffer and the vertex array reading it.
#[derive(Debug)]
pub(super) struct Geometry {
    pub(super) vao: VertexArray,
    _buffer: Buffer,
    pub(super) vertices: u32,
}

impl Sorter {
    /// The quads of a GP/FP pass in texels of the sort texture: (shape key, vertex data, offset,
    /// program). Vertex: position (2 floats), attributes (sign, comparison, partner u, v).
    pub(super) fn quads(&self, step: &Step) -> PassShape {
        let Step::Bitonic {
            block,
            dist,
            mirror,
        } = *step
        else {
            unreachable!("GP/FP passes are bitonic");
        };
        let (w, h) = (self.width, self.height);
        let packed = self.variant.packed();
        let tw = if packed { w / 2 } else { w };
        if mirror {
            return mirror_shape(w, h, tw, block);
        }
        let asc_all = block > w;
        if dist >= w {
            return between_rows_shape(w, h, tw, dist);
        }
        let stage = if asc_all { 0 } else { block };
        if packed && dist == 1 {
            return same_texel_shape(h, tw, block, asc_all, stage);
        }
        row_shape(h, tw, [block, dist, stage], packed, asc_all)
    }

    /// Uploads one shape's vertices; returns its index in the sorter's geometry.
    pub(super) fn upload_geometry(&mut self, vertices: &[f32]) -> Result<usize> {
        let buffer = Buffer::with_data(
            &self.ctx,
            "sort quads",
            BufferKind::Vertex,
            bytemuck::cast_slice(vertices),
            BufferUsage::StaticDraw,
        )?;
        let stride = 6 * 4;
        let vao = VertexArray::with_attributes(
            &self.ctx,
            "sort quads",
            &[
                Attribute {
                    buffer: &buffer,
                    location: 0,
                    components: 2,
                    stride,
                    offset: 0,
                },
                Attribute {
                    buffer: &buffer,
                    location: 1,
                    components: 4,
                    stride,
                    offset: 8,
                },
            ],
        )?;
        self.geometry.push(Geometry {
            vao,
            _buffer: buffer,
            vertices: (vertices.len() / 6) as u32,
        });
        Ok(self.geometry.len() - 1)
    }
}

/// Appends the two triangles of the quad [x0, x1) × [y0, y1), each vertex with `attr` of its
/// corner.
fn push_quad(
    v: &mut Vec<f32>,
    (x0, y0, x1, y1): (u32, u32, u32, u32),
    attr: &dyn Fn(u32, u32) -> [f32; 4],
) {
    for (x, y) in [(x0, y0), (x1, y0), (x1, y1), (x0, y0), (x1, y1), (x0, y1)] {
        v.extend_from_slice(&[x as f32, y as f32]);
        v.extend_from_slice(&attr(x, y));
    }
}

/// Merge stage opening: rows [y0, y0 + r) of a block meet rows mirrored in the block, columns
/// mirrored in the row; the lower half keeps the smaller entries.
fn mirror_shape(w: u32, h: u32, tw: u32, block: u32) -> PassShape {
    let mut v = Vec::new();
    let r = block / w;
    for y0 in (0..h).step_by(r as usize) {
        for (lo, hi, cmp) in [(y0, y0 + r / 2, 1.0), (y0 + r / 2, y0 + r, -1.0)] {
            push_quad(&mut v, (0, lo, tw, hi), &|x, y| {
                [1.0, cmp, (tw - x) as f32, (2 * y0 + r - y) as f32]
            });
        }
    }
    PassShape {
        key: (0, block, 0),
        vertices: v,
        offset: (0, 0),
        program: GpProgram::Mirror,
    }
}

/// Merge passes between rows: transposed quads over groups of rows.
fn between_rows_shape(w: u32, h: u32, tw: u32, dist: u32) -> PassShape {
    let mut v = Vec::new();
    let r = dist / w;
    for y0 in (0..h).step_by(r as usize) {
        let sign = if y0 & r == 0 { 1.0 } else { -1.0 };
        push_quad(&mut v, (0, y0, tw, y0 + r), &|_, _| [sign, sign, 0.0, 0.0]);
    }
    PassShape {
        key: (1, dist, 0),
        vertices: v,
        offset: (0, r as i32),
        program: GpProgram::Plain,
    }
}

/// Both entries in one texel (packed, distance 1); the direction is constant over block / 2
/// texels.
fn same_texel_shape(h: u32, tw: u32, block: u32, asc_all: bool, stage: u32) -> PassShape {
    let mut v = Vec::new();
    let run = (block / 2).max(1);
    if asc_all {
        push_quad(&mut v, (0, 0, tw, h), &|_, _| [1.0, 1.0, 0.0, 0.0]);
    } else {
        for x0 in (0..tw).step_by(run as usize) {
            let cmp = if (2 * x0) & block == 0 { 1.0 } else { -1.0 };
            push_quad(&mut v, (x0, 0, x0 + run, h), &|_, _| [1.0, cmp, 0.0, 0.0]);
        }
    }
    PassShape {
        key: (2, 1, stage),
        vertices: v,
        offset: (0, 0),
        program: GpProgram::SameTexel,
    }
}

/// Row passes: column groups of `dist` entries (dist / 2 texels when packed).
fn row_shape(
    h: u32,
    tw: u32,
    [block, dist, stage]: [u32; 3],
    packed: bool,
    asc_all: bool,
) -> PassShape {
    let mut v = Vec::new();
    let group = if packed { dist / 2 } else { dist };
    for x0 in (0..tw).step_by(group as usize) {
        let first = if packed { 2 * x0 } else { x0 };
        let sign = if first & dist == 0 { 1.0 } else { -1.0 };
        let asc = asc_all || first & block == 0;
        let cmp = if (sign > 0.0) == asc { 1.0 } else { -1.0 };
        push_quad(&mut v, (x0, 0, x0 + group, h), &|_, _| {
            [sign, cmp, 0.0, 0.0]
        });
    }
    PassShape {
        key: (3, dist, stage),
        vertices: v,
        offset: (group as i32, 0),
        program: GpProgram::Plain,
    }
}
