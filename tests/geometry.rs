//! `render.geometry`: the colliders drawn opaque in the particles' camera, the particles
//! depth-tested against them with every blending, and frames unchanged wherever no geometry is.

mod common;

use common::image::{front_camera, texture};
use common::{context, no_gl_error};
use glam::Vec3;
use texflow::gl::{Context, Texture, TextureFormat};
use texflow::render::{FrameTarget, GeometryRenderer, Mesh, ParticleRenderer, ParticleStyle};
use texflow::scene::{self, Blending, DrawOrder, Keyframe};
use texflow::ParticleEngine;

const S: u32 = 8;
const FW: u32 = 48;
const FH: u32 = 40;

/// Positions and statics of an 8×8 state with the given live particles (type 0, 1 of 2 s left).
fn state(ctx: &Context, live: &[Vec3]) -> (Texture, Texture) {
    let n = (S * S) as usize;
    let mut pos = vec![[f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0]; n];
    let stat = vec![[0.0, 0.0, 2.0, 0.25]; n];
    for (i, p) in live.iter().enumerate() {
        pos[i] = [p.x, p.y, p.z, 1.0];
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

/// Renders `live` particles with `style`, with a sphere of radius 0.5 at the origin drawn as
/// geometry or not.
fn render(ctx: &Context, style: &ParticleStyle, live: &[Vec3], geometry: bool) -> image::RgbImage {
    let mut renderer = ParticleRenderer::new(ctx, style.clone(), S, S).unwrap();
    let target = if geometry {
        let mut mesh = Mesh::default();
        mesh.sphere(Vec3::ZERO, 0.5, [0.5, 0.5, 0.5]);
        renderer.set_geometry(GeometryRenderer::new(ctx, &mesh).unwrap());
        FrameTarget::with_depth(ctx, FW, FH).unwrap()
    } else {
        FrameTarget::new(ctx, FW, FH).unwrap()
    };
    let (pos, stat) = state(ctx, live);
    renderer.clear(&target);
    renderer
        .draw(&target, &pos, &stat, &front_camera(4.0), live.len())
        .unwrap();
    target.read_rgb().unwrap()
}

#[test]
fn geometry_hides_the_particles_behind_it_with_every_blending() {
    let ctx = context();
    let (cx, cy) = (FW / 2, FH / 2);
    let behind = Vec3::new(0.0, 0.0, -1.5);
    let in_front = Vec3::new(0.0, 0.0, 1.5);
    let blends = [
        (Blending::Additive, DrawOrder::BackToFront),
        (Blending::Multiplicative, DrawOrder::BackToFront),
        (Blending::Alpha, DrawOrder::BackToFront),
        (Blending::Alpha, DrawOrder::FrontToBack),
    ];
    for (blending, order) in blends {
        let style = ParticleStyle {
            point_size: 5.0,
            blending,
            order,
            background: if blending == Blending::Multiplicative {
                [1.0; 3]
            } else {
                [0.0; 3]
            },
            keyframes: (0..4)
                .map(|k| Keyframe {
                    age: [0.0, 0.3, 0.6, 1.0][k],
                    rgba: [0.9, 0.4, 0.2, 1.0],
                })
                .collect(),
            ..ParticleStyle::default()
        };
        let what = format!("{blending:?} {order:?}");
        let empty = render(&ctx, &style, &[], false);
        let alone = render(&ctx, &style, &[], true);
        // The sphere is drawn at the centre, the corner stays background.
        assert_ne!(alone.get_pixel(cx, cy), empty.get_pixel(cx, cy), "{what}");
        assert_eq!(alone.get_pixel(0, 0), empty.get_pixel(0, 0), "{what}");
        // Without geometry the particle behind the sphere's place is visible...
        let seen = render(&ctx, &style, &[behind], false);
        assert_ne!(seen.get_pixel(cx, cy), empty.get_pixel(cx, cy), "{what}");
        // ...with it, it is hidden: the frame is the sphere's to the byte.
        let hidden = render(&ctx, &style, &[behind], true);
        assert_eq!(hidden, alone, "{what}: a particle behind the sphere shows");
        // A particle in front of the sphere is drawn over it.
        let front = render(&ctx, &style, &[in_front], true);
        assert_ne!(
            front.get_pixel(cx, cy),
            alone.get_pixel(cx, cy),
            "{what}: the particle in front is missing"
        );
        assert_eq!(front.get_pixel(0, 0), alone.get_pixel(0, 0), "{what}");
    }
    no_gl_error(&ctx);
}

/// A built-in scene at a tiny size, geometry on or off.
fn engine(ctx: &Context, name: &str, geometry: bool) -> ParticleEngine {
    let mut s = scene::load(name).unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [64, 64];
    s.render.geometry = geometry;
    ParticleEngine::new(ctx, &s, 7).unwrap()
}

#[test]
fn frames_change_only_where_the_geometry_is() {
    let ctx = context();
    for name in ["fountain", "snow"] {
        // Before the first step nothing is born: the frames are background, and geometry.
        let background = engine(&ctx, name, false).render().unwrap();
        let geometry = engine(&ctx, name, true).render().unwrap();
        let (mut off, mut on) = (engine(&ctx, name, false), engine(&ctx, name, true));
        for _ in 0..100 {
            off.advance_frame().unwrap();
            on.advance_frame().unwrap();
        }
        let (off, on) = (off.render().unwrap(), on.render().unwrap());
        let mut covered = 0;
        let mut particles_over_geometry = 0;
        let mut particles = 0;
        for ((x, y, bg), g) in background.enumerate_pixels().zip(geometry.pixels()) {
            let (a, b) = (off.get_pixel(x, y), on.get_pixel(x, y));
            particles += usize::from(a != bg);
            if g == bg {
                // No geometry here: the frame is the one without geometry, to the byte.
                assert_eq!(
                    a, b,
                    "{name}: pixel ({x}, {y}) changed where no geometry is"
                );
            } else {
                covered += 1;
                particles_over_geometry += usize::from(b != g);
            }
        }
        let share = covered as f64 / (64.0 * 64.0);
        assert!(
            (0.1..0.99).contains(&share),
            "{name}: geometry covers {share}"
        );
        assert!(particles > 0, "{name}: no particle drawn");
        assert!(
            particles_over_geometry > 0,
            "{name}: no particle drawn over the geometry"
        );
    }
    no_gl_error(&ctx);
}

#[test]
fn geometry_without_colliders_is_refused_with_its_place() {
    let src = scene::builtin_source("smoke-unlit").unwrap();
    let src = src.replacen("[render]\n", "[render]\ngeometry = true\n", 1);
    let line = src
        .lines()
        .position(|l| l == "geometry = true")
        .expect("a [render] table")
        + 1;
    let err = scene::parse("smoke.toml", &src).unwrap_err();
    let text = err.to_string();
    assert!(
        text.starts_with(&format!("smoke.toml:{line}:")),
        "{text} (line {line})"
    );
    assert!(text.contains("no") && text.contains("collider"), "{text}");
    assert!(err.is_bad_input());
}

/// The pixel where `p` lands in a `w`×`h` frame of `camera` (row 0 at the top).
fn pixel_of(camera: &texflow::render::Camera, p: Vec3, w: u32, h: u32) -> (u32, u32) {
    let c = camera.view_projection(w as f32 / h as f32) * p.extend(1.0);
    let ndc = c.truncate() / c.w;
    let x = (ndc.x * 0.5 + 0.5) * w as f32;
    let y = (0.5 - ndc.y * 0.5) * h as f32;
    (x as u32, y as u32)
}

/// A sphere on an orbit is drawn where the collision passes have it at each frame
/// (`SphereCollider::center_at`, what its uniforms are set from): at frame 0 at its start, half
/// a period later on the far side of the circle, and its start is background again. The
/// particles are far out of view.
#[test]
fn moving_spheres_are_drawn_where_the_passes_have_them() {
    let src = "name = \"orbit\"\nintegrator = \"verlet\"\n[particles]\nsize = [2, 2]\n\
               [time]\ndt = 0.01\nsubsteps = 5\n[[emitters.initial]]\nshape = \"point\"\n\
               center = [0.0, -50.0, 0.0]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n\
               [[colliders.sphere]]\ncenter = [0.4, 0.0, 0.0]\nradius = 0.3\n\
               orbit = { radius = 0.4, period = 1.0 }\n[render]\nresolution = [64, 64]\n\
               geometry = true\n\
               camera = { target = [0.0, 0.0, 0.0], distance = 3.0, elevation = 60.0 }\n";
    let s = scene::parse("orbit.toml", src).unwrap();
    let ctx = context();
    let mut engine = ParticleEngine::new(&ctx, &s, 1).unwrap();
    let camera = texflow::render::Camera::from(&s.render.camera);
    let sphere = &s.colliders.sphere[0];
    let start = Vec3::from(sphere.center_at(0.0));
    let background = {
        let mut bare = s.clone();
        bare.render.geometry = false;
        let frame = ParticleEngine::new(&ctx, &bare, 1)
            .unwrap()
            .render()
            .unwrap();
        *frame.get_pixel(0, 0)
    };
    let first = engine.render().unwrap();
    let (x, y) = pixel_of(&camera, start, 64, 64);
    assert_ne!(
        *first.get_pixel(x, y),
        background,
        "frame 0: no sphere at its start"
    );
    // Ten frames of 5 steps of 0.01 s: half a period.
    for _ in 0..10 {
        engine.advance_frame().unwrap();
    }
    let t = engine.sim().time();
    let now = Vec3::from(sphere.center_at(t));
    assert!(
        (now - Vec3::new(-0.4, 0.0, 0.0)).length() < 1e-3,
        "{now} at {t} s"
    );
    let half = engine.render().unwrap();
    let (u, v) = pixel_of(&camera, now, 64, 64);
    assert_ne!(
        *half.get_pixel(u, v),
        background,
        "no sphere where it is at {t} s"
    );
    assert_eq!(
        *half.get_pixel(x, y),
        background,
        "the sphere is still drawn at its start"
    );
    no_gl_error(&ctx);
}
