//! Soft particles (`render.soft`): a sprite cut by a plane fades towards the line where it meets
//! it (its opacity scaled by the distance in front of the geometry), and with the key off the
//! frame is the one drawn without it.

mod common;

use common::{context, no_gl_error};
use texflow::scene;

/// One white quad of 40 px at the origin, on a ground plane seen from 10° above it.
const SCENE: &str = r#"
name = "soft"
integrator = "euler"
[particles]
size = [1, 1]
[[emitters.initial]]
shape = "point"
center = [0.0, 0.0, 0.0]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
[[colliders.plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[render]
resolution = [64, 64]
primitive = "quads"
point_size = 40.0
geometry = true
keyframes = [{ age = 0.0, rgba = [1.0, 1.0, 1.0, 1.0] }]
"#;

fn frame(extra: &str) -> image::RgbImage {
    let s = scene::parse("soft.toml", &format!("{SCENE}{extra}")).unwrap();
    let ctx = context();
    let mut e = texflow::ParticleEngine::new(&ctx, &s, 1).unwrap();
    e.advance_frame().unwrap();
    let img = e.render().unwrap();
    no_gl_error(&ctx);
    img
}

/// Green of pixel (x, y): the plane is grey and the quad white, added on top.
fn g(img: &image::RgbImage, x: u32, y: u32) -> i32 {
    img.get_pixel(x, y).0[1] as i32
}

#[test]
fn a_sprite_cut_by_a_plane_fades_towards_the_cut() {
    let hard = frame("");
    let soft = frame("soft = 0.5\n");
    // The quad spans rows 12..32 above the centre (row 32); the plane meets it at the centre.
    let (x, near, far) = (32, 30, 14);
    // Without softness the quad is added evenly: as bright near the cut as far above it, over
    // what lies behind (plane near, sky far: the plane's grey brightens the near pixel).
    assert!(
        g(&hard, x, near) >= g(&hard, x, far),
        "{} {}",
        g(&hard, x, near),
        g(&hard, x, far)
    );
    // Soft: near the cut the plane is within 0.5 m behind the quad, so little is added there;
    // far above it the plane (or nothing) is far behind, so the quad is added in full.
    let added_near = g(&soft, x, near) - background(x, near);
    let added_far = g(&soft, x, far) - background(x, far);
    assert!(
        added_near < added_far,
        "near the cut {added_near} added, far from it {added_far}"
    );
    assert_eq!(
        g(&soft, x, far),
        g(&hard, x, far),
        "far from the plane nothing fades"
    );
}

/// The frame without the quad (the plane alone), for what the quad added.
fn background(x: u32, y: u32) -> i32 {
    thread_local!(static BG: image::RgbImage = frame_without_particle());
    BG.with(|b| g(b, x, y))
}

fn frame_without_particle() -> image::RgbImage {
    let s = SCENE.replace("[1.0, 1.0, 1.0, 1.0]", "[1.0, 1.0, 1.0, 0.0]");
    let s = scene::parse("soft.toml", &s).unwrap();
    let ctx = context();
    let mut e = texflow::ParticleEngine::new(&ctx, &s, 1).unwrap();
    e.advance_frame().unwrap();
    e.render().unwrap()
}

#[test]
fn soft_zero_is_the_frame_without_the_key() {
    assert!(frame("") == frame("soft = 0.0\n"));
    let err = scene::parse(
        "s.toml",
        &SCENE.replace("geometry = true", "geometry = false\nsoft = 0.1"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        err.contains("s.toml:") && err.contains("geometry = true"),
        "{err}"
    );
}
