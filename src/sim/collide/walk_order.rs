//! The order in which the exact detection's count pass takes the particles
//! (`glsl/collide/sorted_keys.glsl`, `WALK_TILES`): its fragment at a pixel works for the
//! particle of sorted index [`walk_index`] there, so that the fragments a GPU runs together
//! (warps of neighbouring pixels) take neighbours in the sort, which walk the same runs of
//! cells. Its outputs lie in that order; [`walk_texel`] finds sorted index `i`'s, and
//! [`to_sorted_order`] puts a read-back in sorted order.

use crate::gl::Defines;

/// The tiles' side in pixels: 256 consecutive sorted indices each.
const TILE: u32 = 16;

/// Whether a `size` state is walked in tiles: both sides powers of two (as every collision
/// sort's state is; `KEY_WIDTH_SHIFT` is then defined too) of at least a tile, so whole tiles
/// cover it. Other states keep the sorted order, in which the order is the identity.
pub fn tiled(size: [u32; 2]) -> bool {
    size.iter().all(|&s| s.is_power_of_two() && s >= TILE)
}

/// `defines` with `WALK_TILES` where a `size` state is walked in tiles.
pub fn walk_defines(defines: &Defines, size: [u32; 2]) -> Defines {
    let mut d = defines.clone();
    if tiled(size) {
        d.push(("WALK_TILES".into(), "1".into()));
    }
    d
}

/// Morton order of the 4 low bits of x and y (x's bits at the even places).
fn interleave(x: u32, y: u32) -> u32 {
    let spread = |v: u32| {
        let v = (v | (v << 2)) & 0x33;
        (v | (v << 1)) & 0x55
    };
    spread(x) | (spread(y) << 1)
}

/// The sorted index the fragment at pixel `(x, y)` of a `size` state works for.
pub fn walk_index(size: [u32; 2], [x, y]: [u32; 2]) -> usize {
    let w = size[0];
    if tiled(size) {
        let tile = (y / TILE) * (w / TILE) + x / TILE;
        return ((tile * TILE * TILE) | interleave(x % TILE, y % TILE)) as usize;
    }
    (y * w + x) as usize
}

/// The pixel (as a row-major texel index) where the count pass wrote sorted index `i`'s result.
pub fn walk_texel(size: [u32; 2], i: usize) -> usize {
    let w = size[0];
    if !tiled(size) {
        return i;
    }
    let (tile, m) = (i as u32 / (TILE * TILE), i as u32 % (TILE * TILE));
    let compact = |v: u32| {
        let v = v & 0x55;
        let v = (v | (v >> 1)) & 0x33;
        (v | (v >> 2)) & 0x0f
    };
    let (x, y) = (compact(m), compact(m >> 1));
    let tiles = w / TILE;
    (((tile / tiles) * TILE + y) * w + (tile % tiles) * TILE + x) as usize
}

/// `texels` (RGBA, `channels` floats a texel) of a count output read back, in sorted order.
pub fn to_sorted_order(size: [u32; 2], texels: &[f32], channels: usize) -> Vec<f32> {
    let n = (size[0] * size[1]) as usize;
    (0..n)
        .flat_map(|i| {
            let t = walk_texel(size, i) * channels;
            texels[t..t + channels].iter().copied()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The order is a bijection of the pixels, walk_texel its inverse, and every 16 × 16 tile
    /// (and each aligned 4 × 4 and 8 × 4 block in it) holds consecutive indices.
    #[test]
    fn the_walk_order_is_a_bijection_with_consecutive_blocks() {
        for size in [[16, 16], [32, 64], [128, 16], [8, 8], [64, 8], [16, 12]] {
            let n = (size[0] * size[1]) as usize;
            let mut seen = vec![false; n];
            for y in 0..size[1] {
                for x in 0..size[0] {
                    let i = walk_index(size, [x, y]);
                    assert!(!seen[i], "{size:?}: {i} twice");
                    seen[i] = true;
                    assert_eq!(walk_texel(size, i), (y * size[0] + x) as usize, "{size:?}");
                }
            }
            if !tiled(size) {
                continue;
            }
            for (bw, bh) in [(4, 4), (8, 4), (16, 16)] {
                let idx: Vec<usize> = (0..bh)
                    .flat_map(|y| (0..bw).map(move |x| walk_index(size, [x, y])))
                    .collect();
                let lo = *idx.iter().min().unwrap();
                assert_eq!(
                    idx.iter().max().unwrap() - lo + 1,
                    bw as usize * bh as usize
                );
                assert_eq!(lo % (bw * bh) as usize, 0, "{size:?} block {bw}×{bh}");
            }
        }
    }
}
