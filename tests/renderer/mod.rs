//! Helpers of the renderer's tests (tests/render.rs, tests/render_quads.rs): a 16×16 state, the
//! styles and cameras they draw with, and the pixels they look at.

#![allow(dead_code)]

use glam::{Vec3, Vec4};
use texflow::gl::{Context, Texture, TextureDesc, TextureFormat};
use texflow::render::{Camera, FrameTarget, ParticleRenderer, ParticleStyle, TypeLook};
use texflow::scene::{Blending, DrawMode, DrawOrder, DrawPrimitive, Keyframe, RenderPath};

pub const SW: u32 = 16;

pub const SH: u32 = 16;

pub const N: usize = (SW * SH) as usize;

pub const FW: u32 = 96;

pub const FH: u32 = 72;

/// A 16×16 state; every particle dead (w = 0, xyz = +inf) until set.
#[derive(Clone)]
pub struct State {
    pub pos: Vec<[f32; 4]>,
    pub stat: Vec<[f32; 4]>,
}

impl State {
    pub fn new() -> Self {
        State {
            pos: vec![[f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0]; N],
            stat: vec![[0.0, 0.0, 1.0, 0.0]; N],
        }
    }

    /// Particle `i` at `p` with `remaining` of `total` seconds of life, of type `ty`, with random
    /// number `rand`.
    pub fn set(&mut self, i: usize, p: Vec3, remaining: f32, total: f32, ty: u32, rand: f32) {
        self.pos[i] = [p.x, p.y, p.z, remaining];
        self.stat[i] = [0.0, ty as f32, total, rand];
    }

    pub fn upload(&self, ctx: &Context) -> (Texture, Texture) {
        let make = |label, data: &[[f32; 4]]| {
            let t = Texture::new(
                ctx,
                TextureDesc {
                    width: SW,
                    height: SH,
                    format: TextureFormat::Rgba32F,
                    label,
                },
            )
            .unwrap();
            t.upload_f32(data.as_flattened()).unwrap();
            t
        };
        (make("position", &self.pos), make("statics", &self.stat))
    }
}

pub fn camera() -> Camera {
    Camera {
        target: Vec3::new(0.1, 0.3, -0.2),
        distance: 3.0,
        azimuth: 25.0,
        elevation: 15.0,
        ..Camera::default()
    }
}

/// The world point behind the centre of pixel (x, y down) at normalised depth `ndc_z`.
pub fn behind_pixel(x: u32, y_down: u32, ndc_z: f32) -> Vec3 {
    let cam = camera();
    let inverse = cam.view_projection(FW as f32 / FH as f32).inverse();
    let ndc = Vec4::new(
        (x as f32 + 0.5) / FW as f32 * 2.0 - 1.0,
        1.0 - (y_down as f32 + 0.5) / FH as f32 * 2.0,
        ndc_z,
        1.0,
    );
    let w = inverse * ndc;
    let p = w.truncate() / w.w;
    assert_eq!(cam.project_to_pixel(p, FW, FH), Some((x, y_down)));
    p
}

/// The default look of each type, with these sprite scales.
pub fn scaled_types(scales: [f32; 4]) -> [TypeLook; 4] {
    std::array::from_fn(|k| TypeLook {
        scale: scales[k],
        ..TypeLook::new(k as u32)
    })
}

pub fn style(
    mode: DrawMode,
    path: RenderPath,
    (blending, order): (Blending, DrawOrder),
) -> ParticleStyle {
    ParticleStyle {
        mode,
        path,
        point_size: if mode == DrawMode::Sprites { 11.0 } else { 3.0 },
        intensity: 0.8,
        blending,
        order,
        types: scaled_types([1.0, 1.5, 0.75, 2.0]),
        primitive: DrawPrimitive::Points,
        stretch: 0.0,
        // Exact in 8 bits, so that background pixels compare equal whatever the rounding.
        background: if blending == Blending::Multiplicative {
            [230.0 / 255.0, 217.0 / 255.0, 204.0 / 255.0]
        } else {
            [13.0 / 255.0, 26.0 / 255.0, 38.0 / 255.0]
        },
        keyframes: test_keyframes(),
        depth_test: false,
        rotate: texflow::scene::Rotate::Age,
        fire: None,
        ..ParticleStyle::default()
    }
}

/// Renders `state` (particles 0..count) with `style` into a fresh FW×FH frame.
pub fn render(
    ctx: &Context,
    style: &ParticleStyle,
    state: &State,
    count: usize,
) -> image::RgbImage {
    let target = FrameTarget::new(ctx, FW, FH).unwrap();
    let renderer = ParticleRenderer::new(ctx, style.clone(), SW, SH).unwrap();
    let (pos, stat) = state.upload(ctx);
    renderer.clear(&target);
    renderer
        .draw(&target, &pos, &stat, &camera(), count)
        .unwrap();
    target.read_rgb().unwrap()
}

pub fn max_diff(a: &image::RgbImage, b: &image::RgbImage) -> u8 {
    a.as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap()
}

/// A deterministic pseudo-random stream for test states.
pub fn lcg(seed: &mut u32) -> f32 {
    *seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
    (*seed >> 8) as f32 / (1u32 << 24) as f32
}

/// A mixed state: mostly live particles of all types and ages spread over the frame, some dead,
/// unborn, permanent or at +inf.
pub fn mixed_state() -> State {
    let mut s = State::new();
    let mut seed = 7;
    for i in 0..N {
        let x = (lcg(&mut seed) * FW as f32) as u32;
        let y = (lcg(&mut seed) * FH as f32) as u32;
        let p = behind_pixel(x, y, lcg(&mut seed) * 1.6 - 0.8);
        let total = 1.0 + 3.0 * lcg(&mut seed);
        let remaining = total * lcg(&mut seed);
        let ty = (lcg(&mut seed) * 4.0) as u32;
        let rand = lcg(&mut seed);
        match i % 11 {
            3 => s.set(i, p, -0.5, total, ty, rand), // unborn
            5 => s.set(i, p, remaining, f32::INFINITY, ty, rand), // permanent
            7 => s.set(i, p, remaining, 0.0, ty, rand), // permanent
            9 => {}                                  // dead
            _ => s.set(i, p, remaining, total, ty, rand),
        }
    }
    s
}

pub fn key(age: f32, rgba: [f32; 4]) -> Keyframe {
    Keyframe { age, rgba }
}

pub fn test_keyframes() -> Vec<Keyframe> {
    vec![
        key(0.0, [1.0, 0.2, 0.0, 0.9]),
        key(0.25, [0.2, 1.0, 0.4, 1.0]),
        key(0.6, [0.0, 0.4, 1.0, 0.6]),
        key(1.0, [0.6, 0.6, 0.6, 0.2]),
    ]
}

pub fn to_u8(v: f32) -> i32 {
    (v.clamp(0.0, 1.0) * 255.0).round() as i32
}

/// Alpha (from the red channel of a white sprite, additive on black) in a square patch.
pub fn patch(img: &image::RgbImage, cx: u32, cy: u32, half: i32) -> Vec<f32> {
    let mut out = Vec::new();
    for dy in -half..=half {
        for dx in -half..=half {
            let p = img.get_pixel((cx as i32 + dx) as u32, (cy as i32 + dy) as u32);
            out.push(p.0[0] as f32 / 255.0);
        }
    }
    out
}

pub fn white_sprites(path: RenderPath, size: f32) -> ParticleStyle {
    ParticleStyle {
        mode: DrawMode::Sprites,
        path,
        point_size: size,
        intensity: 1.0,
        keyframes: vec![
            key(0.0, [1.0; 4]),
            key(0.3, [1.0; 4]),
            key(0.6, [1.0; 4]),
            key(1.0, [1.0; 4]),
        ],
        ..ParticleStyle::default()
    }
}

/// White, opaque over the whole life, additive on black: a pixel's red is the sprite's alpha.
pub fn white(mode: DrawMode, primitive: DrawPrimitive, size: f32) -> ParticleStyle {
    ParticleStyle {
        mode,
        primitive,
        ..white_sprites(RenderPath::TextureFetch, size)
    }
}

/// The lit pixels' (x, y down) coordinates.
pub fn lit(img: &image::RgbImage) -> Vec<(u32, u32)> {
    img.enumerate_pixels()
        .filter(|(_, _, p)| p.0[0] > 0)
        .map(|(x, y, _)| (x, y))
        .collect()
}
