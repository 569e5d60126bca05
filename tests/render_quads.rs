//! The renderer's quads (Latta §3.4.5-3.4.6): quads by vertex replication cover the projected
//! square, stretched quads are as long as the screen motion, sprites turn by speed times age,
//! size over life scales the area, keyframes per type, and the engine draws sorted scenes as
//! quads and streaks. Helpers in tests/renderer/.

mod common;
mod renderer;

use common::image::{front_camera, lit_pixels, probe};
use common::{context, no_gl_error};
use glam::{Vec2, Vec3};
use renderer::*;
use texflow::gl::{Context, Texture, TextureDesc, TextureFormat};
use texflow::render::{
    atlas, second_random, sprite_angle, Camera, FrameState, FrameTarget, Motion, ParticleRenderer,
    ParticleStyle, SizeCurve,
};
use texflow::scene::{Blending, DrawMode, DrawPrimitive, RenderPath};

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
        user: &[],
    };
    renderer.draw_frame(&target, &frame, cam).unwrap();
    target.read_rgb().unwrap()
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

/// Renders `state` with `renderer`, its particle 0 (at `p`, velocity `v`) given the previous
/// position one step of `dt` back (Verlet's motion).
fn verlet_frame(
    ctx: &Context,
    renderer: &ParticleRenderer,
    state: &State,
    (p, v): (Vec3, Vec3),
    dt: f32,
    cam: &Camera,
) -> image::RgbImage {
    let mut prev = vec![[f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0]; N];
    let q = p - v * dt;
    prev[0] = [q.x, q.y, q.z, 1.0];
    let previous = state_texture(ctx, "previous", &prev);
    let target = FrameTarget::new(ctx, FW, FH).unwrap();
    let (pos, stat) = state.upload(ctx);
    renderer.clear(&target);
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
        user: &[],
    };
    renderer.draw_frame(&target, &frame, cam).unwrap();
    target.read_rgb().unwrap()
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
        let verlet = verlet_frame(&ctx, &r, &state, (p, v), 1.0 / 60.0, &cam);
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

/// The engine draws an alpha-blended, sorted scene (smoke-unlit) as quads and stretched quads: the
/// sort gathers the velocities (or Verlet's previous positions) with the state; without exposure a
/// stretched quad is the quad, and flat quads are the points; with exposure the streaks cover more.
#[test]
fn engine_draws_sorted_scenes_as_quads_and_streaks() {
    use texflow::engine::ParticleEngine;
    use texflow::scene::{parse, Integrator};
    let ctx = context();
    let src = texflow::scene::builtin_source("smoke-unlit").unwrap();
    for integrator in [Integrator::Euler, Integrator::Verlet] {
        let frame = |primitive, stretch: f32| {
            let mut scene = parse("smoke-unlit", src).unwrap();
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
