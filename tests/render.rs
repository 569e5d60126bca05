//! The general particle renderer (`render::ParticleRenderer`): both data paths give the same
//! image, dead / unborn / non-finite particles stay invisible, keyframe colours by age, the over
//! and under operators, the sprite atlas tiles and their rotation. Quads and streaks are in
//! tests/render_quads.rs, the helpers in tests/renderer/.

mod common;
mod renderer;

use common::image::{lit_pixels, probe};
use common::{context, no_gl_error};
use glam::{Vec2, Vec3};
use renderer::*;
use texflow::render::{atlas, FrameTarget, KeyframeRamp, ParticleRenderer, ParticleStyle};
use texflow::scene::{Blending, DrawMode, DrawOrder, Keyframe, RenderPath};

const BLENDS: [(Blending, DrawOrder); 4] = [
    (Blending::Additive, DrawOrder::BackToFront),
    (Blending::Multiplicative, DrawOrder::BackToFront),
    (Blending::Alpha, DrawOrder::BackToFront),
    (Blending::Alpha, DrawOrder::FrontToBack),
];

fn background_pixel(style: &ParticleStyle) -> [u8; 3] {
    style.background.map(|c| (c * 255.0).round() as u8)
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
