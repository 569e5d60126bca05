//! Frames and textures: pixels probed against what a test expects, pixels counted, the cameras
//! and state textures the render tests draw with.

use glam::Vec3;
use image::{ImageBuffer, Pixel};
use texflow::gl::{Context, Texture, TextureDesc, TextureFormat};
use texflow::render::Camera;

/// Fails the test unless every channel of pixel (x, y) is within `tol` of `expected`; the
/// message says where, what was expected and what was observed (as piglit's `probe_pixel`).
pub fn probe<P: Pixel<Subpixel = u8>>(
    img: &ImageBuffer<P, Vec<u8>>,
    x: u32,
    y: u32,
    expected: &[u8],
    tol: u8,
    what: &str,
) {
    let observed = img.get_pixel(x, y).channels();
    assert_eq!(observed.len(), expected.len(), "{what}: channels");
    let off = observed
        .iter()
        .zip(expected)
        .any(|(o, e)| o.abs_diff(*e) > tol);
    assert!(
        !off,
        "{what}: Probe at ({x}, {y})\n  Expected: {expected:?}\n  Observed: {observed:?}\n  \
         Tolerance: {tol}"
    );
}

/// Pixels that are not `background`.
pub fn lit_pixels(img: &image::RgbImage, background: [u8; 3]) -> usize {
    img.pixels().filter(|p| p.0 != background).count()
}

/// A camera looking straight down -z at the origin from `distance` on +z.
pub fn front_camera(distance: f32) -> Camera {
    Camera {
        target: Vec3::ZERO,
        distance,
        azimuth: 0.0,
        elevation: 0.0,
        ..Camera::default()
    }
}

/// A `w`×`h` texture of `format` holding `data` (4 floats per texel).
pub fn texture(
    ctx: &Context,
    label: &str,
    (w, h): (u32, u32),
    format: TextureFormat,
    data: &[f32],
) -> Texture {
    let t = Texture::new(
        ctx,
        TextureDesc {
            width: w,
            height: h,
            format,
            label,
        },
    )
    .unwrap();
    t.upload_f32(data).unwrap();
    t
}
