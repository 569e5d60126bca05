//! The engine core on a real GL context (llvmpipe in CI): ping-pong through MRT, the projection
//! of the particle renderer's fire ramp, and the fire's invariants over 1,000 steps.

mod common;

use common::image::probe;
use common::{context, no_gl_error, test_shader};
use glam::Vec3;
use texflow::gl::{Defines, FullscreenPass, PingPong, Program, TextureFormat, FULLSCREEN_VERTEX};
use texflow::render::{Camera, FireRamp, FrameTarget, ParticleRenderer, ParticleStyle};
use texflow::scene;
use texflow::sim::{FireParams, FireSim, Simulation};
use texflow::{engine, EngineKind};

/// A pass that adds 1 to both MRT targets: after k steps both hold initial + k, texel by texel,
/// at square, non-square and non-power-of-two sizes (a half-texel shift or a missed swap fails).
#[test]
fn increment_pass_through_mrt_ping_pong() {
    let ctx = context();
    let program = Program::new(
        &ctx,
        FULLSCREEN_VERTEX,
        &test_shader("increment.frag"),
        &Defines::new(),
    )
    .expect("test program");
    let pass = FullscreenPass::new(&ctx).unwrap();
    for &(w, h) in &[(1, 1), (7, 3), (64, 64), (100, 37), (256, 1), (1, 129)] {
        let mut pp = PingPong::new(
            &ctx,
            "inc",
            &["a", "b"],
            &[TextureFormat::Rgba32F, TextureFormat::Rgba16F],
            w,
            h,
        )
        .unwrap();
        // Texel i holds (i, 2i, -i, 0.5) in a and (0, 1, 2, 3) + (i mod 7) in b.
        let n = (w * h) as usize;
        let a0: Vec<f32> = (0..n)
            .flat_map(|i| [i as f32, 2.0 * i as f32, -(i as f32), 0.5])
            .collect();
        let b0: Vec<f32> = (0..n)
            .flat_map(|i| {
                let m = (i % 7) as f32;
                [m, 1.0 + m, 2.0 + m, 3.0 + m]
            })
            .collect();
        pp.front().texture(0).upload_f32(&a0).unwrap();
        pp.front().texture(1).upload_f32(&b0).unwrap();
        let k = 5;
        for _ in 0..k {
            let textures = [
                ("u_a", pp.front().texture(0).into()),
                ("u_b", pp.front().texture(1).into()),
            ];
            pass.draw(&program, &textures, &[], pp.back());
            pp.swap();
        }
        let a = pp.front().texture(0).read_f32().unwrap();
        let b = pp.front().texture(1).read_f32().unwrap();
        for i in 0..n * 4 {
            // a0 values stay below 2^11 here, so fp16 and fp32 both hold them exactly.
            assert_eq!(
                a[i],
                a0[i] + k as f32,
                "{w}x{h} texel {} channel {} of a",
                i / 4,
                i % 4
            );
            assert_eq!(
                b[i],
                b0[i] + k as f32,
                "{w}x{h} texel {} channel {} of b",
                i / 4,
                i % 4
            );
        }
        assert_eq!(pp.swaps(), k);
    }
    no_gl_error(&ctx);
}

/// One live particle lands on the pixel that glam's projection predicts, and nothing else is lit.
#[test]
fn particle_lands_on_the_projected_pixel() {
    let ctx = context();
    let camera = Camera {
        target: Vec3::new(0.1, 0.4, -0.2),
        distance: 3.0,
        azimuth: 30.0,
        elevation: 20.0,
        ..Camera::default()
    };
    let (fw, fh) = (96, 64);
    let target = FrameTarget::new(&ctx, fw, fh).unwrap();
    let max_age = 2.0;
    let renderer = ParticleRenderer::new(&ctx, fire_style(1.0, max_age, false), 4, 3).unwrap();
    // World positions behind chosen pixel centres, from the inverse of glam's projection.
    let inverse = camera.view_projection(fw as f32 / fh as f32).inverse();
    let positions_to_try: Vec<Vec3> = [(10u32, 7u32, 0.3f32), (48, 32, 0.9), (90, 60, -0.5)]
        .iter()
        .map(|&(x, y_down, ndc_z)| {
            let ndc = glam::Vec4::new(
                (x as f32 + 0.5) / fw as f32 * 2.0 - 1.0,
                1.0 - (y_down as f32 + 0.5) / fh as f32 * 2.0,
                ndc_z,
                1.0,
            );
            let w = inverse * ndc;
            let p = w.truncate() / w.w;
            assert_eq!(camera.project_to_pixel(p, fw, fh), Some((x, y_down)));
            p
        })
        .collect();
    let state = PingPong::new(
        &ctx,
        "one",
        &["position", "velocity"],
        &[TextureFormat::Rgba32F, TextureFormat::Rgba32F],
        4,
        3,
    )
    .unwrap();
    for (slot, p) in positions_to_try.iter().enumerate() {
        let (px, py) = camera.project_to_pixel(*p, fw, fh).expect("in view");
        // 12 particles, all dead (life 0) except the one in `slot`, alive at half its life.
        let mut pos = vec![0f32; 12 * 4];
        let mut vel = vec![0f32; 12 * 4];
        let i = 5 + slot;
        pos[4 * i..4 * i + 4].copy_from_slice(&[p.x, p.y, p.z, 1.0]);
        vel[4 * i + 3] = max_age - 2.0; // total life 2 s, 1 s left: relative age 0.5
        state.front().texture(0).upload_f32(&pos).unwrap();
        state.front().texture(1).upload_f32(&vel).unwrap();
        target.clear();
        renderer
            .draw(
                &target,
                state.front().texture(0),
                state.front().texture(1),
                &camera,
                12,
            )
            .unwrap();
        let img = target.read_rgb().unwrap();
        let lit: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(_, _, px)| px.0 != [0, 0, 0])
            .map(|(x, y, _)| (x, y))
            .collect();
        assert_eq!(lit, vec![(px, py)], "particle at {p}: lit pixels");
    }
    no_gl_error(&ctx);
}

/// The fire's soft sprites (render.mode = "sprites"): a 9-pixel sprite lights its 9×9 square
/// with the centre's colour times (1 − r²)², r the distance of the pixel centre from the sprite's
/// centre in units of its radius; the thesis's square point lights all 81 pixels alike.
#[test]
fn fire_sprites_fall_off_as_one_minus_r_squared_squared() {
    let ctx = context();
    let camera = Camera::default();
    let (fw, fh, size) = (64u32, 48u32, 9i32);
    let target = FrameTarget::new(&ctx, fw, fh).unwrap();
    let (cx, cy) = (30u32, 20u32);
    let ndc = glam::Vec4::new(
        (cx as f32 + 0.5) / fw as f32 * 2.0 - 1.0,
        1.0 - (cy as f32 + 0.5) / fh as f32 * 2.0,
        0.4,
        1.0,
    );
    let w = camera.view_projection(fw as f32 / fh as f32).inverse() * ndc;
    let state = one_particle_at(&ctx, w.truncate() / w.w);
    let draw = |soft: bool| {
        let renderer =
            ParticleRenderer::new(&ctx, fire_style(size as f32, 3.0, soft), 1, 1).unwrap();
        target.clear();
        renderer
            .draw(
                &target,
                state.front().texture(0),
                state.front().texture(1),
                &camera,
                1,
            )
            .unwrap();
        target.read_rgb().unwrap()
    };
    let (square, soft) = (draw(false), draw(true));
    let centre = square.get_pixel(cx, cy).0;
    assert!(
        centre.iter().any(|c| *c > 20),
        "a visible centre: {centre:?}"
    );
    assert_eq!(
        soft.get_pixel(cx, cy).0,
        centre,
        "the sprite's centre is the point's colour"
    );
    let half = size / 2;
    for (x, y, px) in soft.enumerate_pixels() {
        let (dx, dy) = (x as i32 - cx as i32, y as i32 - cy as i32);
        let inside = dx.abs() <= half && dy.abs() <= half;
        let want = if inside { centre } else { [0; 3] };
        probe(&square, x, y, &want, 0, &format!("square at {dx},{dy}"));
        let r2 = (4 * (dx * dx + dy * dy)) as f32 / (size * size) as f32;
        let k = if inside {
            (1.0 - r2).max(0.0).powi(2)
        } else {
            0.0
        };
        for (c, (got, centre)) in px.0.iter().zip(centre).enumerate() {
            let want = centre as f32 * k;
            assert!(
                (*got as f32 - want).abs() <= 1.5,
                "sprite at {dx},{dy}: {:?}, want {want} in channel {c}",
                px.0
            );
        }
    }
    no_gl_error(&ctx);
}

/// A state of one fire particle at `p`, with total life 2 s and 1 s left (relative age 0.5).
fn one_particle_at(ctx: &texflow::gl::Context, p: glam::Vec3) -> PingPong {
    let state = PingPong::new(
        ctx,
        "one",
        &["position", "velocity"],
        &[TextureFormat::Rgba32F, TextureFormat::Rgba32F],
        1,
        1,
    )
    .unwrap();
    state
        .front()
        .texture(0)
        .upload_f32(&[p.x, p.y, p.z, 1.0])
        .unwrap();
    state
        .front()
        .texture(1)
        .upload_f32(&[0.0, 0.0, 0.0, 1.0])
        .unwrap();
    state
}

/// The fire's look in the one particle renderer: its ramp, square points or soft sprites.
fn fire_style(point_size: f32, max_age: f32, soft: bool) -> ParticleStyle {
    ParticleStyle {
        point_size,
        intensity: 1.0,
        fire: Some(FireRamp { max_age, soft }),
        ..ParticleStyle::default()
    }
}

fn count_alive(pos: &[f32]) -> usize {
    pos.chunks_exact(4).filter(|p| p[3] > 0.0).count()
}

/// 1,000 steps of fire: every value finite, lives and waits in range, the live count within the
/// bounds the emission rule gives, and no particle far from where its forces can take it.
#[test]
fn fire_stays_finite_and_in_bounds_for_1000_steps() {
    let ctx = context();
    let params = FireParams::default();
    let (w, h) = (160u32, 120u32);
    let dt = 1.0 / 60.0;
    let mut sim = FireSim::new(&ctx, w, h, params.clone(), 42).unwrap();
    sim.set_time_step(dt, 1).unwrap();
    let n = (w * h) as f64;
    // Every particle's cycle is max_age long; a life L in [life_min, life_max] of it is alive, so
    // in the steady state the live fraction is E[L]/max_age. Phases are independent, so the count
    // is binomial; allow 6 standard deviations plus two steps of discretisation per cycle.
    let p = params.expected_live_fraction();
    let sigma = (n * p * (1.0 - p)).sqrt();
    let slack = 6.0 * sigma + n * 3.0 * dt as f64 / params.max_age as f64;
    let mut counts = Vec::new();
    for step in 1..=1000 {
        sim.step().unwrap();
        if step % 250 == 0 {
            let pos = sim.positions().read_f32().unwrap();
            let vel = sim.velocities().read_f32().unwrap();
            assert!(
                pos.iter().chain(&vel).all(|v| v.is_finite()),
                "non-finite value at step {step}"
            );
            for (pp, vv) in pos.chunks_exact(4).zip(vel.chunks_exact(4)) {
                assert!(
                    pp[3] >= 0.0 && pp[3] <= params.life_max,
                    "life {} out of range",
                    pp[3]
                );
                assert!(
                    vv[3] >= 0.0 && vv[3] <= params.max_age,
                    "wait {} out of range",
                    vv[3]
                );
                if pp[3] > 0.0 {
                    // Alive: total life max_age - wait lies in [life_min, life_max].
                    let life = params.max_age - vv[3];
                    assert!(life >= params.life_min - 1e-4 && life <= params.life_max + 1e-4);
                    // Buoyancy and noise cannot carry a particle further than this in one life.
                    let reach = params.life_max * (2.0 * params.speed + params.spread)
                        + 0.5
                            * (params.buoyancy.length() + params.turbulence)
                            * params.life_max.powi(2);
                    assert!(
                        Vec3::new(pp[0], pp[1], pp[2]).distance(params.emitter_center)
                            <= params.emitter_radius + reach
                    );
                }
            }
            let alive = count_alive(&pos) as f64;
            assert!(
                (alive - n * p).abs() <= slack,
                "step {step}: {alive} alive, expected {} ± {slack}",
                n * p
            );
            counts.push(alive);
        }
    }
    assert_eq!(sim.steps(), 1000);
    no_gl_error(&ctx);
}

/// Births are spread over the first cycle: no step sees more than a small share of the particles
/// born at once (the thesis's "one generation dies at once" artefact).
#[test]
fn fire_births_are_spread_over_the_cycle() {
    let ctx = context();
    let params = FireParams::default();
    let dt = 1.0 / 60.0;
    let mut sim = FireSim::new(&ctx, 64, 64, params.clone(), 3).unwrap();
    sim.set_time_step(dt, 1).unwrap();
    let n = 64.0 * 64.0;
    let per_step = n * dt as f64 / params.max_age as f64;
    let mut last = 0usize;
    for _ in 0..(params.max_age / dt) as usize {
        sim.step().unwrap();
        let alive = count_alive(&sim.positions().read_f32().unwrap());
        let born = alive.saturating_sub(last) as f64;
        assert!(
            born <= per_step + 6.0 * per_step.sqrt() + 2.0,
            "{born} born in one step, expected about {per_step}"
        );
        last = alive;
    }
    no_gl_error(&ctx);
}

fn png_bytes(seed: u64) -> Vec<u8> {
    let ctx = context();
    let mut s = scene::fire();
    s.particles.size = [96, 80];
    s.render.resolution = [128, 96];
    let mut engine = engine::build(&ctx, &s, seed, EngineKind::Gpu).unwrap();
    for _ in 0..40 {
        engine.advance_frame().unwrap();
    }
    let img = engine.render().unwrap();
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .unwrap();
    no_gl_error(&ctx);
    bytes
}

/// The same seed gives identical PNG bytes twice on the same device; another seed does not.
#[test]
fn same_seed_same_png() {
    let a = png_bytes(11);
    let b = png_bytes(11);
    let c = png_bytes(12);
    assert_eq!(a, b, "same seed, different frames");
    assert_ne!(a, c, "different seeds, same frame");
}

/// Sizes over the device limit are refused with a message naming the limit.
#[test]
fn state_over_the_texture_limit_is_refused() {
    let ctx = context();
    let max = ctx.limits().max_texture_size;
    let err = FireSim::new(&ctx, max + 1, 1, FireParams::default(), 0).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("GL_MAX_TEXTURE_SIZE") && msg.contains(&max.to_string()),
        "{msg}"
    );
    no_gl_error(&ctx);
}
