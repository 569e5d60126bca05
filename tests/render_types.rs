//! Latta §3.4.5-3.4.6 and the thesis §2.3 beyond points, quads and sprites: one triangle per
//! particle, a random size within each type's range, flipbooks of atlas tiles; and a `[fire]`
//! scene that honours every render key it accepts or refuses it with its place.

mod common;

use common::image::{front_camera, lit_pixels, probe, texture};
use common::{context, no_gl_error};
use glam::Vec3;
use texflow::gl::{Context, Texture, TextureFormat};
use texflow::render::{flipbook_tile, random_size, FrameTarget, ParticleRenderer, ParticleStyle};
use texflow::scene::{self, DrawMode, DrawPrimitive, Keyframe};

const S: u32 = 8;
const FW: u32 = 96;
const FH: u32 = 96;

/// One live particle: position, remaining and total life, type, random number.
#[derive(Clone, Copy)]
struct P {
    at: Vec3,
    remaining: f32,
    total: f32,
    ty: u32,
    rand: f32,
}

fn p(at: Vec3, rand: f32) -> P {
    P {
        at,
        remaining: 1.0,
        total: 2.0,
        ty: 0,
        rand,
    }
}

fn upload(ctx: &Context, live: &[P]) -> (Texture, Texture) {
    let n = (S * S) as usize;
    let mut pos = vec![[f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0]; n];
    let mut stat = vec![[0.0, 0.0, 1.0, 0.0]; n];
    for (i, q) in live.iter().enumerate() {
        pos[i] = [q.at.x, q.at.y, q.at.z, q.remaining];
        stat[i] = [0.0, q.ty as f32, q.total, q.rand];
    }
    let make = |label, data: &[[f32; 4]]| {
        texture(
            ctx,
            label,
            (S, S),
            TextureFormat::Rgba32F,
            data.as_flattened(),
        )
    };
    (make("position", &pos), make("statics", &stat))
}

/// Opaque white at every age, additive on black.
fn white(mode: DrawMode, primitive: DrawPrimitive, size: f32) -> ParticleStyle {
    ParticleStyle {
        mode,
        primitive,
        point_size: size,
        keyframes: (0..4)
            .map(|k| Keyframe {
                age: [0.0, 0.3, 0.6, 1.0][k],
                rgba: [1.0; 4],
            })
            .collect(),
        ..ParticleStyle::default()
    }
}

fn render(ctx: &Context, style: &ParticleStyle, live: &[P]) -> image::RgbImage {
    let target = FrameTarget::new(ctx, FW, FH).unwrap();
    let r = ParticleRenderer::new(ctx, style.clone(), S, S).unwrap();
    let (pos, stat) = upload(ctx, live);
    r.clear(&target);
    r.draw(&target, &pos, &stat, &front_camera(4.0), live.len())
        .unwrap();
    target.read_rgb().unwrap()
}

/// Lit pixels within `half` pixels of where `at` projects.
fn lit_around(img: &image::RgbImage, at: Vec3, half: i64) -> usize {
    let (cx, cy) = front_camera(4.0).project_to_pixel(at, FW, FH).unwrap();
    let (cx, cy) = (cx as i64, cy as i64);
    img.enumerate_pixels()
        .filter(|(x, y, px)| {
            (*x as i64 - cx).abs() <= half && (*y as i64 - cy).abs() <= half && px.0 != [0, 0, 0]
        })
        .count()
}

/// Latta §3.4.6: "point sprites, triangles or quads". The triangle is the equilateral one
/// around the sprite's inscribed circle: untextured it covers 3·√3/4 ≈ 1.30 of the quad's
/// pixels; textured, the same circle as the quad.
#[test]
fn a_triangle_covers_the_sprites_circle_with_1_3_times_a_quads_pixels() {
    let ctx = context();
    let one = [p(Vec3::ZERO, 0.0)];
    let size = 41.0;
    let quad = lit_pixels(
        &render(
            &ctx,
            &white(DrawMode::Points, DrawPrimitive::Quads, size),
            &one,
        ),
        [0; 3],
    );
    let tri = lit_pixels(
        &render(
            &ctx,
            &white(DrawMode::Points, DrawPrimitive::Triangles, size),
            &one,
        ),
        [0; 3],
    );
    let ratio = tri as f64 / quad as f64;
    let want = 3.0 * 3f64.sqrt() / 4.0;
    assert!(
        (ratio - want).abs() < 0.05,
        "triangle/quad pixels {ratio}, want {want}"
    );
    assert!(
        (quad as f64 - size as f64 * size as f64).abs() < 3.0 * size as f64,
        "{quad}"
    );
    // Sprites: the blob tile lies in the inscribed circle, which both primitives cover.
    let quad = render(
        &ctx,
        &white(DrawMode::Sprites, DrawPrimitive::Quads, size),
        &one,
    );
    let tri = render(
        &ctx,
        &white(DrawMode::Sprites, DrawPrimitive::Triangles, size),
        &one,
    );
    let (q, t) = (
        lit_pixels(&quad, [0; 3]) as f64,
        lit_pixels(&tri, [0; 3]) as f64,
    );
    assert!(
        (t / q - 1.0).abs() < 0.05,
        "sprite pixels: triangle {t}, quad {q}"
    );
    no_gl_error(&ctx);
}

/// Latta §3.4.6: "The size of a particle is random within a range that is defined by the
/// particle type": each quad's side is point_size times the CPU twin's factor.
#[test]
fn sizes_are_random_within_the_types_range() {
    let ctx = context();
    let mut style = white(DrawMode::Points, DrawPrimitive::Quads, 12.0);
    style.types[0].size_range = [0.5, 2.0];
    let places = [-1.0f32, 0.0, 1.0].map(|x| Vec3::new(x, 0.0, 0.0));
    let rands = [0.11f32, 0.52, 0.87];
    let live: Vec<P> = places.iter().zip(rands).map(|(&a, r)| p(a, r)).collect();
    let img = render(&ctx, &style, &live);
    let mut sides = Vec::new();
    for (q, r) in live.iter().zip(rands) {
        let want = 12.0 * random_size([0.5, 2.0], r);
        let side = (lit_around(&img, q.at, 15) as f32).sqrt();
        assert!(
            (side - want).abs() < 1.5,
            "random {r}: side {side}, want {want}"
        );
        sides.push(side);
    }
    assert!(
        sides.iter().any(|s| (s - sides[0]).abs() > 2.0),
        "{sides:?}"
    );
    // [1, 1] is no range: the frame is the plain one to the byte.
    let mut one = style.clone();
    one.types[0].size_range = [1.0; 2];
    let plain = white(DrawMode::Points, DrawPrimitive::Quads, 12.0);
    assert_eq!(render(&ctx, &one, &live), render(&ctx, &plain, &live));
    no_gl_error(&ctx);
}

/// The thesis §2.3 (animated textures): a flipbook particle shows, at each age, exactly the
/// frame a particle with the tile of the CPU twin shows.
#[test]
fn flipbooks_show_the_tile_of_the_particles_age() {
    let ctx = context();
    let base = white(DrawMode::Sprites, DrawPrimitive::Points, 31.0);
    // (frames, rate): over the life, and 4 tiles a second, looping over 2.
    for (frames, rate) in [(4u32, 0.0f32), (2, 4.0)] {
        let mut flip = base.clone();
        flip.types[0].tile = 1;
        flip.types[0].flipbook = (frames, rate);
        let mut seen = Vec::new();
        for remaining in [1.9f32, 1.3, 0.7, 0.1] {
            let q = P {
                remaining,
                ..p(Vec3::ZERO, 0.0)
            };
            let age_s = 2.0 - remaining;
            let tile = flipbook_tile(1, frames, rate, age_s / 2.0, age_s);
            let mut fixed = base.clone();
            fixed.types[0].tile = tile;
            let got = render(&ctx, &flip, &[q]);
            assert_eq!(
                got,
                render(&ctx, &fixed, &[q]),
                "frames {frames}, rate {rate}, age {age_s}: not tile {tile}"
            );
            seen.push(tile);
        }
        let distinct = seen.iter().collect::<std::collections::BTreeSet<_>>().len();
        assert_eq!(distinct, frames as usize, "{seen:?}");
    }
    assert_eq!(
        flipbook_tile(1, 4, 0.0, 0.9, 1.8),
        0,
        "wraps after the fourth tile"
    );
    no_gl_error(&ctx);
}

/// The built-in fire with `line` in `[render]` (replacing the key's own line if it has one).
fn fire_with(line: &str) -> String {
    let key = format!("{} ", line.split('=').next().unwrap().trim());
    let src: Vec<&str> = scene::builtin_source("fire")
        .unwrap()
        .lines()
        .filter(|l| !l.starts_with(&key))
        .collect();
    (src.join("\n") + "\n").replacen("[render]\n", &format!("[render]\n{line}\n"), 1)
}

/// What `[render]` says of a `[fire]` scene is honoured or refused at its line.
#[test]
fn a_fire_scene_refuses_the_render_keys_it_would_ignore() {
    for line in [
        "blending = \"alpha\"",
        "primitive = \"stretched\"",
        "path = \"vertex_buffer\"",
        "geometry = true",
    ] {
        let src = fire_with(line);
        let at = src.lines().position(|l| l == line).unwrap() + 1;
        let err = scene::parse("fire.toml", &src).unwrap_err();
        let text = err.to_string();
        assert!(
            text.starts_with(&format!("fire.toml:{at}:")),
            "{line}: {text}"
        );
        assert!(text.contains("[fire]"), "{text}");
        assert!(err.is_bad_input());
    }
    // The default written out is what the fire does: accepted; and its soft sprites.
    scene::parse("fire.toml", &fire_with("blending = \"additive\"")).unwrap();
    scene::parse("fire.toml", &fire_with("mode = \"sprites\"")).unwrap();
}

#[test]
fn a_fire_scene_draws_on_its_background() {
    let ctx = context();
    let src = fire_with("background = [0.2, 0.4, 0.6]");
    let mut s = scene::parse("fire.toml", &src).unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [32, 32];
    let mut e = texflow::engine::build(&ctx, &s, 1, texflow::EngineKind::Gpu).unwrap();
    e.advance_frame().unwrap();
    let img = e.render().unwrap();
    probe(&img, 0, 0, &[51, 102, 153], 0, "the background");
    no_gl_error(&ctx);
}

#[test]
fn the_new_keys_are_validated_and_listed_in_the_passes() {
    let src = scene::builtin_source("fountain").unwrap();
    let with = |extra: &str| {
        src.replacen(
            "life = [2.5, 3.5]\n",
            &format!("life = [2.5, 3.5]\n{extra}\n"),
            1,
        )
    };
    for (bad, key) in [
        ("size_range = [2.0, 1.0]", "size_range"),
        ("flipbook = { frames = 5 }", "frames"),
        ("flipbook = { frames = 2, rate = -1.0 }", "rate"),
    ] {
        let text = with(bad);
        let at = text.lines().position(|l| l == bad).unwrap() + 1;
        let err = scene::parse("f.toml", &text).unwrap_err().to_string();
        assert!(err.starts_with(&format!("f.toml:{at}:")), "{bad}: {err}");
        assert!(err.contains(key), "{err}");
    }
    let good = with("size_range = [0.5, 1.5]\nflipbook = { frames = 3, rate = 6.0 }").replacen(
        "mode = \"sprites\"",
        "mode = \"sprites\"\nprimitive = \"triangles\"",
        1,
    );
    let ctx = context();
    let plan = common::plan_of(&ctx, &scene::parse("f.toml", &good).unwrap()).to_string();
    for part in ["sprite triangles", "size_range", "flipbooks"] {
        assert!(plan.contains(part), "{part}: {plan}");
    }
}

/// The shared probe passes within its tolerance and otherwise fails naming the pixel, the
/// expected and the observed colour.
#[test]
fn the_probe_names_where_expected_and_observed() {
    let img = image::RgbImage::from_pixel(4, 3, image::Rgb([10, 20, 30]));
    probe(&img, 3, 2, &[11, 19, 30], 1, "within 1");
    let err = std::panic::catch_unwind(|| probe(&img, 1, 2, &[10, 20, 32], 1, "the corner"))
        .expect_err("2 off is outside a tolerance of 1");
    let msg = err.downcast_ref::<String>().cloned().unwrap_or_default();
    assert!(
        msg.contains("the corner: Probe at (1, 2)")
            && msg.contains("Expected: [10, 20, 32]")
            && msg.contains("Observed: [10, 20, 30]"),
        "{msg}"
    );
}
