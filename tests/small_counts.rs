//! Small `--particles` runs of every built-in scene give a visible picture: below a scene's own
//! particle count the renderer's point size grows with the square root of the ratio
//! (`SceneFile::resize_particles`), so that the particles cover about as much of the frame as at
//! the scene's count. At the scene's own count nothing changes.

mod common;

use common::{context, no_gl_error};
use texflow::engine::{build, EngineKind};
use texflow::scene;

/// Mean luma (0-255) of frame `frames` of `s`.
fn mean_luma(s: &scene::SceneFile, frames: usize) -> f64 {
    let ctx = context();
    let mut e = build(&ctx, s, 1, EngineKind::Gpu).unwrap();
    for _ in 0..frames {
        e.advance_frame().unwrap();
    }
    let img = e.render().unwrap();
    no_gl_error(&ctx);
    let sum: f64 = (img.pixels())
        .map(|p| 0.2126 * p.0[0] as f64 + 0.7152 * p.0[1] as f64 + 0.0722 * p.0[2] as f64)
        .sum();
    sum / (img.width() * img.height()) as f64
}

/// Mean luma a frame must reach (of 255): `e3` at 64×64 with its own point size gave 0.4.
const VISIBLE: f64 = 2.0;

/// Every built-in whose own count is above 64×64, run at 64×64 for 60 frames, shows a frame of
/// mean luma above [`VISIBLE`] (the others: `--particles 64` does not shrink them).
#[test]
fn every_builtin_at_64x64_particles_is_visible() {
    let mut shrunk = 0;
    for &name in scene::BUILTIN {
        let own = scene::load(name).unwrap();
        let [w, h] = own.particles.size;
        // A fluid's drawn size is its lattice spacing, and its count its lattice's: not resized.
        if w * h <= 64 * 64 || own.fluid.is_some() {
            continue;
        }
        let mut s = own.clone();
        s.resize_particles([64, 64]);
        let luma = mean_luma(&s, 60);
        eprintln!(
            "{name}: point size {} -> {}, mean luma {luma:.2}",
            own.render.point_size, s.render.point_size
        );
        assert!(
            luma > VISIBLE,
            "{name} at 64x64 particles: mean luma {luma:.2} of 255 (point size {})",
            s.render.point_size
        );
        shrunk += 1;
    }
    assert!(shrunk >= 5, "only {shrunk} built-ins shrink at 64x64");
}

/// The rule: √(own / new) below the scene's count (capped), nothing at or above it, nothing
/// where the size is physical.
#[test]
fn point_size_follows_the_count_only_below_the_scene_s() {
    let e3 = scene::load("e3").unwrap();
    let mut s = e3.clone();
    s.resize_particles(e3.particles.size);
    assert_eq!(s, e3, "at the scene's own size nothing changes");
    s.resize_particles([512, 512]);
    assert_eq!(s.render.point_size, e3.render.point_size);
    let mut s = e3.clone();
    s.resize_particles([64, 64]);
    let ratio = (256.0f32 * 256.0 / (64.0 * 64.0)).sqrt();
    assert_eq!(s.render.point_size, e3.render.point_size * ratio);
    s.resize_particles([1, 1]);
    assert_eq!(s.render.point_size, scene::MAX_SCALED_POINT_SIZE);
    let collide = scene::load("collide").unwrap();
    let mut s = collide.clone();
    s.resize_particles([8, 8]);
    assert_eq!(
        s.render.point_size, collide.render.point_size,
        "a radius, not a look"
    );
}
