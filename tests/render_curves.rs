//! The particle type's look as curves of the emitter's time (`tint`, `sprite_scale`), each
//! particle keeping the value at its birth, against the curve evaluated on the CPU at the birth
//! time read from the state; `render.rotation` against the same sprite turned on the CPU; their
//! refusals at their line and column.

mod common;

use common::context;
use glam::Vec3;
use texflow::scene::curve::Animated;
use texflow::scene::{self, SceneFile};

/// An allocator emitter whose centre runs along x at 1 m/s from -2 m, one birth every 0.4 s,
/// particles at rest and long-lived: each is drawn where it was born, 0.4 m from the last, in a
/// frame of 512×128 that sees x in about [-2.3, 2.3]. `keys`: the emitter's other keys,
/// `render`: the render section's.
fn row_scene(keys: &str, render: &str) -> SceneFile {
    row_of("allocator]]\nrate = 2.5", keys, render)
}

/// [`row_scene`] with the emitter's kind and own key `kind` (`allocator]]\nrate = 2.5`).
fn row_of(kind: &str, keys: &str, render: &str) -> SceneFile {
    let src = format!(
        "name = \"row\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 8]\n[time]\ndt = 0.05\n\
         [[emitters.{kind}\nshape = \"point\"\n\
         center = {{ keys = [[0.0, [-2.0, 0.0, 0.0]], [4.0, [2.0, 0.0, 0.0]]] }}\n\
         direction = [0.0, 1.0, 0.0]\nspeed = 0.0\nlife = [15.0, 15.0]\n{keys}\n\
         [render]\nresolution = [512, 128]\nblending = \"additive\"\n\
         keyframes = [{{ age = 0.0, rgba = [1.0, 1.0, 1.0, 1.0] }}]\n{render}\n\
         [render.camera]\ndistance = 1.45\nelevation = 0.0\n"
    );
    common::scene::parse("row.toml", &src)
}

/// Runs `s` to 4.3 s and gives the frame, and per live particle its pixel and birth time (the
/// statics' x, where the allocator stamped it).
/// A live particle: its pixel and its birth time.
type Born = ((u32, u32), f32);

fn run_row(s: &SceneFile) -> (image::RgbImage, Vec<Born>) {
    let ctx = context();
    let mut e = texflow::ParticleEngine::new(&ctx, s, 4).unwrap();
    while e.sim().time() < 4.3 {
        e.advance_frame().unwrap();
    }
    let img = e.render().unwrap();
    let (w, h) = img.dimensions();
    let vp = e.camera().view_projection(w as f32 / h as f32);
    let pos = e.sim().read_positions().unwrap();
    let st = e.sim().statics().read_f32().unwrap();
    let mut out = Vec::new();
    for (p, s) in pos.chunks_exact(4).zip(st.chunks_exact(4)) {
        if p[3] <= 0.0 || p[3].is_nan() {
            continue;
        }
        let c = vp * Vec3::new(p[0], p[1], p[2]).extend(1.0);
        let ndc = c.truncate() / c.w;
        let px = (
            (ndc.x * 0.5 + 0.5) * w as f32,
            (0.5 - ndc.y * 0.5) * h as f32,
        );
        out.push(((px.0 as u32, px.1 as u32), s[0]));
    }
    common::no_gl_error(&ctx);
    (img, out)
}

/// `tint` with keys (smooth), a sine on red and a noise on green and blue.
const TINT: &str = "tint = { keys = [[0.0, [0.2, 0.4, 0.4, 1.0]], [4.0, [0.7, 0.4, 0.4, 1.0]]], \
                    interpolation = \"smooth\", periodic = { amplitude = [0.15, 0.0, 0.0, 0.0], \
                    period = 1.3, phase = 0.1 }, noise = { amplitude = [0.0, 0.3, 0.3, 0.0], \
                    frequency = 3.0, seed = 5 } }";

/// [`TINT`] on an allocator emitter: each point's pixel is the curve at its birth time (white
/// keyframes, additive on black, alpha 1), to 8 bits.
#[test]
fn points_keep_the_tint_of_their_birth_time() {
    check_tint(&row_scene(TINT, "point_size = 5.0"));
}

/// [`TINT`] on a timestamp emitter (128 texels over a cycle of 20 s, each born once in the
/// 4.3 s, at its phase, the statics' x): the same.
#[test]
fn timestamp_points_keep_the_tint_of_their_birth_time() {
    check_tint(&row_of(
        "timestamp]]\ncycle = 20.0",
        TINT,
        "point_size = 5.0",
    ));
}

/// Every live point's pixel against the tint curve at its birth time (but points another
/// covers: random time stamps may fall close together).
fn check_tint(s: &SceneFile) {
    let curve = &s.emitters.all().next().unwrap().tint;
    assert!(matches!(curve, Animated::Curve(_)));
    let (img, particles) = run_row(s);
    let alone: Vec<Born> = (particles.iter())
        .filter(|(at, _)| {
            let near = |(b, _): &&Born| at.0.abs_diff(b.0) < 6 && at.1.abs_diff(b.1) < 6;
            particles.iter().filter(near).count() == 1
        })
        .copied()
        .collect();
    assert!(
        alone.len() >= 8,
        "{} apart of {}",
        alone.len(),
        particles.len()
    );
    let mut reds = Vec::new();
    for ((x, y), birth) in alone {
        let want = curve
            .at(birth)
            .map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
        let what = format!("particle born at {birth} s, tint {:?}", curve.at(birth));
        common::image::probe(&img, x, y, &want[..3], 2, &what);
        reds.push(want[0]);
    }
    // The curve moved: the test compares values that differ.
    let (lo, hi) = (reds.iter().min().unwrap(), reds.iter().max().unwrap());
    assert!(hi - lo > 60, "{reds:?}");
}

/// `sprite_scale` ramping 1 → 2.5 over the first 3 s: each sprite's lit area, against the first
/// one's, is the square of the ratio of the curve at their birth times (within 15% in size).
#[test]
fn sprites_keep_the_scale_of_their_birth_time() {
    let scale = "sprite_scale = { keys = [[0.0, 1.0], [3.0, 2.5]] }\ntile = 0";
    let s = row_scene(scale, "mode = \"sprites\"\npoint_size = 12.0");
    let curve = &s.emitters.allocator[0].sprite_scale;
    let (img, mut particles) = run_row(&s);
    particles.sort_by(|a, b| a.1.total_cmp(&b.1));
    // Lit pixels within 20 px of the centre (the next sprite is about 45 px away).
    let area = |(x, y): (u32, u32)| -> f32 {
        let mut n = 0;
        for (px, py, p) in img.enumerate_pixels() {
            if px.abs_diff(x) <= 20 && py.abs_diff(y) <= 20 && p.0.iter().any(|&c| c > 8) {
                n += 1;
            }
        }
        n as f32
    };
    let (first, born0) = particles[0];
    let a0 = area(first);
    assert!(a0 > 20.0, "{a0}");
    for &(at, birth) in &particles[1..] {
        let want = curve.at(birth) / curve.at(born0);
        let got = (area(at) / a0).sqrt();
        assert!(
            (got / want - 1.0).abs() < 0.15,
            "born at {birth} s: size ratio {got}, the curve's {want}"
        );
    }
    let last = particles.last().unwrap().1;
    assert!(
        curve.at(last) / curve.at(born0) > 2.0,
        "the ramp was covered"
    );
}

/// A sprite of the (six-fold) snowflake tile at the frame's centre: `render.rotation =
/// "angle + 90.0"` (degrees) draws the picture without it turned by a quarter turn about the
/// centre, which differs from the unturned one.
#[test]
fn render_rotation_turns_sprites_by_its_degrees() {
    let ctx = context();
    let src = "name = \"turn\"\n[particles]\nsize = [4, 4]\n\
               [[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
               speed = [0.0, 0.0]\ntile = 1\n\
               [render]\nresolution = [64, 64]\nmode = \"sprites\"\npoint_size = 32.0\n\
               keyframes = [{ age = 0.0, rgba = [1.0, 1.0, 1.0, 1.0] }]\n\
               rotation = \"angle + 90.0\"\n\
               [render.camera]\ndistance = 5.0\nelevation = 0.0\n";
    let draw = |src: &str| {
        let s = scene::parse("turn.toml", src).unwrap();
        let mut e = texflow::ParticleEngine::new(&ctx, &s, 4).unwrap();
        common::set_particles(e.sim_mut(), &[([0.0; 3], [0.0; 3])], |_, _| 0.3);
        e.render().unwrap()
    };
    let turned = draw(src);
    let plain = draw(&src.replace("rotation = \"angle + 90.0\"\n", ""));
    // Pixel (i, j) turned a quarter about the centre (a pixel corner): (63 - j, i).
    let diff = |a: &image::RgbImage, b: &image::RgbImage| -> u8 {
        let mut worst = 0;
        for (i, j, p) in a.enumerate_pixels() {
            let q = b.get_pixel(63 - j, i);
            for c in 0..3 {
                worst = worst.max(p.0[c].abs_diff(q.0[c]));
            }
        }
        worst
    };
    // Either sense of the quarter turn: the tile is symmetric under a half turn.
    assert!(diff(&plain, &turned) <= 3, "{}", diff(&plain, &turned));
    assert!(
        diff(&plain, &plain) > 40,
        "the tile is not square-symmetric"
    );
    // A name the expression cannot read: the GLSL error names the key and its place.
    let s = scene::parse(
        "turn.toml",
        &src.replace("angle + 90.0", "angle + spin_rate"),
    )
    .unwrap();
    let e = texflow::ParticleEngine::new(&ctx, &s, 4)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("render.rotation at turn.toml:14:12") && e.contains("spin_rate"),
        "{e}"
    );
    common::no_gl_error(&ctx);
}

/// The CPU engine draws one set of keyframes: it refuses a tint, naming it.
#[test]
fn cpu_engine_refuses_a_tint() {
    let ctx = context();
    let s = row_of(
        "timestamp]]\ncycle = 50.0",
        "tint = [0.5, 1.0, 1.0, 1.0]",
        "",
    );
    let e = texflow::engine::build(&ctx, &s, 1, texflow::EngineKind::Cpu).err();
    let e = e.expect("refused").to_string();
    assert!(e.contains("tint"), "{e}");
    common::no_gl_error(&ctx);
}

/// Bad curves and expressions are refused at their line and column.
#[test]
fn bad_type_curves_are_refused_at_their_line_and_column() {
    // The key under test is on line 9.
    let emitter = |kind: &str, keys: &str| {
        let own = match kind {
            "allocator" => "rate = 10.0",
            "timestamp" => "cycle = 1.0",
            _ => "# all at once",
        };
        format!(
            "name = \"bad\"\n[particles]\nsize = [8, 8]\n[[emitters.{kind}]]\n{own}\n\
             direction = [0.0, 1.0, 0.0]\nspeed = 1.0\nlife = [1.0, 1.0]\n{keys}\n\
             [render]\nmode = \"sprites\"\n"
        )
    };
    let five = "tint = { keys = [[0.0, [1.0, 1.0, 1.0, 1.0]], [1.0, [1.0, 1.0, 1.0, 1.0]], \
                [2.0, [1.0, 1.0, 1.0, 1.0]], [3.0, [1.0, 1.0, 1.0, 1.0]], \
                [4.0, [1.0, 1.0, 1.0, 1.0]]] }";
    let cases = [
        (emitter("allocator", five), ":9:", "at most 4 keys"),
        (
            emitter(
                "allocator",
                "sprite_scale = { keys = [[0.0, 0.5]], noise = { amplitude = 0.6, frequency = 2.0 } }",
            ),
            ":9:",
            "sprite_scale must be a finite number above 0",
        ),
        (
            emitter("allocator", "tint = [1.0, -0.5, 1.0, 1.0]"),
            ":9:",
            "its green reaches -0.5",
        ),
        (
            emitter("allocator", "tint = [1.0, 1.0, 1.0]"),
            ":9:",
            "[r, g, b, a]",
        ),
        (
            emitter("timestamp", "tint = { keys = [[0.0, [1.0, 1.0, 1.0]]] }"),
            ":9:",
            "[r, g, b, a]",
        ),
        (
            emitter("initial", "sprite_scale = { keys = [[0.0, 1.0], [1.0, 2.0]] }"),
            ":9:",
            "all born at time 0",
        ),
        (
            emitter("allocator", "tint = [1.0, 0.5, 0.5, 1.0]").replace("sprites", "surface"),
            ":9:",
            "draws the connected surface",
        ),
        (
            emitter("allocator", "").replace("mode = \"sprites\"", "rotation = \"angle\""),
            ":11:",
            "turns the sprites' atlas tiles",
        ),
    ];
    for (src, at, what) in cases {
        let e = match scene::parse("bad.toml", &src) {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted:\n{src}"),
        };
        assert!(
            e.contains(&format!("bad.toml{at}")) && e.contains(what),
            "{e}\n{src}"
        );
    }
}
