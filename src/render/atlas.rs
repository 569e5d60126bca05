//! The sprite atlas (Latta §3.4.6): one texture holding a tile per particle type, since a draw
//! cannot switch textures per particle. Generated procedurally on the CPU, 2×2 tiles:
//!
//! | tile | type | shape |
//! | --- | --- | --- |
//! | 0 | 0 | soft round blob |
//! | 1 | 1 | six-armed snowflake (star) |
//! | 2 | 2 | soft smoke puff (noisy blob) |
//! | 3 | 3 | ring (spark) with an empty centre and one bead inside it (a marking that turns) |
//!
//! Tile `k` covers texels `[(k % 2)·T, (k % 2 + 1)·T) × [(k / 2)·T, (k / 2 + 1)·T)` in GL texel
//! coordinates (y up; row 0 is the first row of the upload). The shape is in alpha, colour is
//! white (the smoke is shaded a little), so the keyframes colour the sprite. Every shape lies
//! inside the tile's inscribed circle with a margin, so a rotated sprite shows the whole shape
//! and linear filtering never picks up a neighbouring tile.

use crate::error::Result;
use crate::gl::{Context, Texture, TextureDesc, TextureFormat};

/// Tiles per row and column.
pub const ATLAS_TILES: u32 = 2;

/// Default tile size in texels (a power of two, so mipmap levels keep tiles apart).
pub const DEFAULT_TILE: u32 = 64;

/// The atlas on the CPU: RGBA floats in `[0, 1]`, row-major from the bottom row (GL's order).
#[derive(Debug, Clone, PartialEq)]
pub struct AtlasImage {
    /// Tile side in texels.
    pub tile: u32,
    /// `(2·tile)² · 4` floats.
    pub data: Vec<f32>,
}

impl AtlasImage {
    /// Side of the whole atlas in texels.
    pub fn size(&self) -> u32 {
        ATLAS_TILES * self.tile
    }

    /// Texel `(x, y)` of the whole atlas (GL coordinates, y up).
    pub fn texel(&self, x: u32, y: u32) -> [f32; 4] {
        let i = 4 * (y as usize * self.size() as usize + x as usize);
        [
            self.data[i],
            self.data[i + 1],
            self.data[i + 2],
            self.data[i + 3],
        ]
    }

    /// Texel `(x, y)` of tile `k` (tile-local, y up).
    pub fn tile_texel(&self, k: u32, x: u32, y: u32) -> [f32; 4] {
        let (ox, oy) = tile_origin(k);
        self.texel(ox * self.tile + x, oy * self.tile + y)
    }

    /// The alpha of tile `k` sampled at tile coordinates `u, v` in `[0, 1]` (nearest texel).
    pub fn alpha_at(&self, k: u32, u: f32, v: f32) -> f32 {
        let t = self.tile as f32;
        let x = ((u * t) as u32).min(self.tile - 1);
        let y = ((v * t) as u32).min(self.tile - 1);
        self.tile_texel(k, x, y)[3]
    }
}

/// The tile (column, row) of particle type `k`.
pub fn tile_origin(k: u32) -> (u32, u32) {
    (k % ATLAS_TILES, (k / ATLAS_TILES) % ATLAS_TILES)
}

fn smoothstep(e0: f32, e1: f32, x: f32) -> f32 {
    let t = ((x - e0) / (e1 - e0)).clamp(0.0, 1.0);
    t * t * (3.0 - 2.0 * t)
}

/// Integer hash to [0, 1) (a small avalanche hash; deterministic on every platform).
fn hash2(x: i32, y: i32, seed: u32) -> f32 {
    let mut h = (x as u32).wrapping_mul(0x8da6_b343)
        ^ (y as u32).wrapping_mul(0xd816_3841)
        ^ seed.wrapping_mul(0xcb1a_b31f);
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Smooth value noise with a period of `period` lattice cells, so that it tiles.
fn value_noise(x: f32, y: f32, period: i32, seed: u32) -> f32 {
    let (xf, yf) = (x.floor(), y.floor());
    let (fx, fy) = (x - xf, y - yf);
    let (sx, sy) = (fx * fx * (3.0 - 2.0 * fx), fy * fy * (3.0 - 2.0 * fy));
    let (ix, iy) = (xf as i32, yf as i32);
    let at = |dx: i32, dy: i32| {
        hash2(
            (ix + dx).rem_euclid(period),
            (iy + dy).rem_euclid(period),
            seed,
        )
    };
    let a = at(0, 0) + (at(1, 0) - at(0, 0)) * sx;
    let b = at(0, 1) + (at(1, 1) - at(0, 1)) * sx;
    a + (b - a) * sy
}

/// Fractal noise in [0, 1): four octaves of value noise.
fn fbm(x: f32, y: f32) -> f32 {
    let (mut sum, mut amp, mut norm, mut freq) = (0.0, 0.5, 0.0, 4);
    for octave in 0..4 {
        sum += amp * value_noise(x * freq as f32, y * freq as f32, freq, 17 + octave);
        norm += amp;
        amp *= 0.5;
        freq *= 2;
    }
    sum / norm
}

/// Distance from `p` to the segment `a`-`b`.
fn segment_distance(p: (f32, f32), a: (f32, f32), b: (f32, f32)) -> f32 {
    let (abx, aby) = (b.0 - a.0, b.1 - a.1);
    let (apx, apy) = (p.0 - a.0, p.1 - a.1);
    let t = ((apx * abx + apy * aby) / (abx * abx + aby * aby)).clamp(0.0, 1.0);
    let (dx, dy) = (apx - t * abx, apy - t * aby);
    (dx * dx + dy * dy).sqrt()
}

/// Outer radius of every shape, in tile units (the inscribed circle has radius 0.5).
pub const SHAPE_RADIUS: f32 = 0.42;

/// Tile `k`'s RGBA at tile-local position `(x, y)` relative to the tile centre, in tile units
/// (`x, y ∈ [-0.5, 0.5]`).
pub fn shape(k: u32, x: f32, y: f32) -> [f32; 4] {
    let r = (x * x + y * y).sqrt();
    let edge = 1.0 - smoothstep(SHAPE_RADIUS - 0.04, SHAPE_RADIUS, r);
    match k % 4 {
        // Soft round blob: a smooth bump, 1 at the centre, 0 at the rim.
        0 => {
            let t = (1.0 - r / SHAPE_RADIUS).clamp(0.0, 1.0);
            [1.0, 1.0, 1.0, t * t * (3.0 - 2.0 * t)]
        }
        // Six-armed snowflake: arms every 60°, each with a pair of side branches, and a hexagonal
        // core.
        1 => {
            let mut d = f32::INFINITY;
            for arm in 0..6 {
                let a = arm as f32 * std::f32::consts::FRAC_PI_3;
                let (s, c) = a.sin_cos();
                let tip = (0.38 * c, 0.38 * s);
                d = d.min(segment_distance((x, y), (0.0, 0.0), tip));
                let root = (0.22 * c, 0.22 * s);
                for side in [-1.0f32, 1.0] {
                    let b = a + side * std::f32::consts::FRAC_PI_3;
                    let (bs, bc) = b.sin_cos();
                    let end = (root.0 + 0.1 * bc, root.1 + 0.1 * bs);
                    d = d.min(segment_distance((x, y), root, end));
                }
            }
            let line = 1.0 - smoothstep(0.015, 0.04, d);
            let core = 1.0 - smoothstep(0.05, 0.08, r);
            [1.0, 1.0, 1.0, line.max(core) * edge]
        }
        // Smoke puff: a soft blob whose density and rim are broken up by fractal noise.
        2 => {
            let n = fbm(x + 0.5, y + 0.5);
            let rim = SHAPE_RADIUS * (0.75 + 0.25 * n);
            let t = (1.0 - r / rim).clamp(0.0, 1.0);
            let density = t.powf(0.8) * (0.45 + 0.55 * n);
            let shade = 0.7 + 0.3 * n;
            [shade, shade, shade, (density * edge).clamp(0.0, 1.0)]
        }
        // Ring: a Gaussian band at radius 0.3, empty at the centre, with one bead inside it
        // towards +y: a marking that shows which way the sprite has turned (`spin`'s rolling).
        _ => {
            let band = (-((r - 0.3) / 0.045).powi(2)).exp();
            let bead_r = (x * x + (y - 0.17).powi(2)).sqrt();
            let bead = 1.0 - smoothstep(0.04, 0.06, bead_r);
            [1.0, 1.0, 1.0, band.max(bead) * edge]
        }
    }
}

/// Generates the atlas with tiles of `tile` texels (a power of two, at least 8).
pub fn generate(tile: u32) -> AtlasImage {
    assert!(
        tile.is_power_of_two() && tile >= 8,
        "tile size {tile}: a power of two of at least 8"
    );
    let size = ATLAS_TILES * tile;
    let mut data = vec![0f32; (size * size * 4) as usize];
    for k in 0..ATLAS_TILES * ATLAS_TILES {
        let (ox, oy) = tile_origin(k);
        for ty in 0..tile {
            for tx in 0..tile {
                let x = (tx as f32 + 0.5) / tile as f32 - 0.5;
                let y = (ty as f32 + 0.5) / tile as f32 - 0.5;
                let px = shape(k, x, y);
                let (gx, gy) = (ox * tile + tx, oy * tile + ty);
                let i = 4 * (gy * size + gx) as usize;
                data[i..i + 4].copy_from_slice(&px);
            }
        }
    }
    AtlasImage { tile, data }
}

/// Uploads the atlas as an RGBA32F texture with linear filtering and mipmaps down to tiles of 16
/// texels (below that, bilinear taps near a tile's border would reach its neighbour).
pub fn upload(ctx: &Context, image: &AtlasImage) -> Result<Texture> {
    let size = image.size();
    let tex = Texture::new(
        ctx,
        TextureDesc {
            width: size,
            height: size,
            format: TextureFormat::Rgba32F,
            label: "sprite atlas",
        },
    )?;
    tex.upload_f32(&image.data)?;
    tex.filter_linear_mipmapped(image.tile.ilog2().saturating_sub(4))?;
    ctx.check_error("building the sprite atlas")?;
    Ok(tex)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polar(k: u32, img: &AtlasImage, r: f32, deg: f32) -> f32 {
        let (s, c) = deg.to_radians().sin_cos();
        img.alpha_at(k, 0.5 + r * c, 0.5 + r * s)
    }

    #[test]
    fn size_range_and_tile_layout() {
        let img = generate(32);
        assert_eq!(img.size(), 64);
        assert_eq!(img.data.len(), 64 * 64 * 4);
        assert!(img
            .data
            .iter()
            .all(|v| v.is_finite() && (0.0..=1.0).contains(v)));
        assert_eq!(tile_origin(0), (0, 0));
        assert_eq!(tile_origin(1), (1, 0));
        assert_eq!(tile_origin(2), (0, 1));
        assert_eq!(tile_origin(3), (1, 1));
        // Tile 1's centre texel is where shape 1 puts it.
        let t = img.tile_texel(1, 16, 16);
        assert_eq!(t, shape(1, 0.5 / 32.0, 0.5 / 32.0));
        assert_eq!(img.texel(32 + 16, 16), t);
    }

    #[test]
    fn every_shape_fits_inside_the_inscribed_circle() {
        let img = generate(64);
        for k in 0..4 {
            for y in 0..64 {
                for x in 0..64 {
                    let (u, v) = ((x as f32 + 0.5) / 64.0 - 0.5, (y as f32 + 0.5) / 64.0 - 0.5);
                    if (u * u + v * v).sqrt() >= SHAPE_RADIUS {
                        assert_eq!(img.tile_texel(k, x, y)[3], 0.0, "tile {k} at ({x}, {y})");
                    }
                }
            }
        }
    }

    #[test]
    fn blob_is_full_at_the_centre_and_falls_off() {
        let img = generate(64);
        let a: Vec<f32> = [0.0, 0.1, 0.2, 0.3, 0.4]
            .iter()
            .map(|r| polar(0, &img, *r, 37.0))
            .collect();
        assert!(a[0] > 0.99, "{a:?}");
        assert!(a.windows(2).all(|w| w[0] > w[1]), "{a:?}");
        // Round: the same at every angle.
        for deg in [0.0, 45.0, 100.0, 210.0] {
            assert!((polar(0, &img, 0.2, deg) - a[2]).abs() < 0.05);
        }
    }

    #[test]
    fn snowflake_has_six_arms() {
        let img = generate(64);
        for arm in 0..6 {
            let deg = arm as f32 * 60.0;
            assert!(polar(1, &img, 0.3, deg) > 0.9, "arm at {deg}°");
            // Half-way between arms, beyond the branches: empty.
            assert!(
                polar(1, &img, 0.36, deg + 30.0) < 0.05,
                "gap at {}°",
                deg + 30.0
            );
        }
        assert!(polar(1, &img, 0.0, 0.0) > 0.99);
    }

    #[test]
    fn smoke_is_a_noisy_blob() {
        let img = generate(64);
        assert!(polar(2, &img, 0.0, 0.0) > 0.3);
        // Noise: alpha at one radius varies with the angle.
        let ring: Vec<f32> = (0..36)
            .map(|i| polar(2, &img, 0.2, i as f32 * 10.0))
            .collect();
        let (lo, hi) = ring
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), v| (l.min(*v), h.max(*v)));
        assert!(hi - lo > 0.1, "smoke at r = 0.2 spans {lo}..{hi}");
        // Colour varies too (shading), and stays grey.
        let t = img.tile_texel(2, 20, 30);
        assert!(t[0] < 1.0 && t[0] == t[1] && t[1] == t[2]);
    }

    #[test]
    fn ring_is_empty_inside() {
        let img = generate(64);
        assert!(polar(3, &img, 0.0, 0.0) < 1e-3);
        assert!(polar(3, &img, 0.1, 0.0) < 0.01);
        for deg in [0.0, 90.0, 135.0, 300.0] {
            assert!(polar(3, &img, 0.3, deg) > 0.9, "ring at {deg}°");
        }
        // The bead marks one side only, so a turn of the sprite shows (half a turn too).
        assert!(polar(3, &img, 0.17, 90.0) > 0.9);
        for deg in [0.0, 180.0, 270.0] {
            assert!(polar(3, &img, 0.17, deg) < 0.01, "bead at {deg}°");
        }
    }

    #[test]
    fn noise_is_deterministic_and_tiles() {
        assert_eq!(generate(16), generate(16));
        for (x, y) in [(0.3, 0.7), (1.2, 3.9)] {
            assert!((value_noise(x, y, 4, 1) - value_noise(x + 4.0, y, 4, 1)).abs() < 1e-6);
        }
    }
}
