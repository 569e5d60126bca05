//! Pictures of state textures: one square of pixels per texel, a colour ramp for scalars (keys,
//! ids, speeds, cell indices) and RGB within a box for positions.

use image::{Rgb, RgbImage};

/// Control points of the ramp, dark blue through green to yellow (viridis-like): its luminance
/// rises monotonically, so it reads in grey too, and [`ramp_position`] can invert it.
const RAMP: [[f32; 3]; 5] = [
    [68.0, 1.0, 84.0],
    [59.0, 82.0, 139.0],
    [33.0, 145.0, 140.0],
    [94.0, 201.0, 98.0],
    [253.0, 231.0, 37.0],
];

/// The colour of texels whose value is not a finite number (dead particles' +inf keys, NaN).
pub const NOT_FINITE: [u8; 3] = [255, 0, 255];

/// The colour of dead particles in position pictures.
pub const DEAD: [u8; 3] = [0, 0, 0];

/// The ramp's colour at `t` in [0, 1] (clamped).
pub fn ramp(t: f32) -> [u8; 3] {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (RAMP.len() - 1) as f32;
    let i = (x.floor() as usize).min(RAMP.len() - 2);
    let f = x - i as f32;
    let mut c = [0u8; 3];
    for k in 0..3 {
        c[k] = (RAMP[i][k] + (RAMP[i + 1][k] - RAMP[i][k]) * f).round() as u8;
    }
    c
}

/// Where on the ramp a colour lies, in [0, 1] (the nearest of 1024 samples), or `None` for a
/// colour off the ramp. Tests read pictures back with it.
pub fn ramp_position(rgb: [u8; 3]) -> Option<f32> {
    let dist = |c: [u8; 3]| {
        (0..3)
            .map(|k| (c[k] as i32 - rgb[k] as i32).pow(2))
            .sum::<i32>()
    };
    let (best, d) = (0..=1023)
        .map(|i| {
            let t = i as f32 / 1023.0;
            (t, dist(ramp(t)))
        })
        .min_by_key(|&(_, d)| d)?;
    (d <= 12).then_some(best)
}

/// The range of the finite values in `values` (`None` when there are none).
pub fn finite_range(values: impl IntoIterator<Item = f32>) -> Option<(f32, f32)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |r, v| match r {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// How many pixels a texel becomes: a picture about 256 pixels wide, at least 2 pixels a texel.
pub fn scale_for(width: u32, height: u32) -> u32 {
    (256 / width.max(height).max(1)).clamp(2, 32)
}

/// A `width`×`height` grid of texels, each drawn as a square of `scale` pixels, row 0 at the
/// top (texel (0, 0) top left, as a reader counts entries).
pub fn grid(width: u32, height: u32, scale: u32, colour: impl Fn(usize) -> [u8; 3]) -> RgbImage {
    RgbImage::from_fn(width * scale, height * scale, |x, y| {
        let i = (y / scale) as usize * width as usize + (x / scale) as usize;
        Rgb(colour(i))
    })
}

/// A scalar per texel on the ramp over `range` (low dark blue, high yellow); non-finite values in
/// magenta.
pub fn scalar(values: &[f32], width: u32, height: u32, range: (f32, f32)) -> RgbImage {
    let (lo, hi) = range;
    let span = if hi > lo { hi - lo } else { 1.0 };
    grid(width, height, scale_for(width, height), |i| {
        let v = values.get(i).copied().unwrap_or(f32::NAN);
        if v.is_finite() {
            ramp((v - lo) / span)
        } else {
            NOT_FINITE
        }
    })
}

/// Positions (RGBA texels: xyz, life) as colours: x, y and z within `bounds` become red, green
/// and blue; dead particles (life ≤ 0) are black.
pub fn positions(texels: &[f32], width: u32, height: u32, bounds: [[f32; 3]; 2]) -> RgbImage {
    let [lo, hi] = bounds;
    grid(width, height, scale_for(width, height), |i| {
        let Some(p) = texels.get(4 * i..4 * i + 4) else {
            return DEAD;
        };
        // A NaN life counts as dead too.
        if p[3].is_nan() || p[3] <= 0.0 {
            return DEAD;
        }
        let mut c = [0u8; 3];
        for k in 0..3 {
            let span = (hi[k] - lo[k]).max(1e-6);
            c[k] = (((p[k] - lo[k]) / span).clamp(0.0, 1.0) * 255.0).round() as u8;
        }
        c
    })
}

/// The rows `(first, last)` of a `width`×`height` state of positions (RGBA texels: xyz, life)
/// between which all its live particles (life > 0) lie, when they span at most half its rows (a
/// sparse state: its pictures are cropped to them, else it is mostly black); `None` otherwise.
pub fn sparse_rows(texels: &[f32], width: u32, height: u32) -> Option<(u32, u32)> {
    let w = 4 * width as usize;
    let live = |r: &usize| {
        texels
            .get(r * w..(r + 1) * w)
            .is_some_and(|row| row.chunks_exact(4).any(|p| p[3] > 0.0))
    };
    let first = (0..height as usize).find(live)?;
    let last = (0..height as usize).rev().find(live)?;
    (2 * (last - first + 1) <= height as usize).then_some((first as u32, last as u32))
}

/// The bounding box of the live positions (life > 0), or a unit box when none is alive.
pub fn live_bounds(texels: &[f32]) -> [[f32; 3]; 2] {
    let mut b = [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]];
    for p in texels.chunks_exact(4).filter(|p| p[3] > 0.0) {
        for k in 0..3 {
            if p[k].is_finite() {
                b[0][k] = b[0][k].min(p[k]);
                b[1][k] = b[1][k].max(p[k]);
            }
        }
    }
    if b[0][0] > b[1][0] {
        return [[0.0; 3], [1.0; 3]];
    }
    b
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ramp_inverts_and_rises_in_luminance() {
        let mut last = -1.0;
        for i in 0..=100 {
            let t = i as f32 / 100.0;
            let back = ramp_position(ramp(t)).unwrap();
            assert!((back - t).abs() < 0.02, "{t} came back as {back}");
            let c = ramp(t);
            let y = 0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32;
            assert!(y >= last - 0.5, "luminance falls at {t}");
            last = y;
        }
        assert_eq!(ramp_position(NOT_FINITE), None);
    }

    #[test]
    fn grids_put_texel_zero_top_left() {
        let img = scalar(&[0.0, 1.0, 2.0, 3.0], 2, 2, (0.0, 3.0));
        let s = scale_for(2, 2);
        assert_eq!(img.dimensions(), (2 * s, 2 * s));
        assert_eq!(img.get_pixel(0, 0).0, ramp(0.0));
        assert_eq!(img.get_pixel(2 * s - 1, 2 * s - 1).0, ramp(1.0));
        assert_eq!(img.get_pixel(2 * s - 1, 0).0, ramp(1.0 / 3.0));
    }
}
