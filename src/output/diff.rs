//! How far two frames are apart: what a lossy variant (the compact sort's quantised depths)
//! changes in the blended image, against the exact variant's frame.

use std::path::Path;

use crate::error::{Error, Result};

/// The difference of two RGBA8 images of one size, over every channel of every pixel.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ImageDiff {
    /// Width and height.
    pub size: [u32; 2],
    /// Mean absolute difference per channel, in units of 1/255.
    pub mean: f64,
    /// Largest absolute difference of a channel, in units of 1/255.
    pub max: u8,
    /// Share of pixels with any channel different.
    pub pixels_changed: f64,
    /// Peak signal-to-noise ratio in dB over the RGB channels (infinite for equal images).
    pub psnr_db: f64,
}

/// Compares two RGBA8 buffers of `size` (4 bytes a pixel).
pub fn diff_rgba8(size: [u32; 2], a: &[u8], b: &[u8]) -> Result<ImageDiff> {
    let n = size[0] as usize * size[1] as usize;
    if a.len() != 4 * n || b.len() != 4 * n {
        return Err(Error::InvalidInput(format!(
            "images of {}x{} need {} bytes each, not {} and {}",
            size[0],
            size[1],
            4 * n,
            a.len(),
            b.len()
        )));
    }
    let (mut sum, mut max, mut changed, mut sq) = (0u64, 0u8, 0usize, 0u64);
    for (pa, pb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let mut any = false;
        for c in 0..4 {
            let d = pa[c].abs_diff(pb[c]);
            sum += d as u64;
            max = max.max(d);
            any |= d != 0;
            if c < 3 {
                sq += (d as u64) * (d as u64);
            }
        }
        changed += any as usize;
    }
    let mse = sq as f64 / (3 * n.max(1)) as f64;
    Ok(ImageDiff {
        size,
        mean: sum as f64 / (4 * n.max(1)) as f64,
        max,
        pixels_changed: changed as f64 / n.max(1) as f64,
        psnr_db: if mse == 0.0 {
            f64::INFINITY
        } else {
            10.0 * (255.0f64 * 255.0 / mse).log10()
        },
    })
}

/// Largest image file `diff` reads: a 8192×8192 RGBA frame stored without compression is
/// 256 MiB.
pub const MAX_IMAGE_BYTES: u64 = 256 << 20;

/// Compares two PNG (or other image) files, which must have the same size. Each must be a
/// regular file (a fifo would block the read, a device never end) of at most
/// [`MAX_IMAGE_BYTES`]; both are looked at before either is read.
pub fn diff_files(a: &Path, b: &Path) -> Result<ImageDiff> {
    for p in [a, b] {
        let m = std::fs::metadata(p).map_err(|e| {
            Error::InvalidInput(format!("{}: {e}: name an image file", p.display()))
        })?;
        if !m.is_file() {
            return Err(Error::InvalidInput(format!(
                "{} is not a regular file (a folder, fifo, device or socket): diff reads image \
                 files only",
                p.display()
            )));
        }
    }
    let open = |p: &Path| {
        let bytes = crate::input::read_input(p, "image", MAX_IMAGE_BYTES)?;
        image::ImageReader::new(std::io::Cursor::new(bytes))
            .with_guessed_format()
            .map_err(|e| Error::InvalidInput(format!("{}: {e}", p.display())))?
            .decode()
            .map(|i| i.to_rgba8())
            .map_err(|e| Error::InvalidInput(format!("{}: {e}", p.display())))
    };
    let (ia, ib) = (open(a)?, open(b)?);
    if ia.dimensions() != ib.dimensions() {
        return Err(Error::InvalidInput(format!(
            "{} is {}x{} and {} is {}x{}: compare frames of one size",
            a.display(),
            ia.width(),
            ia.height(),
            b.display(),
            ib.width(),
            ib.height()
        )));
    }
    diff_rgba8([ia.width(), ia.height()], ia.as_raw(), ib.as_raw())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_differences() {
        let a = vec![10u8; 4 * 4];
        let mut b = a.clone();
        b[0] = 13; // pixel 0, red +3
        b[7] = 12; // pixel 1, alpha +2
        let d = diff_rgba8([2, 2], &a, &b).unwrap();
        assert_eq!(d.max, 3);
        assert!((d.mean - 5.0 / 16.0).abs() < 1e-12);
        assert!((d.pixels_changed - 0.5).abs() < 1e-12);
        // MSE over RGB: 9 / 12.
        let psnr = 10.0 * (255.0f64 * 255.0 / 0.75).log10();
        assert!((d.psnr_db - psnr).abs() < 1e-9);
        assert_eq!(diff_rgba8([2, 2], &a, &a).unwrap().psnr_db, f64::INFINITY);
        assert!(diff_rgba8([3, 2], &a, &b).is_err());
    }
}
