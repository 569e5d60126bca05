//! Half-angle slicing (`render.lighting = "half_angle"`): the key pass sorts along an axis as a
//! CPU sort does, the engine sorts lit scenes along the half-angle vector, a particle behind a
//! dense layer (seen from the light) is darker than one beside it, as a CPU twin of the light
//! buffer's transmittance per slice says, and the lighting keys are refused at their place.

mod common;

use common::image::texture;
use common::{context, no_gl_error};
use glam::Vec3;
use texflow::gl::TextureFormat;
use texflow::render::{Camera, FrameState, FrameTarget, HalfAngleRenderer, ParticleStyle};
use texflow::scene::{self, Blending, DrawOrder, Keyframe, LightSection, Render};
use texflow::sort::{KeyMode, SortOptions, Sorter, Variant};

fn lcg(s: &mut u64) -> f32 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*s >> 33) % 20000) as f32 / 1000.0 - 10.0
}

/// The key pass with `KeyMode::Axis` and a whole sort give the particles in ascending
/// dot(x, axis), ties by index, dead ones last: the order of a CPU sort.
#[test]
fn axis_sort_matches_a_cpu_sort() {
    let ctx = context();
    let (w, h) = (16u32, 8u32);
    let n = (w * h) as usize;
    let mut seed = 5;
    let mut pos: Vec<f32> = (0..n)
        .flat_map(|_| [lcg(&mut seed), lcg(&mut seed), lcg(&mut seed), 1.0])
        .collect();
    // A few dead particles and a few with equal keys.
    for i in [3, 40, 77] {
        pos[4 * i..4 * i + 4].copy_from_slice(&[f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0]);
    }
    pos.copy_within(4 * 10..4 * 11, 4 * 11);
    let positions = texture(&ctx, "positions", (w, h), TextureFormat::Rgba32F, &pos);
    let axis = Vec3::new(0.3, -0.8, 0.5).normalize();
    let key = |i: usize| {
        let p = &pos[4 * i..4 * i + 4];
        if p[3] > 0.0 {
            Vec3::from_slice(&p[..3]).dot(axis)
        } else {
            f32::INFINITY
        }
    };
    let mut want: Vec<usize> = (0..n).collect();
    want.sort_by(|&a, &b| key(a).total_cmp(&key(b)).then(a.cmp(&b)));
    for variant in [Variant::OddEven, Variant::Packed, Variant::Blocked] {
        let mut sorter = Sorter::new(&ctx, variant, w, h, SortOptions::default()).unwrap();
        let mode = KeyMode::Axis { direction: axis };
        sorter.write_keys(&positions, n, &mode, true).unwrap();
        sorter.sort();
        let got: Vec<usize> = sorter
            .read()
            .unwrap()
            .iter()
            .map(|e| e[1] as usize)
            .collect();
        assert_eq!(got, want, "{variant:?}");
    }
    no_gl_error(&ctx);
}

/// The engine sorts a lit scene along the half-angle vector of its camera and light: the
/// vector halfway between the view and the light direction (the view flipped when the light
/// faces the viewer), computed here from the scene's keys.
#[test]
fn the_engine_sorts_lit_scenes_along_the_half_angle() {
    let ctx = context();
    let mut s = scene::load("smoke").unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [32, 32];
    let mut engine = texflow::ParticleEngine::new(&ctx, &s, 1).unwrap();
    for _ in 0..20 {
        engine.advance_frame().unwrap();
    }
    assert!(engine.order_for_drawing().unwrap());
    let camera = engine.camera();
    let v = (camera.target - camera.eye()).normalize();
    let l = Vec3::from(s.render.light.direction).normalize();
    let axis = if v.dot(l) >= 0.0 { v + l } else { l - v }.normalize();
    let pos = engine.sim().positions().read_f32().unwrap();
    let entries = engine.sorter().unwrap().read().unwrap();
    let live: Vec<_> = entries.iter().filter(|e| e[0].is_finite()).collect();
    assert!(live.len() > 20, "{} live particles", live.len());
    for (k, e) in live.iter().enumerate() {
        let i = e[1] as usize;
        let want = Vec3::from_slice(&pos[4 * i..4 * i + 3]).dot(axis);
        assert!(
            (e[0] - want).abs() < 1e-4,
            "entry {k}: key {} for {want}",
            e[0]
        );
        assert!(k == 0 || live[k - 1][0] <= e[0], "entry {k} out of order");
    }
    let frame = engine.render().unwrap();
    assert_eq!(frame.dimensions(), (32, 32));
    no_gl_error(&ctx);
}

/// The twin's configurations: a 64×64 frame looking down -z from (0, 0, 4), white particles
/// of opacity 0.5 drawn as 8-pixel squares, listed in ascending order along the half-angle
/// vector, and a layer of three at one place between the light and A; B and C are lit
/// unshadowed (C beside A, B nowhere under the layer).
const SIZE: f32 = 8.0;
const ALPHA: f32 = 0.5;
const AMBIENT: f32 = 0.2;
const LIGHT: f32 = 0.8;
const EXTENT: f32 = 1.0;
const LIGHT_TEXELS: u32 = 16;

/// A light and the particles in drawing order; `probes` are B, A and C, `layer` the three
/// stacked ones.
struct Config {
    light: [f32; 3],
    particles: [[f32; 3]; 6],
    probes: [usize; 3],
    layer: [usize; 3],
}

/// Straight down: the eye looks across the light (dot = 0), so the slices go front to back
/// with the under operator, along (0, -1, -1)/√2: B above, the layer, then A under it and C.
const DOWN: Config = Config {
    light: [0.0, -1.0, 0.0],
    particles: [
        [0.0, 1.0, 0.0],
        [0.0, 0.5, 0.0],
        [0.0, 0.5, 0.0],
        [0.0, 0.5, 0.0],
        [0.0, 0.0, 0.0],
        [0.8, 0.0, 0.0],
    ],
    probes: [0, 4, 5],
    layer: [1, 2, 3],
};

/// Down and towards the eye: the light faces the viewer (dot < 0), so the slices go back to
/// front with the over operator; the layer sits on A's ray to the light, half a unit behind.
const FACING: Config = Config {
    light: [0.0, -1.0, 1.0],
    particles: [
        [0.0, 0.5, -0.5],
        [0.0, 0.5, -0.5],
        [0.0, 0.5, -0.5],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0],
        [0.8, 0.0, 0.0],
    ],
    probes: [3, 4, 5],
    layer: [0, 1, 2],
};

fn camera() -> Camera {
    Camera {
        target: Vec3::ZERO,
        distance: 4.0,
        azimuth: 0.0,
        elevation: 0.0,
        ..Camera::default()
    }
}

/// The CPU twin of the light buffer: the transmittance particle `i` finds, bilinear between
/// the four light-buffer texels around it, each texel's the product of 1 − α over the
/// particles of earlier slices whose light-facing square covers the texel's centre. The
/// buffer's axes are x and the unit vector normal to x and the light (both lights here are
/// normal to x; up to signs, which the texel grid centred on the target is symmetric in); a
/// square is as wide in the scene as the sprite is at its depth d: SIZE · 2·d·tan(fov/2) / 64.
fn twin_transmittance(c: &Config, i: usize, slices: usize) -> f32 {
    let n = c.particles.len();
    let batch = n.div_ceil(slices);
    let w_axis = Vec3::from(c.light).normalize().cross(Vec3::X);
    let plane = |p: [f32; 3]| (p[0], Vec3::from(p).dot(w_axis));
    let half = |p: [f32; 3]| SIZE * (4.0 - p[2]) * (22.5f32).to_radians().tan() / 64.0;
    let texels = LIGHT_TEXELS as f32;
    let centre = |t: f32| ((t + 0.5) / texels * 2.0 - 1.0) * EXTENT;
    let texel = |tu: f32, tw: f32| -> f32 {
        if tu < 0.0 || tw < 0.0 || tu >= texels || tw >= texels {
            return 1.0;
        }
        (0..n)
            .filter(|&j| j / batch < i / batch)
            .filter(|&j| {
                let (u, w) = plane(c.particles[j]);
                let h = half(c.particles[j]);
                (u - centre(tu)).abs() < h && (w - centre(tw)).abs() < h
            })
            .map(|_| 1.0 - ALPHA)
            .product()
    };
    let coord = |x: f32| (x / EXTENT * 0.5 + 0.5) * texels - 0.5;
    let (u, w) = plane(c.particles[i]);
    let (u, w) = (coord(u), coord(w));
    let (u0, w0) = (u.floor(), w.floor());
    let (fu, fw) = (u - u0, w - w0);
    let row = |tw: f32| texel(u0, tw) * (1.0 - fu) + texel(u0 + 1.0, tw) * fu;
    row(w0) * (1.0 - fw) + row(w0 + 1.0) * fw
}

/// Draws the configuration in `slices` slices; the frame read back.
fn draw(ctx: &texflow::gl::Context, c: &Config, slices: u32) -> image::RgbImage {
    let mut pos = vec![f32::INFINITY; 8 * 4];
    let statics = vec![0.0; 8 * 4];
    for k in 0..8 {
        pos[4 * k + 3] = 0.0;
    }
    for (k, p) in c.particles.iter().enumerate() {
        pos[4 * k..4 * k + 4].copy_from_slice(&[p[0], p[1], p[2], 1.0]);
    }
    let positions = texture(ctx, "positions", (4, 2), TextureFormat::Rgba32F, &pos);
    let statics = texture(ctx, "statics", (4, 2), TextureFormat::Rgba32F, &statics);
    let render = Render {
        point_size: SIZE,
        blending: Blending::Alpha,
        order: DrawOrder::BackToFront,
        keyframes: vec![Keyframe {
            age: 0.0,
            rgba: [1.0, 1.0, 1.0, ALPHA],
        }],
        ..Render::default()
    };
    let style = ParticleStyle::from_render(&render, [1.0; 4]);
    let light = LightSection {
        direction: c.light,
        colour: [LIGHT; 3],
        ambient: [AMBIENT; 3],
        density: 1.0,
        resolution: LIGHT_TEXELS,
        extent: Some(EXTENT),
    };
    let lit = HalfAngleRenderer::new(ctx, style, &light, slices, EXTENT).unwrap();
    let target = FrameTarget::new(ctx, 64, 64).unwrap();
    let state = FrameState {
        positions: &positions,
        statics: &statics,
        motion: None,
        time: 0.0,
        spins: None,
        count: c.particles.len(),
        user: &[],
    };
    lit.draw(&target, &state, &camera(), None).unwrap();
    target.read_rgb().unwrap()
}

/// A particle under a dense layer, as the light sees it, is darker than one beside it once
/// the layer is drawn into the light buffer in an earlier slice, by the transmittance the CPU
/// twin gives per slice; in one slice nothing shadows anything. Both orders: the light across
/// the view (under operator) and facing it (over operator). Over a black background a pixel
/// covered by one particle is α · (ambient + light · T) with either operator.
#[test]
fn a_particle_behind_a_dense_layer_is_darker_as_the_twin_says() {
    let ctx = context();
    let eye = camera().eye();
    for c in [&DOWN, &FACING] {
        // The configuration lists the particles as the sort along the half-angle vector would.
        let v = (camera().target - eye).normalize();
        let l = Vec3::from(c.light).normalize();
        let s = if v.dot(l) >= 0.0 { v + l } else { l - v };
        let keys: Vec<f32> = c.particles.iter().map(|p| Vec3::from(*p).dot(s)).collect();
        assert!(keys.windows(2).all(|k| k[0] <= k[1]), "{keys:?}");
        for slices in [1, 2, 6] {
            let frame = draw(&ctx, c, slices);
            let value = |i: usize| {
                let p = Vec3::from(c.particles[i]);
                let (x, y) = camera().project_to_pixel(p, 64, 64).unwrap();
                frame.get_pixel(x, y).0[0] as f32 / 255.0
            };
            let at = format!("light {:?}, {slices} slices", c.light);
            for i in c.probes {
                let t = twin_transmittance(c, i, slices as usize);
                let want = ALPHA * (AMBIENT + LIGHT * t);
                assert!(
                    (value(i) - want).abs() <= 2.0 / 255.0,
                    "{at}, particle {i}: {} against the twin's {want} (T = {t})",
                    value(i)
                );
            }
            // The layer's pixel: its three composited in drawing order, the first on top
            // with the under operator, the last with the over operator.
            let lit =
                |i: usize| ALPHA * (AMBIENT + LIGHT * twin_transmittance(c, i, slices as usize));
            let (mut colour, mut cover) = (0.0, 0.0);
            for i in c.layer {
                if v.dot(l) >= 0.0 {
                    colour += (1.0 - cover) * lit(i);
                    cover += (1.0 - cover) * ALPHA;
                } else {
                    colour = lit(i) + (1.0 - ALPHA) * colour;
                }
            }
            let got = value(c.layer[0]);
            assert!(
                (got - colour).abs() <= 3.0 / 255.0,
                "{at}, layer: {got} against {colour}"
            );
            let (under, beside) = (value(c.probes[1]), value(c.probes[2]));
            if slices == 1 {
                assert!((under - beside).abs() <= 1.0 / 255.0, "{at}: no shadow");
            } else {
                assert!(under + 0.1 < beside, "{at}: {under} not below {beside}");
            }
        }
    }
    no_gl_error(&ctx);
}

/// The lighting keys' bad values are refused at their line and column.
#[test]
fn lighting_keys_are_refused_at_their_place() {
    let lit = scene::builtin_source("smoke").unwrap();
    let unlit = scene::builtin_source("smoke-unlit").unwrap();
    let cases = [
        (
            lit.replace("slices = 32", "slices = 0"),
            "slices = 0",
            "slices",
        ),
        (
            lit.replace(
                "direction = [0.5, -1.0, -0.3]",
                "direction = [0.0, 0.0, 0.0]",
            ),
            "light = {",
            "direction",
        ),
        (
            lit.replace("blending = \"alpha\"", "blending = \"additive\""),
            "lighting = ",
            "alpha",
        ),
        (
            unlit.replacen("[render]\n", "[render]\nslices = 8\n", 1),
            "slices = 8",
            "half_angle",
        ),
        (
            lit.replace(
                "variant = \"oddeven\"",
                "variant = \"oddeven\"\npasses_per_frame = 4",
            ),
            "passes_per_frame",
            "passes_per_frame",
        ),
    ];
    for (src, line_start, words) in cases {
        let line = src.lines().position(|l| l.starts_with(line_start)).unwrap() + 1;
        let err = scene::parse("lit.toml", &src).unwrap_err();
        let text = err.to_string();
        assert!(
            text.starts_with(&format!("lit.toml:{line}:")),
            "{text} (line {line})"
        );
        assert!(text.contains(words), "{text}");
        assert!(err.is_bad_input());
    }
    scene::parse("lit.toml", lit).expect("smoke is valid");
}

/// `bench scene` times a lit scene's own passes: the keys along the half-angle vector, the
/// light-buffer passes and the eye passes, each next to a floor measured in the same run.
#[test]
fn bench_scene_times_the_slices_passes() {
    let ctx = context();
    let opts = texflow::bench::SceneBenchOptions {
        repeats: 1,
        warmup_frames: Some(30),
        resolution: Some([64, 64]),
        ..Default::default()
    };
    let s = scene::load("smoke").unwrap();
    let records = texflow::bench::bench_scene(&ctx, &s, &[16], &opts, |_| {}).unwrap();
    let phases = &records[0].phases;
    for name in [
        "sort keys: along the half-angle vector",
        "light-buffer passes",
        "eye passes",
    ] {
        let p = phases
            .iter()
            .find(|p| p.phase.starts_with(name))
            .unwrap_or_else(|| panic!("no phase {name} in {phases:?}"));
        assert!(p.ms > 0.0 && p.floor_ms > 0.0, "{p:?}");
    }
    no_gl_error(&ctx);
}
