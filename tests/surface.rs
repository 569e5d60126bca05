//! `render.mode = "surface"`: a constraint layout drawn as connected geometry by vertex texture
//! fetch over an index buffer. Image properties computed here: the built-in cloth's surface
//! covers one connected region and far more pixels than its points; a flat sheet is lit by
//! Lambert's law from the known light (facing it: the full colour, edge-on: the ambient share;
//! either winding alike, the normal flipped towards the eye); the built-in hair's strands join
//! every root to its tip, which its points do not; scenes without constraints and the CPU
//! engine refuse the mode.

mod common;

use glam::Vec3;
use texflow::engine::{self, Engine, EngineKind};
use texflow::render::{Camera, SURFACE_AMBIENT, SURFACE_LIGHT};
use texflow::scene::{self, DrawMode, SceneFile};

const RES: u32 = 256;

/// The built-in `name` at `RES`² without its colliders drawn (only the layout is lit), points of
/// 1 pixel, in `mode`.
fn builtin(name: &str, mode: DrawMode) -> SceneFile {
    let mut s = scene::load(name).unwrap();
    s.render.mode = mode;
    s.render.geometry = false;
    s.render.point_size = 1.0;
    s.render.resolution = [RES, RES];
    s
}

/// The frame's pixels that differ from the background.
fn lit(img: &image::RgbImage, s: &SceneFile) -> Vec<bool> {
    let bg = s.render.background.map(|c| (c * 255.0).round() as i32);
    img.pixels()
        .map(|p| (0..3).any(|k| (p.0[k] as i32 - bg[k]).abs() > 1))
        .collect()
}

/// Labels the 8-connected components of `mask` (`RES` wide): component id per pixel (0: unlit)
/// and the number of components.
fn components(mask: &[bool]) -> (Vec<u32>, u32) {
    let (w, h) = (RES as i32, (mask.len() / RES as usize) as i32);
    let mut label = vec![0u32; mask.len()];
    let mut n = 0;
    for start in 0..mask.len() {
        if !mask[start] || label[start] != 0 {
            continue;
        }
        n += 1;
        label[start] = n;
        let mut stack = vec![start];
        while let Some(k) = stack.pop() {
            let (x, y) = ((k % RES as usize) as i32, (k / RES as usize) as i32);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (qx, qy) = (x + dx, y + dy);
                    if qx < 0 || qy < 0 || qx >= w || qy >= h {
                        continue;
                    }
                    let q = (qy * w + qx) as usize;
                    if mask[q] && label[q] == 0 {
                        label[q] = n;
                        stack.push(q);
                    }
                }
            }
        }
    }
    (label, n)
}

/// Two engines of `name`, surface and points, advanced together; at each of `frames` (frame
/// numbers, ascending) `check` gets both frames and the surface engine.
fn both(
    name: &str,
    frames: &[u32],
    mut check: impl FnMut(u32, &SceneFile, &[bool], &[bool], &dyn Engine),
) {
    let ctx = common::context();
    let (ss, sp) = (
        builtin(name, DrawMode::Surface),
        builtin(name, DrawMode::Points),
    );
    let mut es = engine::build(&ctx, &ss, 1, EngineKind::Gpu).unwrap();
    let mut ep = engine::build(&ctx, &sp, 1, EngineKind::Gpu).unwrap();
    let mut at = 0;
    for &f in frames {
        while at < f {
            es.advance_frame().unwrap();
            ep.advance_frame().unwrap();
            at += 1;
        }
        let surface = lit(&es.render().unwrap(), &ss);
        let points = lit(&ep.render().unwrap(), &sp);
        let count = |m: &[bool]| m.iter().filter(|b| **b).count();
        eprintln!(
            "{name} frame {f}: surface {} pixels in {} regions, points {} in {}",
            count(&surface),
            components(&surface).1,
            count(&points),
            components(&points).1
        );
        check(f, &ss, &surface, &points, es.as_ref());
    }
    common::no_gl_error(&ctx);
}

#[test]
fn the_cloth_surface_is_one_region_covering_far_more_than_its_points() {
    both("cloth", &[0, 40, 100], |f, _, surface, points, _| {
        let (s, p) = (
            surface.iter().filter(|b| **b).count(),
            points.iter().filter(|b| **b).count(),
        );
        // 1024 points of one pixel cover at most 1024 pixels; the sheet between them fills in.
        assert!(p <= 1024, "frame {f}: {p} point pixels");
        assert!(s > 3 * p, "frame {f}: surface {s} pixels, points {p}");
        let (_, n) = components(surface);
        assert_eq!(n, 1, "frame {f}: the surface's lit pixels form {n} regions");
        // The points (spaced wider than a pixel) do not join up.
        let (_, np) = components(points);
        assert!(np > 200, "frame {f}: the points form only {np} regions");
    });
}

/// A flat 8×8 sheet with unit normal `n` (winding flipped if `flip`) through the origin, seen
/// from +z, drawn in grey 0.8 on black: the mean red of its lit pixels, in [0, 1].
fn sheet_brightness(ctx: &texflow::gl::Context, n: Vec3, flip: bool) -> f32 {
    let (mut u, mut v) = n.any_orthonormal_pair();
    if flip {
        std::mem::swap(&mut u, &mut v);
    }
    let origin = -(u + v) * 0.35;
    let src = format!(
        "name = \"sheet\"\nintegrator = \"verlet\"\n[particles]\nsize = [8, 8]\n\
         [time]\ndt = 0.008333334\n\
         [constraints]\nkind = \"cloth\"\nspacing = 0.1\norigin = {:?}\nu = {:?}\nv = {:?}\n\
         pinned = [[0, 0]]\n\
         [render]\nmode = \"surface\"\nresolution = [{RES}, {RES}]\nbackground = [0.0, 0.0, 0.0]\n\
         camera = {{ target = [0.0, 0.0, 0.0], distance = 2.0, azimuth = 0.0, elevation = 0.0 }}\n\
         keyframes = [{{ age = 0.0, rgba = [0.8, 0.8, 0.8, 1.0] }}]\n",
        origin.to_array(),
        u.to_array(),
        v.to_array()
    );
    let s = common::scene::parse("sheet", &src);
    let mut e = engine::build(ctx, &s, 1, EngineKind::Gpu).unwrap();
    let img = e.render().unwrap();
    let red: Vec<f32> = img
        .pixels()
        .filter(|p| p.0 != [0, 0, 0])
        .map(|p| p.0[0] as f32 / 255.0)
        .collect();
    assert!(red.len() > 500, "{n}: only {} pixels lit", red.len());
    red.iter().sum::<f32>() / red.len() as f32
}

#[test]
fn a_sheet_facing_the_light_is_lit_fully_and_one_edge_on_by_the_ambient_share() {
    let ctx = common::context();
    let l = Vec3::from(SURFACE_LIGHT).normalize();
    // Facing the light, and turned from the eye (+z) until the light grazes it.
    let edge_on = (Vec3::Z - l * Vec3::Z.dot(l)).normalize();
    // Lambert: colour · (ambient + (1 − ambient) · max(n·l, 0)).
    let expect = |n: Vec3| 0.8 * (SURFACE_AMBIENT + (1.0 - SURFACE_AMBIENT) * n.dot(l).max(0.0));
    for flip in [false, true] {
        let facing = sheet_brightness(&ctx, l, flip);
        let grazing = sheet_brightness(&ctx, edge_on, flip);
        assert!(
            (facing - expect(l)).abs() < 0.01,
            "facing (flip {flip}): {facing}, expected {}",
            expect(l)
        );
        assert!(
            (grazing - expect(edge_on)).abs() < 0.01,
            "edge-on (flip {flip}): {grazing}, expected {}",
            expect(edge_on)
        );
        assert!(facing > 3.0 * grazing, "{facing} against {grazing}");
    }
    common::no_gl_error(&ctx);
}

/// The components of the lit pixels within one pixel of `p`.
fn near(label: &[u32], p: (u32, u32)) -> Vec<u32> {
    let mut out = Vec::new();
    for dy in -1..=1i32 {
        for dx in -1..=1i32 {
            let (x, y) = (p.0 as i32 + dx, p.1 as i32 + dy);
            if x < 0 || y < 0 || x >= RES as i32 || y >= RES as i32 {
                continue;
            }
            let c = label[(y as u32 * RES + x as u32) as usize];
            if c != 0 {
                out.push(c);
            }
        }
    }
    out
}

/// Of the strands whose root and tip are both in the frame: how many, and how many of them have
/// their root and tip pixels in one component of `mask`.
fn joined_strands(
    mask: &[bool],
    positions: &[[f32; 4]],
    camera: &Camera,
    w: usize,
) -> (usize, usize) {
    let (label, _) = components(mask);
    let pixel = |k: usize| {
        let p = positions[k];
        camera.project_to_pixel(Vec3::new(p[0], p[1], p[2]), RES, RES)
    };
    let seen: Vec<_> = (0..positions.len() / w)
        .filter_map(|j| Some((pixel(j * w)?, pixel(j * w + w - 1)?)))
        .collect();
    let joined = seen
        .iter()
        .filter(|(root, tip)| {
            let (root, tip) = (near(&label, *root), near(&label, *tip));
            root.iter().any(|c| tip.contains(c))
        })
        .count();
    (seen.len(), joined)
}

#[test]
fn hair_strands_join_every_root_to_its_tip_and_points_do_not() {
    both("hair", &[0, 60], |f, s, lines, points, e| {
        let (nl, np) = (
            lines.iter().filter(|b| **b).count(),
            points.iter().filter(|b| **b).count(),
        );
        assert!(nl > 2 * np, "frame {f}: lines {nl} pixels, points {np}");
        let positions = e.dump().unwrap().positions;
        let w = s.particles.size[0] as usize;
        let strands = s.particles.size[1] as usize;
        assert_eq!(positions.len(), w * strands);
        let camera = Camera::from(&s.render.camera);
        let (seen, joined) = joined_strands(lines, &positions, &camera, w);
        assert!(
            seen >= strands / 2,
            "frame {f}: {seen} strands in the frame"
        );
        assert_eq!(joined, seen, "frame {f}: strands joined root to tip");
        let (_, by_points) = joined_strands(points, &positions, &camera, w);
        assert!(
            by_points < seen / 2,
            "frame {f}: {by_points} of {seen} strands joined by points alone"
        );
    });
}

#[test]
fn surface_needs_constraints_and_the_gpu_engine() {
    // The fountain (emitters, no [constraints]) with the key added first in its [render].
    let (label, src) = scene::load_source("fountain").unwrap();
    let src: String = src
        .lines()
        .filter(|l| !l.starts_with("mode = "))
        .map(|l| format!("{l}\n"))
        .collect();
    let src = src.replacen("[render]\n", "[render]\nmode = \"surface\"\n", 1);
    let want = src.lines().position(|l| l == "mode = \"surface\"").unwrap() + 1;
    let (line, column, message) = common::scene::scene_error(scene::parse(&label, &src));
    assert_eq!((line, column), (want, 8), "{message}");
    assert!(
        message.contains("[constraints]") && message.contains("mode = \"points\""),
        "{message}"
    );
    // A key the opaque surface would ignore is refused at its place.
    let (label, src) = scene::load_source("cloth").unwrap();
    let src = src.replacen("[render]\n", "[render]\nblending = \"alpha\"\n", 1);
    let want = src
        .lines()
        .position(|l| l == "blending = \"alpha\"")
        .unwrap()
        + 1;
    let (line, column, message) = common::scene::scene_error(scene::parse(&label, &src));
    assert_eq!((line, column), (want, 12), "{message}");
    assert!(message.contains("mode = \"points\""), "{message}");
    let ctx = common::context();
    let cloth = scene::load("cloth").unwrap();
    assert_eq!(cloth.render.mode, DrawMode::Surface);
    let Err(err) = engine::build(&ctx, &cloth, 1, EngineKind::Cpu) else {
        panic!("the CPU engine built a surface scene");
    };
    // Refused by name (its Verlet step first; the surface is refused after it as well).
    assert!(err.to_string().contains("does not cover"), "{err}");
}
