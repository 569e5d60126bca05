//! The general particle renderer (`render::ParticleRenderer`): both data paths give the same
//! image, dead / unborn / non-finite particles stay invisible, keyframe colours by age, the over
//! and under operators, the sprite atlas tiles and their rotation.

mod common;

use common::image::{front_camera, lit_pixels, probe};
use common::{context, no_gl_error};
use glam::{Vec2, Vec3, Vec4};
use texflow::gl::{Context, Texture, TextureDesc, TextureFormat};
use texflow::render::{
    atlas, second_random, sprite_angle, Camera, FrameState, FrameTarget, KeyframeRamp, Motion,
    ParticleRenderer, ParticleStyle, SizeCurve, TypeLook,
};
use texflow::scene::{Blending, DrawMode, DrawOrder, DrawPrimitive, Keyframe, RenderPath};

const SW: u32 = 16;
const SH: u32 = 16;
const N: usize = (SW * SH) as usize;
const FW: u32 = 96;
const FH: u32 = 72;

const BLENDS: [(Blending, DrawOrder); 4] = [
    (Blending::Additive, DrawOrder::BackToFront),
    (Blending::Multiplicative, DrawOrder::BackToFront),
    (Blending::Alpha, DrawOrder::BackToFront),
    (Blending::Alpha, DrawOrder::FrontToBack),
];

/// A 16×16 state; every particle dead (w = 0, xyz = +inf) until set.
#[derive(Clone)]
struct State {
    pos: Vec<[f32; 4]>,
    stat: Vec<[f32; 4]>,
}

impl State {
    fn new() -> Self {
        State {
            pos: vec![[f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0]; N],
            stat: vec![[0.0, 0.0, 1.0, 0.0]; N],
        }
    }

    /// Particle `i` at `p` with `remaining` of `total` seconds of life, of type `ty`, with random
    /// number `rand`.
    fn set(&mut self, i: usize, p: Vec3, remaining: f32, total: f32, ty: u32, rand: f32) {
        self.pos[i] = [p.x, p.y, p.z, remaining];
        self.stat[i] = [0.0, ty as f32, total, rand];
    }

    fn upload(&self, ctx: &Context) -> (Texture, Texture) {
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

fn camera() -> Camera {
    Camera {
        target: Vec3::new(0.1, 0.3, -0.2),
        distance: 3.0,
        azimuth: 25.0,
        elevation: 15.0,
        ..Camera::default()
    }
}

/// The world point behind the centre of pixel (x, y down) at normalised depth `ndc_z`.
fn behind_pixel(x: u32, y_down: u32, ndc_z: f32) -> Vec3 {
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
fn scaled_types(scales: [f32; 4]) -> [TypeLook; 4] {
    std::array::from_fn(|k| TypeLook {
        scale: scales[k],
        ..TypeLook::new(k as u32)
    })
}

fn style(
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
    }
}

/// Renders `state` (particles 0..count) with `style` into a fresh FW×FH frame.
fn render(ctx: &Context, style: &ParticleStyle, state: &State, count: usize) -> image::RgbImage {
    let target = FrameTarget::new(ctx, FW, FH).unwrap();
    let renderer = ParticleRenderer::new(ctx, style.clone(), SW, SH).unwrap();
    let (pos, stat) = state.upload(ctx);
    renderer.clear(&target);
    renderer
        .draw(&target, &pos, &stat, &camera(), count)
        .unwrap();
    target.read_rgb().unwrap()
}

fn background_pixel(style: &ParticleStyle) -> [u8; 3] {
    style.background.map(|c| (c * 255.0).round() as u8)
}

fn max_diff(a: &image::RgbImage, b: &image::RgbImage) -> u8 {
    a.as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y))
        .max()
        .unwrap()
}

/// A deterministic pseudo-random stream for test states.
fn lcg(seed: &mut u32) -> f32 {
    *seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
    (*seed >> 8) as f32 / (1u32 << 24) as f32
}

/// A mixed state: mostly live particles of all types and ages spread over the frame, some dead,
/// unborn, permanent or at +inf.
fn mixed_state() -> State {
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

/// Vertex texture fetch and the pixel-pack vertex buffer draw the same bytes, for points and
/// sprites and every blending mode, whole states and partial counts.
#[test]
fn both_paths_draw_identical_images() {
    let ctx = context();
    let state = mixed_state();
    for mode in [DrawMode::Points, DrawMode::Sprites] {
        for blend in BLENDS {
            for count in [N, 150] {
                let fetch = style(mode, RenderPath::TextureFetch, blend);
                let buffer = style(mode, RenderPath::VertexBuffer, blend);
                let a = render(&ctx, &fetch, &state, count);
                let b = render(&ctx, &buffer, &state, count);
                let lit = lit_pixels(&a, background_pixel(&fetch));
                assert!(
                    lit > 200,
                    "{mode:?} {blend:?} {count}: only {lit} pixels drawn"
                );
                assert!(
                    a == b,
                    "{mode:?} {blend:?} count {count}: paths differ by up to {}",
                    max_diff(&a, &b)
                );
            }
        }
    }
    no_gl_error(&ctx);
}

/// `draw(.., count)` draws particles 0..count only.
#[test]
fn only_the_first_count_particles_are_drawn() {
    let ctx = context();
    let mut state = State::new();
    state.set(0, behind_pixel(20, 30, 0.2), 1.0, 2.0, 0, 0.0);
    state.set(17, behind_pixel(60, 40, 0.2), 1.0, 2.0, 0, 0.0);
    for path in [RenderPath::TextureFetch, RenderPath::VertexBuffer] {
        let mut s = style(DrawMode::Points, path, BLENDS[0]);
        s.point_size = 1.0;
        let bg = background_pixel(&s);
        let lit = |img: &image::RgbImage| -> Vec<(u32, u32)> {
            img.enumerate_pixels()
                .filter(|(_, _, p)| p.0 != bg)
                .map(|(x, y, _)| (x, y))
                .collect()
        };
        assert_eq!(
            lit(&render(&ctx, &s, &state, 17)),
            vec![(20, 30)],
            "{path:?}"
        );
        assert_eq!(
            lit(&render(&ctx, &s, &state, 18)),
            vec![(20, 30), (60, 40)],
            "{path:?}"
        );
        assert_eq!(lit(&render(&ctx, &s, &state, 0)), vec![], "{path:?}");
    }
    no_gl_error(&ctx);
}

/// Dead (w <= 0), unborn (w < 0), NaN-life and non-finite particles draw nothing, on either path
/// and in either mode, while a live control particle does.
#[test]
fn dead_unborn_and_non_finite_particles_are_not_drawn() {
    let ctx = context();
    let mut state = State::new();
    let p = behind_pixel(40, 30, 0.0);
    state.set(0, p, 0.0, 2.0, 0, 0.3); // dead at a finite position
    state.set(1, p, -0.25, 2.0, 1, 0.3); // unborn
    state.set(2, p, -1e-6, 2.0, 3, 0.3); // just unborn
    state.set(3, p, f32::NAN, 2.0, 0, 0.3);
    state.set(4, Vec3::new(f32::INFINITY, p.y, p.z), 1.0, 2.0, 0, 0.3);
    state.set(5, Vec3::new(p.x, f32::NEG_INFINITY, p.z), 1.0, 2.0, 0, 0.3);
    state.set(6, Vec3::new(p.x, p.y, f32::NAN), 1.0, 2.0, 0, 0.3);
    state.set(7, Vec3::splat(f32::NAN), 1.0, 2.0, 2, 0.3);
    state.set(8, Vec3::splat(f32::INFINITY), 1.0, 2.0, 0, 0.3); // alive at +inf
                                                                // Particles 9.. are dead at +inf with w = 0 (State::new); make some w negative too.
    for i in 9..40 {
        state.pos[i][3] = -(i as f32);
    }
    let mut control = state.clone();
    control.set(40, p, 1.0, 2.0, 0, 0.3);
    for mode in [DrawMode::Points, DrawMode::Sprites] {
        for path in [RenderPath::TextureFetch, RenderPath::VertexBuffer] {
            for blend in BLENDS {
                let s = style(mode, path, blend);
                let bg = background_pixel(&s);
                let img = render(&ctx, &s, &state, N);
                assert_eq!(lit_pixels(&img, bg), 0, "{mode:?} {path:?} {blend:?}");
                let img = render(&ctx, &s, &control, N);
                assert!(
                    lit_pixels(&img, bg) > 0,
                    "{mode:?} {path:?} {blend:?} control"
                );
            }
        }
    }
    no_gl_error(&ctx);
}

fn key(age: f32, rgba: [f32; 4]) -> Keyframe {
    Keyframe { age, rgba }
}

fn test_keyframes() -> Vec<Keyframe> {
    vec![
        key(0.0, [1.0, 0.2, 0.0, 0.9]),
        key(0.25, [0.2, 1.0, 0.4, 1.0]),
        key(0.6, [0.0, 0.4, 1.0, 0.6]),
        key(1.0, [0.6, 0.6, 0.6, 0.2]),
    ]
}

fn to_u8(v: f32) -> i32 {
    (v.clamp(0.0, 1.0) * 255.0).round() as i32
}

/// A particle projected to a known pixel has its keyframe colour for its age: additive on black
/// gives colour · alpha, multiplicative on white gives mix(1, colour, alpha); ages on each of the
/// three segments, at the keyframes, and permanent particles (age 0).
#[test]
fn particle_colour_follows_the_keyframes_by_age() {
    colour_follows(test_keyframes());
}

/// Six keyframes, the first after age 0 and the last before 1: the colour is held outside them
/// (ages 0, 0.05 and 0.95 of `colour_follows`).
#[test]
fn any_number_of_keyframes_colours_by_age() {
    colour_follows(vec![
        key(0.08, [1.0, 0.9, 0.2, 0.8]),
        key(0.2, [0.9, 0.3, 0.1, 1.0]),
        key(0.28, [0.1, 0.8, 0.3, 0.5]),
        key(0.55, [0.3, 0.2, 0.9, 0.9]),
        key(0.7, [0.7, 0.7, 0.1, 0.4]),
        key(0.9, [0.2, 0.5, 0.5, 0.7]),
    ]);
    // The ramp the pixels were compared with against linear interpolation written out.
    let r = KeyframeRamp::new(&[key(0.2, [0.0; 4]), key(0.6, [1.0, 0.5, 0.0, 1.0])]);
    assert_eq!(r.eval(0.0), [0.0; 4]);
    assert!((r.eval(0.5)[0] - 0.75).abs() < 1e-6 && (r.eval(0.5)[1] - 0.375).abs() < 1e-6);
    assert_eq!(r.eval(0.9), [1.0, 0.5, 0.0, 1.0]);
}

fn colour_follows(keys: Vec<Keyframe>) {
    let ctx = context();
    let ramp = KeyframeRamp::new(&keys);
    let intensity = 0.9;
    // (remaining, total) pairs and the relative age they mean.
    let lives: [(f32, f32, f32); 11] = [
        (4.0, 4.0, 0.0),
        (3.8, 4.0, 0.05),
        (3.6, 4.0, 0.1),
        (3.0, 4.0, 0.25),
        (2.8, 4.0, 0.3),
        (2.0, 4.0, 0.5),
        (1.6, 4.0, 0.6),
        (1.0, 4.0, 0.75),
        (0.2, 4.0, 0.95),
        (1.0, 0.0, 0.0),
        (1.0, f32::INFINITY, 0.0),
    ];
    let mut state = State::new();
    let mut pixels = Vec::new();
    for (i, (rem, total, _)) in lives.iter().enumerate() {
        let px = (8 + 8 * i as u32, 10 + 5 * i as u32);
        state.set(
            3 * i + 1,
            behind_pixel(px.0, px.1, 0.3),
            *rem,
            *total,
            0,
            0.5,
        );
        pixels.push(px);
    }
    for path in [RenderPath::TextureFetch, RenderPath::VertexBuffer] {
        for (blending, background) in [
            (Blending::Additive, [0.0; 3]),
            (Blending::Multiplicative, [1.0; 3]),
        ] {
            let s = ParticleStyle {
                path,
                point_size: 1.0,
                intensity,
                blending,
                keyframes: keys.clone(),
                background,
                ..ParticleStyle::default()
            };
            let img = render(&ctx, &s, &state, N);
            for (&(x, y), &(_, _, age)) in pixels.iter().zip(&lives) {
                let c = ramp.eval(age);
                let a = (c[3] * intensity).clamp(0.0, 1.0);
                let want = [0, 1, 2].map(|ch| match blending {
                    Blending::Additive => to_u8(c[ch] * a),
                    _ => to_u8(1.0 - a + c[ch] * a),
                } as u8);
                probe(
                    &img,
                    x,
                    y,
                    &want,
                    1,
                    &format!("{path:?} {blending:?} age {age}"),
                );
            }
            // Nothing else is drawn.
            let bg = background_pixel(&s);
            assert_eq!(lit_pixels(&img, bg), lives.len(), "{path:?} {blending:?}");
        }
    }
    no_gl_error(&ctx);
}

/// Two overlapping particles: the over operator drawing back to front and the under operator
/// drawing front to back give the same image; the wrong order gives a visibly different one.
#[test]
fn over_back_to_front_equals_under_front_to_back() {
    let ctx = context();
    // Piecewise constant keyframes: red (alpha 0.6) for ages below 0.5, blue (alpha 0.7) after.
    let keys = vec![
        key(0.0, [1.0, 0.1, 0.0, 0.6]),
        key(0.5, [1.0, 0.1, 0.0, 0.6]),
        key(0.5, [0.0, 0.3, 1.0, 0.7]),
        key(1.0, [0.0, 0.3, 1.0, 0.7]),
    ];
    let (cx, cy) = (48, 36);
    let near = behind_pixel(cx, cy, -0.2);
    let far = behind_pixel(cx, cy, 0.6);
    let cam = camera();
    assert!(near.distance(cam.eye()) < far.distance(cam.eye()));
    // Near: red (age 0.25); far: blue (age 0.75).
    let mut back_to_front = State::new();
    back_to_front.set(0, far, 1.0, 4.0, 0, 0.1);
    back_to_front.set(1, near, 3.0, 4.0, 0, 0.7);
    let mut front_to_back = State::new();
    front_to_back.set(0, near, 3.0, 4.0, 0, 0.7);
    front_to_back.set(1, far, 1.0, 4.0, 0, 0.1);
    for mode in [DrawMode::Points, DrawMode::Sprites] {
        for path in [RenderPath::TextureFetch, RenderPath::VertexBuffer] {
            for background in [[0.0; 3], [51.0 / 255.0, 77.0 / 255.0, 26.0 / 255.0]] {
                let s = |order| ParticleStyle {
                    mode,
                    path,
                    point_size: if mode == DrawMode::Sprites { 21.0 } else { 7.0 },
                    blending: Blending::Alpha,
                    order,
                    keyframes: keys.clone(),
                    background,
                    ..ParticleStyle::default()
                };
                let over = s(DrawOrder::BackToFront);
                let under = s(DrawOrder::FrontToBack);
                let good_over = render(&ctx, &over, &back_to_front, 2);
                let good_under = render(&ctx, &under, &front_to_back, 2);
                let what = format!("{mode:?} {path:?} background {background:?}");
                assert!(
                    lit_pixels(&good_over, background_pixel(&over)) >= 49,
                    "{what}: drawn"
                );
                assert!(
                    max_diff(&good_over, &good_under) <= 2,
                    "{what}: over and under differ by {}",
                    max_diff(&good_over, &good_under)
                );
                // The centre shows red over blue: mostly red.
                let c = good_over.get_pixel(cx, cy).0;
                assert!(c[0] > c[2], "{what}: centre {c:?}");
                for (style, state) in [(&over, &front_to_back), (&under, &back_to_front)] {
                    let wrong = render(&ctx, style, state, 2);
                    let c = wrong.get_pixel(cx, cy).0;
                    assert!(
                        max_diff(&good_over, &wrong) > 40 && c[2] > c[0],
                        "{what} {:?}: the wrong order should show blue over red, centre {c:?}",
                        style.order
                    );
                }
            }
        }
    }
    no_gl_error(&ctx);
}

/// The CPU picture of one sprite: alpha of tile `ty` at pixel offset (dx, dy down) from the
/// centre of an odd-sized sprite of `size` pixels rotated by `rand` turns, as the fragment shader
/// computes it (before filtering).
fn expected_alpha(ty: u32, size: f32, rand: f32, dx: i32, dy: i32) -> f32 {
    let d = Vec2::new(dx as f32 / size, dy as f32 / size);
    let (s, c) = (std::f32::consts::TAU * rand).sin_cos();
    let r = Vec2::new(c * d.x - s * d.y, s * d.x + c * d.y);
    if r.length_squared() > 0.25 {
        return 0.0;
    }
    atlas::shape(ty, r.x, r.y)[3]
}

/// Alpha (from the red channel of a white sprite, additive on black) in a square patch.
fn patch(img: &image::RgbImage, cx: u32, cy: u32, half: i32) -> Vec<f32> {
    let mut out = Vec::new();
    for dy in -half..=half {
        for dx in -half..=half {
            let p = img.get_pixel((cx as i32 + dx) as u32, (cy as i32 + dy) as u32);
            out.push(p.0[0] as f32 / 255.0);
        }
    }
    out
}

fn reference(ty: u32, size: f32, rand: f32, half: i32) -> Vec<f32> {
    let mut out = Vec::new();
    for dy in -half..=half {
        for dx in -half..=half {
            out.push(expected_alpha(ty, size, rand, dx, dy));
        }
    }
    out
}

fn mean_abs(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum::<f32>() / a.len() as f32
}

fn white_sprites(path: RenderPath, size: f32) -> ParticleStyle {
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

/// The sprite of type k shows tile k's shape: the blob is full in the middle and fades, the
/// snowflake has six arms, the smoke is a noisy puff, the ring's centre is empty; each matches
/// the CPU picture of its own tile better than any other tile's.
#[test]
fn sprite_of_each_type_shows_its_tile() {
    let ctx = context();
    let size = 31.0;
    let half = 15;
    let centres = [(20u32, 18u32), (70, 18), (20, 54), (70, 54)];
    let mut state = State::new();
    for (k, &(x, y)) in centres.iter().enumerate() {
        state.set(k * 5, behind_pixel(x, y, 0.1), 1.0, 2.0, k as u32, 0.0);
    }
    for path in [RenderPath::TextureFetch, RenderPath::VertexBuffer] {
        let img = render(&ctx, &white_sprites(path, size), &state, N);
        let patches: Vec<Vec<f32>> = centres
            .iter()
            .map(|&(x, y)| patch(&img, x, y, half))
            .collect();
        let at = |k: usize, dx: i32, dy: i32| patches[k][((dy + half) * 31 + dx + half) as usize];
        // Blob.
        assert!(at(0, 0, 0) > 0.95, "blob centre {}", at(0, 0, 0));
        assert!(at(0, 0, 0) > at(0, 5, 0) && at(0, 5, 0) > at(0, 10, 0));
        assert!(at(0, 14, 0) < 0.02 && at(0, 0, -14) < 0.02);
        // Snowflake: an arm along +x (0°) at 0.3 of the size, empty between arms (30°).
        assert!(at(1, 0, 0) > 0.9);
        assert!(at(1, 9, 0) > 0.7, "arm {}", at(1, 9, 0));
        let gap = (0.36 * size * 30f32.to_radians().cos()).round() as i32;
        let gap_y = (0.36 * size * 30f32.to_radians().sin()).round() as i32;
        assert!(at(1, gap, gap_y) < 0.1, "gap {}", at(1, gap, gap_y));
        // Smoke: present in the middle, not a smooth disc.
        assert!(at(2, 0, 0) > 0.2);
        // Ring: empty centre, bright at 0.3 of the size.
        assert!(at(3, 0, 0) < 0.02, "ring centre {}", at(3, 0, 0));
        assert!(at(3, 0, 9) > 0.7 && at(3, -9, 0) > 0.7);
        // Each sprite is closest to its own tile's picture.
        for (k, p) in patches.iter().enumerate() {
            let errors: Vec<f32> = (0..4)
                .map(|t| mean_abs(p, &reference(t, size, 0.0, half)))
                .collect();
            assert!(errors[k] < 0.08, "{path:?} type {k}: errors {errors:?}");
            for (t, e) in errors.iter().enumerate() {
                if t != k {
                    assert!(
                        *e > 2.0 * errors[k],
                        "{path:?} type {k} vs tile {t}: {errors:?}"
                    );
                }
            }
        }
    }
    no_gl_error(&ctx);
}

/// The sprite's size is point_size · type_scale[type].
#[test]
fn sprite_size_follows_the_type_scale() {
    let ctx = context();
    let mut state = State::new();
    state.set(0, behind_pixel(24, 36, 0.0), 1.0, 2.0, 1, 0.0);
    state.set(1, behind_pixel(70, 36, 0.0), 1.0, 2.0, 2, 0.0);
    let mut s = white_sprites(RenderPath::TextureFetch, 15.0);
    let extent = |img: &image::RgbImage, x0: u32, x1: u32| {
        let xs: Vec<u32> = img
            .enumerate_pixels()
            .filter(|(x, _, p)| (x0..x1).contains(x) && p.0[0] > 0)
            .map(|(x, _, _)| x)
            .collect();
        xs.iter().max().unwrap() - xs.iter().min().unwrap() + 1
    };
    // Type 1 (snowflake, arms along x reach 0.38 of the size) at scale 1, then 2.
    s.types = scaled_types([1.0; 4]);
    let small = render(&ctx, &s, &state, 2);
    s.types = scaled_types([1.0, 2.0, 1.0, 1.0]);
    let big = render(&ctx, &s, &state, 2);
    let (a, b) = (extent(&small, 0, 48), extent(&big, 0, 48));
    assert!((9..=15).contains(&a), "scale 1: {a} pixels wide");
    assert!(
        b >= 2 * a - 3 && b <= 2 * a + 3,
        "scale 2: {b} pixels wide, scale 1: {a}"
    );
    // Type 2 is unchanged.
    assert_eq!(extent(&small, 48, 96), extent(&big, 48, 96));
    no_gl_error(&ctx);
}

/// Sprites turn by the angle of their random number: the same number gives the same sprite,
/// different numbers different ones, each matching the CPU picture rotated by its own angle.
#[test]
fn rotation_follows_the_random_number() {
    let ctx = context();
    let size = 31.0;
    let half = 15;
    let rands = [0.0f32, 0.05, 0.05, 0.3];
    let centres = [(20u32, 18u32), (70, 18), (20, 54), (70, 54)];
    let mut state = State::new();
    for (k, (&(x, y), &r)) in centres.iter().zip(&rands).enumerate() {
        // The snowflake: 6-fold, so 0.05 turns (18°) and 0.3 (108° = 48° mod 60°) all differ.
        state.set(k, behind_pixel(x, y, 0.1), 1.0, 2.0, 1, r);
    }
    for path in [RenderPath::TextureFetch, RenderPath::VertexBuffer] {
        let img = render(&ctx, &white_sprites(path, size), &state, 4);
        let p: Vec<Vec<f32>> = centres
            .iter()
            .map(|&(x, y)| patch(&img, x, y, half))
            .collect();
        // The same random number, the same sprite (up to gl_PointCoord's rounding at another
        // place on the screen).
        let same = p[1]
            .iter()
            .zip(&p[2])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f32::max);
        assert!(
            same <= 2.5 / 255.0,
            "{path:?}: the same random number differs by {same}"
        );
        assert!(
            mean_abs(&p[0], &p[1]) > 0.05,
            "{path:?}: 0 and 0.05 turns look alike"
        );
        assert!(
            mean_abs(&p[1], &p[3]) > 0.05,
            "{path:?}: 0.05 and 0.3 turns look alike"
        );
        for (k, patch) in p.iter().enumerate() {
            let own = mean_abs(patch, &reference(1, size, rands[k], half));
            assert!(
                own < 0.08,
                "{path:?} sprite {k}: error {own} against its own angle"
            );
            for (j, &r) in rands.iter().enumerate() {
                if r != rands[k] {
                    let other = mean_abs(patch, &reference(1, size, r, half));
                    assert!(
                        other > 2.0 * own,
                        "{path:?} sprite {k}: error {own}, against the angle of {j}: {other}"
                    );
                }
            }
        }
    }
    no_gl_error(&ctx);
}

/// The pass list names the copies on the vertex-buffer path and the background composite of
/// the under operator; the state size is checked.
#[test]
fn pass_names_and_state_checks() {
    let ctx = context();
    let r = ParticleRenderer::new(
        &ctx,
        style(DrawMode::Sprites, RenderPath::VertexBuffer, BLENDS[2]),
        SW,
        SH,
    )
    .unwrap();
    assert_eq!(
        r.pass_names(),
        vec![
            "copy positions to vertex buffer (pixel pack)",
            "copy statics to vertex buffer (pixel pack)",
            "render sprites (vertex buffer, alpha over, back to front)",
        ]
    );
    let r2 = ParticleRenderer::new(
        &ctx,
        style(DrawMode::Points, RenderPath::TextureFetch, BLENDS[3]),
        SW,
        SH,
    )
    .unwrap();
    assert_eq!(
        r2.pass_names(),
        vec![
            "render points (texture fetch, alpha under, front to back)",
            "composite background under",
        ]
    );
    let target = FrameTarget::new(&ctx, FW, FH).unwrap();
    let (pos, stat) = State::new().upload(&ctx);
    assert!(r.draw(&target, &pos, &stat, &camera(), N + 1).is_err());
    let small = ParticleRenderer::new(
        &ctx,
        style(DrawMode::Points, RenderPath::TextureFetch, BLENDS[0]),
        8,
        8,
    )
    .unwrap();
    assert!(small.draw(&target, &pos, &stat, &camera(), 4).is_err());
    no_gl_error(&ctx);
}

// ---- Latta §3.4.5-3.4.6: quads by vertex replication, stretched quads, rotation speed, size
// over life, keyframes per type.

/// A 16×16 RGBA32F texture of `data` (the state layout).
fn state_texture(ctx: &Context, label: &str, data: &[[f32; 4]]) -> Texture {
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
}

/// Renders with `renderer` at `time`, with the velocities `motion` where given.
fn render_frame(
    ctx: &Context,
    renderer: &ParticleRenderer,
    state: &State,
    motion: Option<&Texture>,
    time: f32,
    cam: &Camera,
) -> image::RgbImage {
    let target = FrameTarget::new(ctx, FW, FH).unwrap();
    let (pos, stat) = state.upload(ctx);
    renderer.clear(&target);
    let frame = FrameState {
        positions: &pos,
        statics: &stat,
        motion: motion.map(Motion::Velocity),
        time,
        spins: None,
        count: N,
    };
    renderer.draw_frame(&target, &frame, cam).unwrap();
    target.read_rgb().unwrap()
}

/// White, opaque over the whole life, additive on black: a pixel's red is the sprite's alpha.
fn white(mode: DrawMode, primitive: DrawPrimitive, size: f32) -> ParticleStyle {
    ParticleStyle {
        mode,
        primitive,
        ..white_sprites(RenderPath::TextureFetch, size)
    }
}

/// The lit pixels' (x, y down) coordinates.
fn lit(img: &image::RgbImage) -> Vec<(u32, u32)> {
    img.enumerate_pixels()
        .filter(|(_, _, p)| p.0[0] > 0)
        .map(|(x, y, _)| (x, y))
        .collect()
}

/// A camera-facing quad of `point_size` pixels covers exactly the pixels the closed-form
/// projection predicts (a `size`×`size` square around the projected pixel) and the same pixels
/// as the point sprite of that size; textured sprite quads draw what point sprites draw.
#[test]
fn quads_cover_the_pixels_of_the_projected_square() {
    let ctx = context();
    let centres = [(20u32, 18u32), (70, 30), (41, 55)];
    let mut state = State::new();
    for (k, &(x, y)) in centres.iter().enumerate() {
        state.set(
            k * 7,
            behind_pixel(x, y, 0.2 * k as f32 - 0.3),
            1.0,
            2.0,
            0,
            0.1,
        );
    }
    for size in [1.0f32, 7.0, 13.0] {
        let h = (size as i32 - 1) / 2;
        let mut expected: Vec<(u32, u32)> = centres
            .iter()
            .flat_map(|&(cx, cy)| {
                (-h..=h).flat_map(move |dy| {
                    (-h..=h).map(move |dx| ((cx as i32 + dx) as u32, (cy as i32 + dy) as u32))
                })
            })
            .collect();
        expected.sort_by_key(|&(x, y)| (y, x));
        for primitive in [DrawPrimitive::Points, DrawPrimitive::Quads] {
            let r = ParticleRenderer::new(&ctx, white(DrawMode::Points, primitive, size), SW, SH)
                .unwrap();
            let img = render_frame(&ctx, &r, &state, None, 0.0, &camera());
            assert_eq!(lit(&img), expected, "{primitive:?} of {size} pixels");
        }
    }
    // Rotated, textured sprites of every type and age: the quads' interpolated coordinate gives
    // the picture gl_PointCoord gives.
    let mut s = white_sprites(RenderPath::TextureFetch, 17.0);
    s.types = scaled_types([1.0, 1.5, 0.75, 2.0]);
    let points = ParticleRenderer::new(&ctx, s.clone(), SW, SH).unwrap();
    s.primitive = DrawPrimitive::Quads;
    let quads = ParticleRenderer::new(&ctx, s, SW, SH).unwrap();
    let state = mixed_state();
    let a = render_frame(&ctx, &points, &state, None, 0.0, &camera());
    let b = render_frame(&ctx, &quads, &state, None, 0.0, &camera());
    let mean = a
        .as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| x.abs_diff(*y) as f32)
        .sum::<f32>()
        / a.as_raw().len() as f32;
    assert!(
        mean < 0.5,
        "sprite quads differ from point sprites by {mean} on average"
    );
    assert!(
        max_diff(&a, &b) <= 24,
        "largest difference {}",
        max_diff(&a, &b)
    );
    no_gl_error(&ctx);
}

/// An atlas whose tile 0 is a bar along the tile's u axis (|u| < 0.4, |v| < 0.07): asymmetric,
/// so its principal axis shows the sprite's angle.
fn bar_atlas() -> atlas::AtlasImage {
    let mut img = atlas::generate(atlas::DEFAULT_TILE);
    let t = img.tile;
    let size = img.size();
    for y in 0..t {
        for x in 0..t {
            let u = (x as f32 + 0.5) / t as f32 - 0.5;
            let v = (y as f32 + 0.5) / t as f32 - 0.5;
            let a = if u.abs() < 0.4 && v.abs() < 0.07 {
                1.0
            } else {
                0.0
            };
            let i = 4 * (y * size + x) as usize;
            img.data[i..i + 4].copy_from_slice(&[1.0, 1.0, 1.0, a]);
        }
    }
    img
}

/// The principal axis angle (radians in (-π/2, π/2], y up) of the red channel in a patch.
fn principal_axis(img: &image::RgbImage, cx: u32, cy: u32, half: i32) -> f32 {
    let (mut m, mut sxx, mut syy, mut sxy) = (0.0f64, 0.0, 0.0, 0.0);
    for dy in -half..=half {
        for dx in -half..=half {
            let w = img
                .get_pixel((cx as i32 + dx) as u32, (cy as i32 + dy) as u32)
                .0[0] as f64;
            let (x, y) = (dx as f64, -dy as f64);
            m += w;
            sxx += w * x * x;
            syy += w * y * y;
            sxy += w * x * y;
        }
    }
    assert!(m > 0.0, "nothing drawn at ({cx}, {cy})");
    (0.5 * (2.0 * sxy).atan2(sxx - syy)) as f32
}

/// Difference of two axis angles modulo π, in degrees.
fn axis_error(a: f32, b: f32) -> f32 {
    let d = (a - b).rem_euclid(std::f32::consts::PI);
    d.min(std::f32::consts::PI - d).to_degrees()
}

/// Latta §3.4.6: the sprite's angle is angle0 + speed · age, the speed drawn in the type's range:
/// the bar's principal axis after t seconds of life (and for a permanent particle, t seconds of
/// simulation time) matches the CPU twin, for points and quads.
#[test]
fn rotation_speed_turns_the_sprite_by_speed_times_age() {
    let ctx = context();
    let size = 31.0;
    let centres = [(20u32, 18u32), (70, 18), (20, 54), (70, 54)];
    // (random number, age in s, permanent)
    let cases = [
        (0.0f32, 0.0f32, false),
        (0.0, 0.5, false),
        (0.05, 1.2, false),
        (0.3, 0.8, true),
    ];
    let time = 0.8;
    let mut state = State::new();
    for (k, (&(x, y), &(r, age, permanent))) in centres.iter().zip(&cases).enumerate() {
        let p = behind_pixel(x, y, 0.1);
        if permanent {
            // Born at 0, total life 0: its age is the simulation time.
            state.set(k, p, 1.0, 0.0, 0, r);
        } else {
            state.set(k, p, 2.0 - age, 2.0, 0, r);
        }
    }
    let spin = [40.0, 100.0];
    for primitive in [DrawPrimitive::Points, DrawPrimitive::Quads] {
        let mut s = white(DrawMode::Sprites, primitive, size);
        s.types[0].spin = spin;
        let mut r = ParticleRenderer::new(&ctx, s, SW, SH).unwrap();
        r.set_atlas(&bar_atlas()).unwrap();
        let img = render_frame(&ctx, &r, &state, None, time, &camera());
        for (k, &(cx, cy)) in centres.iter().enumerate() {
            let (rand, age, permanent) = cases[k];
            let age = if permanent { time } else { age };
            let expected = sprite_angle(rand, spin, age);
            let speed = spin[0] + second_random(rand) * (spin[1] - spin[0]);
            assert!((spin[0]..=spin[1]).contains(&speed));
            let measured = principal_axis(&img, cx, cy, 15);
            let err = axis_error(measured, expected);
            assert!(
                err < 2.0,
                "{primitive:?} sprite {k}: axis {:.1}°, expected {:.1}° (speed {speed:.1}°/s)",
                measured.to_degrees(),
                expected.to_degrees()
            );
        }
    }
    no_gl_error(&ctx);
}

/// Size over life: the rendered area of an opaque disc sprite scales as the square of the
/// curve's scale at the particle's relative age.
#[test]
fn size_over_life_scales_the_area_by_the_curve() {
    let ctx = context();
    let mut atlas = bar_atlas();
    for px in atlas.data.chunks_mut(4) {
        px.copy_from_slice(&[1.0; 4]); // opaque everywhere: the inscribed disc is drawn
    }
    let curve = SizeCurve::from_points(&[[0.0, 1.0], [0.5, 2.5], [1.0, 1.5]]);
    let ages = [0.0f32, 0.25, 0.5, 0.9];
    let base = 9.0;
    let mut areas = Vec::new();
    for primitive in [DrawPrimitive::Points, DrawPrimitive::Quads] {
        let mut s = white(DrawMode::Sprites, primitive, base);
        s.types[0].size = curve;
        let mut r = ParticleRenderer::new(&ctx, s, SW, SH).unwrap();
        r.set_atlas(&atlas).unwrap();
        for &age in &ages {
            let mut state = State::new();
            state.set(0, behind_pixel(48, 36, 0.0), 2.0 * (1.0 - age), 2.0, 0, 0.0);
            let img = render_frame(&ctx, &r, &state, None, 0.0, &camera());
            let area = img.pixels().map(|p| p.0[0] as f32 / 255.0).sum::<f32>();
            // The pixels whose centres lie in the disc of diameter d around the particle's
            // pixel centre (the sprite's inscribed circle).
            let d = base * curve.eval(age);
            let h = (d / 2.0).ceil() as i32;
            let disc = (-h..=h)
                .flat_map(|y| (-h..=h).map(move |x| (x * x + y * y) as f32))
                .filter(|r2| *r2 <= d * d / 4.0)
                .count() as f32;
            assert!(
                (area - disc).abs() <= 0.03 * disc + 2.0,
                "{primitive:?} at age {age}: area {area}, disc of {d} pixels {disc}"
            );
            areas.push((area, disc));
        }
        // Relative to birth, the areas grow as the lattice discs of the curve's diameters.
        let n = areas.len();
        for &(area, disc) in &areas[n - 3..] {
            let (a0, d0) = areas[n - 4];
            assert!(((area / a0) / (disc / d0) - 1.0).abs() < 0.05, "{areas:?}");
        }
    }
    no_gl_error(&ctx);
}

/// Latta §3.4.6: keyframes "defined for each particle type": two emitters' particles take their
/// own ramps, a type without its own takes the scene's.
#[test]
fn keyframes_per_type_colour_each_emitters_particles() {
    let ctx = context();
    let flat = |rgba: [f32; 4], end: [f32; 4]| {
        Some(vec![
            key(0.0, rgba),
            key(0.3, rgba),
            key(0.6, end),
            key(1.0, end),
        ])
    };
    let mut s = white(DrawMode::Points, DrawPrimitive::Points, 5.0);
    s.blending = Blending::Alpha;
    s.keyframes = vec![
        key(0.0, [0.2, 0.2, 1.0, 1.0]),
        key(0.3, [0.2, 0.2, 1.0, 1.0]),
        key(0.6, [0.2, 0.2, 1.0, 1.0]),
        key(1.0, [0.2, 0.2, 1.0, 1.0]),
    ];
    s.types[0].keyframes = flat([1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0, 1.0]);
    s.types[1].keyframes = flat([0.0, 1.0, 0.0, 1.0], [1.0, 1.0, 0.0, 1.0]);
    let r = ParticleRenderer::new(&ctx, s.clone(), SW, SH).unwrap();
    let centres = [
        (15u32, 15u32),
        (45, 15),
        (75, 15),
        (15, 50),
        (45, 50),
        (75, 50),
    ];
    let types = [0u32, 1, 2, 0, 1, 2];
    let ages = [0.1f32, 0.1, 0.1, 0.8, 0.8, 0.8];
    let mut state = State::new();
    for k in 0..6 {
        let (x, y) = centres[k];
        state.set(
            k,
            behind_pixel(x, y, 0.0),
            2.0 * (1.0 - ages[k]),
            2.0,
            types[k],
            0.0,
        );
    }
    let img = render_frame(&ctx, &r, &state, None, 0.0, &camera());
    for k in 0..6 {
        let (x, y) = centres[k];
        let want = s.ramp_of(types[k] as usize).eval(ages[k]);
        let what = format!("particle {k} of type {}, ramp {want:?}", types[k]);
        probe(
            &img,
            x,
            y,
            &[0, 1, 2].map(|c| to_u8(want[c]) as u8),
            1,
            &what,
        );
    }
    no_gl_error(&ctx);
}

/// Where `p` lands in window pixels (x right, y up), unrounded.
fn window(cam: &Camera, p: Vec3) -> Vec2 {
    let c = cam.view_projection(FW as f32 / FH as f32) * p.extend(1.0);
    let ndc = c.truncate() / c.w;
    Vec2::new(
        (ndc.x * 0.5 + 0.5) * FW as f32,
        (ndc.y * 0.5 + 0.5) * FH as f32,
    )
}

/// The velocity-stretched quad (motion blur) spans |v_screen|·stretch + size along the screen
/// velocity and size across it; Verlet's previous positions give the same streak as the
/// velocity; a particle at rest is the plain quad.
#[test]
fn stretched_quads_are_as_long_as_the_screen_motion() {
    let ctx = context();
    let cam = front_camera(3.0);
    let size = 5.0;
    let stretch = 0.5;
    let mut s = white(DrawMode::Points, DrawPrimitive::Stretched, size);
    s.stretch = stretch;
    let r = ParticleRenderer::new(&ctx, s.clone(), SW, SH).unwrap();
    let p = Vec3::new(0.3, -0.1, 0.0);
    for v in [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 0.8, 0.0),
        Vec3::ZERO,
    ] {
        let mut state = State::new();
        state.set(0, p, 1.0, 2.0, 0, 0.0);
        let mut vel = vec![[0.0f32; 4]; N];
        vel[0] = [v.x, v.y, v.z, 0.0];
        let motion = state_texture(&ctx, "velocity", &vel);
        let img = render_frame(&ctx, &r, &state, Some(&motion), 0.0, &cam);
        let px = lit(&img);
        let (xs, ys): (Vec<u32>, Vec<u32>) = px.iter().copied().unzip();
        let width = (xs.iter().max().unwrap() - xs.iter().min().unwrap() + 1) as f32;
        let height = (ys.iter().max().unwrap() - ys.iter().min().unwrap() + 1) as f32;
        let screen = window(&cam, p) - window(&cam, p - v * stretch);
        let (along, across) = if v.y != 0.0 {
            (height, width)
        } else {
            (width, height)
        };
        let expected = screen.length() + size;
        assert!(
            (along - expected).abs() <= 1.0,
            "v {v}: {along} pixels along the motion, expected {expected}"
        );
        assert_eq!(across, size, "v {v}: {across} pixels across the motion");
        if v == Vec3::ZERO {
            let quads = ParticleRenderer::new(
                &ctx,
                ParticleStyle {
                    primitive: DrawPrimitive::Quads,
                    ..s.clone()
                },
                SW,
                SH,
            )
            .unwrap();
            assert_eq!(img, render_frame(&ctx, &quads, &state, None, 0.0, &cam));
            continue;
        }
        // Verlet: the previous position one step of dt back gives the same streak.
        let dt = 1.0 / 60.0;
        let mut prev = vec![[f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0]; N];
        let q = p - v * dt;
        prev[0] = [q.x, q.y, q.z, 1.0];
        let previous = state_texture(&ctx, "previous", &prev);
        let target = FrameTarget::new(&ctx, FW, FH).unwrap();
        let (pos, stat) = state.upload(&ctx);
        r.clear(&target);
        let frame = FrameState {
            positions: &pos,
            statics: &stat,
            motion: Some(Motion::Previous {
                positions: &previous,
                dt,
            }),
            time: 0.0,
            spins: None,
            count: N,
        };
        r.draw_frame(&target, &frame, &cam).unwrap();
        let verlet = target.read_rgb().unwrap();
        assert!(
            lit(&verlet).len().abs_diff(px.len()) <= size as usize,
            "Verlet streak {} pixels, velocity streak {}",
            lit(&verlet).len(),
            px.len()
        );
    }
    // Without motion, a stretched draw is refused.
    let target = FrameTarget::new(&ctx, FW, FH).unwrap();
    let (pos, stat) = State::new().upload(&ctx);
    assert!(r.draw(&target, &pos, &stat, &cam, N).is_err());
    no_gl_error(&ctx);
}

/// The driver's point size range is known; sprites wider than it are refused with the fix
/// (quads), and quads are refused on the vertex-buffer path.
#[test]
fn point_size_limit_and_quad_paths() {
    let ctx = context();
    let [lo, hi] = ctx.limits().point_size_range;
    assert!(
        lo > 0.0 && lo <= 1.0 && hi >= lo,
        "point size range [{lo}, {hi}]"
    );
    let mut s = white(DrawMode::Sprites, DrawPrimitive::Points, hi + 1.0);
    let e = ParticleRenderer::new(&ctx, s.clone(), SW, SH).unwrap_err();
    assert!(e.to_string().contains("quads"), "{e}");
    s.primitive = DrawPrimitive::Quads;
    assert!(ParticleRenderer::new(&ctx, s.clone(), SW, SH).is_ok());
    s.path = RenderPath::VertexBuffer;
    let e = ParticleRenderer::new(&ctx, s, SW, SH).unwrap_err();
    assert!(e.to_string().contains("texture_fetch"), "{e}");
    no_gl_error(&ctx);
}

/// The engine draws an alpha-blended, sorted scene (smoke) as quads and stretched quads: the sort
/// gathers the velocities (or Verlet's previous positions) with the state; without exposure a
/// stretched quad is the quad, and flat quads are the points; with exposure the streaks cover more.
#[test]
fn engine_draws_sorted_scenes_as_quads_and_streaks() {
    use texflow::engine::ParticleEngine;
    use texflow::scene::{parse, Integrator};
    let ctx = context();
    let src = texflow::scene::builtin_source("smoke").unwrap();
    for integrator in [Integrator::Euler, Integrator::Verlet] {
        let frame = |primitive, stretch: f32| {
            let mut scene = parse("smoke", src).unwrap();
            scene.particles.size = [16, 16];
            scene.render.resolution = [64, 64];
            scene.render.mode = DrawMode::Points;
            scene.render.point_size = 3.0;
            scene.render.primitive = primitive;
            scene.render.stretch = stretch;
            scene.integrator = integrator;
            let mut e = ParticleEngine::new(&ctx, &scene, 3).unwrap();
            for _ in 0..20 {
                e.advance_frame().unwrap();
            }
            e.render().unwrap()
        };
        let points = frame(DrawPrimitive::Points, 0.0);
        let quads = frame(DrawPrimitive::Quads, 0.0);
        let still = frame(DrawPrimitive::Stretched, 0.0);
        let streaks = frame(DrawPrimitive::Stretched, 0.2);
        let background = points.get_pixel(0, 0).0;
        assert!(
            lit_pixels(&points, background) > 20,
            "{integrator:?}: nothing drawn"
        );
        assert_eq!(
            points, quads,
            "{integrator:?}: flat quads differ from points"
        );
        assert!(
            max_diff(&quads, &still) <= 1,
            "{integrator:?}: no exposure, not the quad"
        );
        assert!(
            lit_pixels(&streaks, background) > lit_pixels(&quads, background),
            "{integrator:?}: streaks cover no more than quads"
        );
    }
    no_gl_error(&ctx);
}

/// The new keys are checked where they are written: line and column, the problem and the fix.
#[test]
fn sprite_keys_are_validated_with_their_place() {
    let src = texflow::scene::builtin_source("fountain").unwrap();
    let bad = |extra: &str, render: &str| {
        let text = src
            .replacen(
                "[[emitters.allocator]]",
                &format!("[[emitters.allocator]]\n{extra}"),
                1,
            )
            .replacen("[render]", &format!("[render]\n{render}"), 1);
        texflow::scene::parse("x.toml", &text)
            .unwrap_err()
            .to_string()
    };
    let e = bad("rotation_speed = [90.0, 10.0]", "");
    assert!(
        e.contains("rotation_speed") && e.contains("min <= max"),
        "{e}"
    );
    let e = bad("size_over_life = [[0.0, 1.0], [0.5, 2.0]]", "");
    assert!(e.contains("the last 1"), "{e}");
    let nine = (0..9)
        .map(|i| format!("{{ age = {}, rgba = [1, 1, 1, 1] }}", i as f32 / 8.0))
        .collect::<Vec<_>>()
        .join(", ");
    let e = bad(&format!("keyframes = [{nine}]"), "");
    assert!(e.contains("9 keyframes are too many"), "{e}");
    let e = bad(
        "keyframes = [{ age = 0.5, rgba = [1, 1, 1, 1] }, { age = 0.25, rgba = [1, 1, 1, 1] }]",
        "",
    );
    assert!(e.contains("must ascend"), "{e}");
    let e = bad("", "primitive = \"quads\"\npath = \"vertex_buffer\"");
    assert!(
        e.contains("texture_fetch") && e.contains("primitive"),
        "{e}"
    );
    for e in [
        bad("rotation_speed = [90.0, 10.0]", ""),
        bad("", "stretch = -1.0"),
    ] {
        assert!(e.contains("x.toml:"), "no place in {e}");
    }
}
