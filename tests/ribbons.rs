//! `render.trails = "ribbon"`: quads between consecutive trail children of one parent. On a
//! tiny hand-made trail (a ring of 5 texels after one parent texel, children 0.1 s apart on a
//! line across the view): ribbons cover the pixels between the points, a segment with a dead end
//! or one whose ends were born too far apart is not drawn; scenes refuse ribbons they cannot
//! draw at the key's line and column; without the key frames are the same bytes.

mod common;

use common::cli::{pngs, s, texflow};
use common::image::{front_camera, lit_pixels, texture};
use common::scene::scene_error;
use common::{context, no_gl_error};

use texflow::gl::TextureFormat;
use texflow::render::{FrameState, FrameTarget, ParticleRenderer, ParticleStyle, RibbonRenderer};
use texflow::scene::{self, Blending, ChildLayout, ChildRange, Keyframe, Render};

const SIZE: u32 = 64;
const RATE: f32 = 10.0;
/// Trail texels 1..=5 hold the children at these x (metres), each 1 / RATE s younger than the
/// one before; texel 0 is the (dead) parent.
const XS: [f32; 5] = [-0.6, -0.2, 0.2, 0.6, 0.9];

fn layout() -> ChildLayout {
    ChildLayout {
        parent_slots: 1,
        ranges: vec![ChildRange {
            start: 1,
            per_parent: 5,
            parent: 0,
            kind: 1,
            on_death: 0,
            trail_rate: RATE,
        }],
    }
}

fn style() -> ParticleStyle {
    let render = Render {
        point_size: 3.0,
        blending: Blending::Additive,
        keyframes: vec![Keyframe {
            age: 0.0,
            rgba: [1.0; 4],
        }],
        ..Render::default()
    };
    ParticleStyle::from_render(&render, [1.0; 4])
}

/// The frame of the trail with `ages` (seconds since birth, per trail texel; None: dead),
/// points only or with ribbons.
fn frame(ages: [Option<f32>; 5], ribbons: bool) -> image::RgbImage {
    let ctx = context();
    let (mut pos, mut stat) = (vec![0.0f32; 8 * 4], vec![0.0f32; 8 * 4]);
    for (k, (x, age)) in XS.iter().zip(ages).enumerate() {
        let t = 4 * (k + 1);
        let life = 1.0;
        pos[t..t + 4].copy_from_slice(&[*x, 0.0, 0.0, age.map_or(0.0, |a| life - a)]);
        stat[t..t + 4].copy_from_slice(&[0.0, 1.0, life, 0.5]);
    }
    let positions = texture(&ctx, "positions", (8, 1), TextureFormat::Rgba32F, &pos);
    let statics = texture(&ctx, "statics", (8, 1), TextureFormat::Rgba32F, &stat);
    let mut r = ParticleRenderer::new(&ctx, style(), 8, 1).unwrap();
    if ribbons {
        r.set_ribbons(RibbonRenderer::new(&ctx, &layout(), &style(), 0.01, None).unwrap());
    }
    let target = FrameTarget::new(&ctx, SIZE, SIZE).unwrap();
    r.clear(&target);
    let state = FrameState {
        positions: &positions,
        statics: &statics,
        motion: None,
        time: 1.0,
        spins: None,
        count: 8,
        user: &[],
    };
    r.draw_frame(&target, &state, &front_camera(2.0)).unwrap();
    no_gl_error(&ctx);
    target.read_rgb().unwrap()
}

/// Whether the pixel halfway between trail texels `i` and `i + 1` (on the x axis) is lit.
fn lit_between(img: &image::RgbImage, i: usize) -> bool {
    let x = 0.5 * (XS[i] + XS[i + 1]);
    let vp = front_camera(2.0).view_projection(1.0);
    let ndc = vp.project_point3(glam::Vec3::new(x, 0.0, 0.0));
    let px = ((ndc.x * 0.5 + 0.5) * SIZE as f32) as u32;
    let py = ((0.5 - ndc.y * 0.5) * SIZE as f32) as u32;
    // Either row next to the axis (the ribbon is 3 px wide about it).
    (py.saturating_sub(1)..=py).any(|y| img.get_pixel(px, y).0 != [0, 0, 0])
}

const TRAIL: [Option<f32>; 5] = [Some(0.4), Some(0.3), Some(0.2), Some(0.1), Some(0.0)];

#[test]
fn ribbons_cover_the_gaps_between_the_points() {
    let points = frame(TRAIL, false);
    let ribbon = frame(TRAIL, true);
    assert!(
        lit_pixels(&ribbon, [0; 3]) > 2 * lit_pixels(&points, [0; 3]),
        "ribbons {} px, points {} px",
        lit_pixels(&ribbon, [0; 3]),
        lit_pixels(&points, [0; 3])
    );
    for i in 0..4 {
        assert!(!lit_between(&points, i), "points: gap {i} is dark");
        assert!(lit_between(&ribbon, i), "ribbons: gap {i} is covered");
    }
}

#[test]
fn a_segment_to_a_dead_child_or_across_a_birth_gap_is_not_drawn() {
    // Texel 2 dead: its two segments go; texel 5 born 0.5 s after texel 4 (more than one
    // trail interval plus a step): that segment goes too; 3 -> 4 stays.
    let img = frame([Some(0.9), None, Some(0.7), Some(0.6), Some(0.1)], true);
    assert!(!lit_between(&img, 0), "live 1 to dead 2");
    assert!(!lit_between(&img, 1), "dead 2 to live 3");
    assert!(lit_between(&img, 2), "live 3 to live 4, 0.1 s apart");
    assert!(!lit_between(&img, 3), "4 to 5, born 0.5 s apart");
}

const BASE: &str = r#"name = "t"
[particles]
size = [16, 16]
[[emitters.timestamp]]
cycle = 2.0
direction = [0.0, 1.0, 0.0]
speed = [1.0, 1.0]
life = [1.0, 1.0]
[[emitters.child]]
parent = 0
per_parent = 4
trail_rate = 10.0
direction = [0.0, 1.0, 0.0]
speed = [1.0, 1.0]
life = [0.2, 0.2]
"#;

#[test]
fn scenes_refuse_ribbons_they_cannot_draw() {
    let no_children = BASE.split("[[emitters.child]]").next().unwrap();
    let bursts = BASE.replace("trail_rate = 10.0", "on_death = 4");
    let cases = [
        (no_children.to_owned(), "", "trail_rate above 0"),
        (bursts, "", "trail_rate above 0"),
        (
            BASE.to_owned(),
            "path = \"vertex_buffer\"\n",
            "texture_fetch",
        ),
        // Alpha blending re-orders (gathers) the state the ribbons would read by ring index,
        // and draws in depth order: one unsorted batch fits neither, lit or not.
        (BASE.to_owned(), "blending = \"alpha\"\n", "unsorted batch"),
        (
            BASE.to_owned(),
            "blending = \"alpha\"\nlookup = \"index\"\n",
            "unsorted batch",
        ),
    ];
    for (head, extra, want) in cases {
        let src = format!("{head}[render]\n{extra}trails = \"ribbon\"\n");
        let line = src.lines().count();
        let (l, c, m) = scene_error(scene::parse("t.toml", &src));
        // At the key's value: `trails = "ribbon"` is the last line.
        assert_eq!((l, c), (line, 10), "{m}\n{src}");
        assert!(m.contains("trails") && m.contains(want), "{m}");
    }
    // A surface is refused (without a [constraints] layout already by mode itself).
    let src = format!("{BASE}[render]\nmode = \"surface\"\ntrails = \"ribbon\"\n");
    assert!(scene::parse("t.toml", &src).is_err());
    let src = format!("{BASE}[render]\nribbon_width = 0.1\n");
    let (l, _, m) = scene_error(scene::parse("t.toml", &src));
    assert_eq!(l, src.lines().count());
    assert!(m.contains("trails"), "{m}");
    let src = format!("{BASE}[render]\ntrails = \"ribbon\"\nribbon_width = -1.0\n");
    let (_, _, m) = scene_error(scene::parse("t.toml", &src));
    assert!(m.contains("above 0"), "{m}");
    assert!(scene::parse("t.toml", &format!("{BASE}[render]\ntrails = \"ribbon\"\n")).is_ok());
}

/// Without the key (or with `none`) nothing new runs: the same bytes; with it, other bytes.
#[test]
fn without_trails_frames_are_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/fireworks.toml"
    );
    let fireworks = std::fs::read_to_string(path).unwrap();
    let mut frames = Vec::new();
    for (name, trails) in [("absent", ""), ("none", "none"), ("ribbon", "ribbon")] {
        let src = if trails.is_empty() {
            fireworks.clone()
        } else {
            fireworks.replace("[render]\n", &format!("[render]\ntrails = \"{trails}\"\n"))
        };
        let file = dir.path().join(format!("{name}.toml"));
        std::fs::write(&file, src).unwrap();
        let out = dir.path().join(name);
        let o = texflow(&[
            "render",
            s(&file),
            "--frames",
            "18",
            "--every",
            "17",
            "--resolution",
            "64x64",
            "--out",
            s(&out),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let last = pngs(&out).pop().expect("a frame");
        frames.push(std::fs::read(out.join(last)).unwrap());
    }
    assert!(frames[0] == frames[1], "trails = \"none\" is the default");
    assert!(frames[0] != frames[2], "ribbons draw something");
}
