//! `texflow bench scene` at tiny sizes (the phases of a scene's plan, each with a floor), the
//! render floor's points, and the public ping-pong pass API against closed forms.

mod common;

use texflow::bench::{bench_scene, RenderFloor, SceneBenchOptions};
use texflow::gl::{Framebuffer, PingPong, StatePass, Texture, TextureDesc, TextureFormat, Uniform};

fn opts() -> SceneBenchOptions {
    SceneBenchOptions {
        repeats: 2,
        warmup_frames: Some(3),
        resolution: Some([64, 64]),
        ..Default::default()
    }
}

#[test]
fn every_phase_of_the_plan_is_timed_next_to_a_floor() {
    let ctx = common::context();
    for (name, sorted, collides) in [
        ("fire", false, false),
        ("e3", true, false),
        ("collide", false, true),
    ] {
        let scene = texflow::scene::load(name).unwrap();
        let mut calls = 0;
        let records = bench_scene(&ctx, &scene, &[16], &opts(), |_| calls += 1).unwrap();
        assert_eq!((records.len(), calls), (1, 1));
        let r = &records[0];
        assert_eq!((r.size, r.particles, r.resolution), (16, 256, [64, 64]));
        assert!(r.live <= r.particles);
        assert!((r.fps * r.frame_ms - 1e3).abs() < 1e-6);
        assert!((r.particles_per_s - r.particles as f64 * r.fps).abs() < 1e-6 * r.particles_per_s);
        let has = |p: &str| r.phases.iter().any(|x| x.phase.starts_with(p));
        assert_eq!(
            has("sort keys") && has("sort network") && has("gather"),
            sorted,
            "{name}"
        );
        assert_eq!(has("collide"), collides, "{name}");
        assert!(has("render"), "{name}");
        for p in &r.phases {
            assert!(p.ms > 0.0 && p.floor_ms > 0.0, "{name}: {p:?}");
            assert!((p.ratio - p.ms / p.floor_ms).abs() < 1e-9);
        }
        // The cost model sees the fetches the sorts and UberFlow's detection declare.
        let fetches = |prefix: &str| -> u64 {
            (r.phases.iter())
                .filter(|x| x.phase.starts_with(prefix))
                .filter_map(|x| x.drawn.map(|d| d.stats.fetches))
                .sum()
        };
        assert_eq!(fetches("sort network") > 0, sorted, "{name}");
        assert_eq!(fetches("collide") > 0, collides, "{name}");
        // The same one-paragraph summary `render --stats` prints.
        let s = texflow::bench::scene::summary(r);
        assert!(
            s.contains(&format!("scene {name}")) && s.contains("fps"),
            "{s}"
        );
    }
    common::no_gl_error(&ctx);
}

#[test]
fn the_render_floor_draws_as_many_one_pixel_points_as_asked() {
    let ctx = common::context();
    let tex = Texture::new(
        &ctx,
        TextureDesc {
            width: 64,
            height: 64,
            format: TextureFormat::Rgba8,
            label: "floor frame",
        },
    )
    .unwrap();
    let fb = Framebuffer::new(&ctx, "floor frame", vec![tex]).unwrap();
    let floor = RenderFloor::new(&ctx).unwrap();
    let n = 200;
    // Without blending, each point replaces one pixel: lit pixels are the distinct positions of
    // n uniformly hashed points in 4096 pixels (about n - n²/8192 ≈ 195 expected).
    floor.draw(&fb, [0.0; 4], None, n);
    let lit = fb
        .texture(0)
        .read_u8()
        .unwrap()
        .chunks_exact(4)
        .filter(|p| p[0] > 0)
        .count();
    assert!((180..=n).contains(&lit), "{lit} lit pixels for {n} points");
    // In raster order (the cost model's frame probe), additive: 1.5 frames of points light the
    // first half of the frame's rows twice and the rest once, every pixel at its own.
    let blend = Some(texflow::gl::Blend::SUM);
    floor.draw_in_raster_order(&fb, [0.0; 4], blend, 64 * 64 * 3 / 2);
    let red: Vec<u8> = (fb.texture(0).read_u8().unwrap().chunks_exact(4))
        .map(|p| p[0])
        .collect();
    let once = red[64 * 64 - 1];
    assert!(once > 0, "the last pixel unlit");
    for (i, &r) in red.iter().enumerate() {
        let times = if i < 64 * 32 { 2 } else { 1 };
        assert!(r.abs_diff(once * times) <= 1, "pixel {i}: {r}, once {once}");
    }
    common::no_gl_error(&ctx);
}

const EULER: &str = "
uniform sampler2D u_state0;
uniform sampler2D u_state1;
uniform float u_dt;
uniform vec3 u_accel;
layout(location = 0) out vec4 o_x;
layout(location = 1) out vec4 o_v;
void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    vec4 x = texelFetch(u_state0, t, 0);
    vec4 v = texelFetch(u_state1, t, 0);
    o_x = vec4(x.xyz + v.xyz * u_dt, x.w);
    o_v = vec4(v.xyz + u_accel * u_dt, v.w);
}";

#[test]
fn a_user_pass_matches_the_closed_form_of_explicit_euler() {
    let ctx = common::context();
    let (w, h) = (16u32, 16u32);
    let formats = [TextureFormat::Rgba32F; 2];
    let mut state = PingPong::new(&ctx, "user", &["x", "v"], &formats, w, h).unwrap();
    let n = (w * h) as usize;
    let x0: Vec<f32> = (0..4 * n).map(|i| (i % 7) as f32 * 0.5).collect();
    let v0: Vec<f32> = (0..4 * n).map(|i| (i % 5) as f32 - 2.0).collect();
    state.front().texture(0).upload_f32(&x0).unwrap();
    state.front().texture(1).upload_f32(&v0).unwrap();
    let pass = StatePass::new(&ctx, "euler.frag", EULER, 2).unwrap();
    let (dt, a, steps) = (0.125f32, [0.0f32, -1.0, 0.5], 8);
    for _ in 0..steps {
        let accel = Uniform::Vec3(glam::Vec3::from_array(a));
        pass.run(
            &mut state,
            &[("u_dt", Uniform::F32(dt)), ("u_accel", accel)],
        );
    }
    assert_eq!(state.swaps(), steps as u64);
    let x = state.front().texture(0).read_f32().unwrap();
    let v = state.front().texture(1).read_f32().unwrap();
    // x_n = x0 + n dt v0 + a dt² n(n-1)/2, v_n = v0 + n dt a (exact in binary fractions).
    let t = steps as f32;
    for i in 0..n {
        for (c, a) in a.iter().enumerate() {
            let k = 4 * i + c;
            let xe = x0[k] + t * dt * v0[k] + a * dt * dt * t * (t - 1.0) / 2.0;
            let ve = v0[k] + t * dt * a;
            assert!((x[k] - xe).abs() < 1e-5, "x[{k}] {} vs {xe}", x[k]);
            assert!((v[k] - ve).abs() < 1e-5, "v[{k}] {} vs {ve}", v[k]);
        }
        assert_eq!((x[4 * i + 3], v[4 * i + 3]), (x0[4 * i + 3], v0[4 * i + 3]));
    }
    common::no_gl_error(&ctx);
}

#[test]
fn a_user_pass_that_does_not_compile_names_its_file_and_line() {
    let ctx = common::context();
    let src = "layout(location = 0) out vec4 o;\nvoid main() {\n    o = undefined_thing;\n}\n";
    let err = StatePass::new(&ctx, "mine.frag", src, 1)
        .unwrap_err()
        .to_string();
    assert!(err.contains("mine.frag"), "{err}");
    assert!(err.contains(":3") || err.contains("line 3"), "{err}");
    // Includes of the crate's GLSL work in a user pass.
    let src = "#include \"common/rng.glsl\"\nlayout(location = 0) out vec4 o;\nvoid main() { o = vec4(1.0); }\n";
    StatePass::new(&ctx, "with_include.frag", src, 1).unwrap();
    assert!(StatePass::new(&ctx, "five.frag", src, 5).is_err());
    common::no_gl_error(&ctx);
}

#[test]
fn bench_scene_runs_every_built_in_scene() {
    // The bench times the engine's own stages: a scene `render` runs (spin's sprites turned by
    // the spin texture among them) runs here too.
    let ctx = common::context();
    let opts = SceneBenchOptions {
        repeats: 1,
        warmup_frames: None,
        resolution: Some([64, 64]),
        ..Default::default()
    };
    for name in texflow::scene::BUILTIN {
        let scene = texflow::scene::load(name).unwrap();
        let records = bench_scene(&ctx, &scene, &[32], &opts, |_| {})
            .unwrap_or_else(|e| panic!("bench scene {name}: {e}"));
        let r = &records[0];
        assert!(r.live > 0, "{name}: nothing alive to time");
        assert!(
            r.phases.iter().any(|p| p.phase.starts_with("render")),
            "{name}: no render phase in {:?}",
            r.phases.iter().map(|p| &p.phase).collect::<Vec<_>>()
        );
        for p in &r.phases {
            assert!(
                p.ms.is_finite() && p.ms > 0.0,
                "{name}: {} {}",
                p.phase,
                p.ms
            );
            assert!(
                p.floor_ms.is_finite() && p.floor_ms > 0.0,
                "{name}: {}",
                p.phase
            );
            predicted_from_what_it_drew(name, r, p);
        }
        let table = texflow::bench::scene_markdown(&records);
        assert!(
            table.contains("| predicted_ms | predicted / ms |"),
            "{table}"
        );
    }
}

/// A phase's prediction is the cost model's sum over what it drew, with the record's constants
/// (computed here term by term); every phase has one. The render pass and a lit scene's
/// passes apart, whose fragments were counted, are priced by the frame's constants, measured
/// into a frame of the record's resolution.
fn predicted_from_what_it_drew(
    name: &str,
    r: &texflow::bench::SceneBenchRecord,
    p: &texflow::bench::scene::PhaseRecord,
) {
    let c = &r.constants;
    let f = c.frame.expect("bench scene measures the frame's constants");
    assert_eq!(f.resolution, r.resolution, "{name}");
    for k in [
        c.fixed_ms,
        c.follow_on_ms,
        c.concurrent_ms,
        c.ms_per_mb_written,
        c.ms_per_m_fetches,
        c.ms_per_m_points,
        c.ms_per_m_vertices,
        f.ms_per_m_fragments,
        f.ms_per_m_points,
        f.ms_per_m_cleared,
    ] {
        assert!(k.is_finite() && k >= 0.0, "{name}: {c:?}");
    }
    let slices = p.phase.starts_with("light-buffer") || p.phase.starts_with("eye passes");
    match (p.drawn, p.predicted_ms) {
        (Some(d), Some(m)) => {
            let s = d.stats;
            // Into a frame, a fragment's time holds its write: the bytes are not charged again.
            // The texels cleared are priced there only (the render pass clears its frame).
            let (per_point, fragments, bytes) = match d.fragments {
                Some(n) => (
                    f.ms_per_m_points,
                    n as f64 / 1e6 * f.ms_per_m_fragments
                        + s.cleared as f64 / 1e6 * f.ms_per_m_cleared,
                    0,
                ),
                None => (c.ms_per_m_points, 0.0, s.bytes_written),
            };
            // The render pass clears its frame, every texel of it (a lit render its light
            // buffer too).
            if p.phase.starts_with("render") {
                let [w, h] = r.resolution;
                let frame = w as u64 * h as u64;
                let lit = (r.phases.iter()).any(|q| q.phase.starts_with("light-buffer"));
                assert!(
                    s.cleared == frame || (lit && s.cleared > frame),
                    "{name}: {}: {} texels cleared, the frame has {frame}",
                    p.phase,
                    s.cleared
                );
            }
            assert!(
                s.follow_ons + s.concurrent < s.draws.max(1),
                "{name}: the first draw follows none and waits on what came before"
            );
            assert_eq!(
                d.fragments.is_some(),
                p.phase.starts_with("render") || slices,
                "{name}"
            );
            let want = (s.draws - s.follow_ons - s.concurrent) as f64 * c.fixed_ms
                + s.follow_ons as f64 * c.follow_on_ms
                + s.concurrent as f64 * c.concurrent_ms
                + (s.vertices - s.points) as f64 / 1e6 * c.ms_per_m_vertices
                + bytes as f64 / 1e6 * c.ms_per_mb_written
                + s.fetches as f64 / 1e6 * c.ms_per_m_fetches
                + s.points as f64 / 1e6 * per_point
                + fragments;
            // (A phase may draw nothing in a repetition: births when none is due.)
            assert!((m - want).abs() <= 1e-9 * want.max(1.0), "{name}: {p:?}");
        }
        _ => panic!("{name}: a prediction without counts, or counts without one: {p:?}"),
    }
}

#[test]
fn bench_step_measures_any_scene() {
    // The fire, a scene of the particle pipeline without sort, and one sorted for alpha
    // blending: each step and render pass timed next to its floor, on the engine `render` runs.
    let ctx = common::context();
    let opts = texflow::bench::StepOptions {
        repeats: 2,
        warmup_steps: 3,
        clock: None,
    };
    for name in ["fire-points", "fountain", "smoke-unlit"] {
        let mut scene = texflow::scene::load(name).unwrap();
        scene.render.resolution = [32, 32];
        let records = texflow::bench::bench_step(&ctx, &scene, &[16], &opts, |_| {})
            .unwrap_or_else(|e| panic!("bench step {name}: {e}"));
        let r = &records[0];
        assert_eq!((r.size, r.particles), (16, 256), "{name}");
        for (ms, floor, ratio) in [
            (r.sim_ms, r.sim_floor_ms, r.sim_ratio),
            (r.render_ms, r.render_floor_ms, r.render_ratio),
        ] {
            assert!(ms > 0.0 && floor > 0.0, "{name}: {r:?}");
            assert!((ratio - ms / floor).abs() < 1e-9, "{name}: {r:?}");
        }
    }
    common::no_gl_error(&ctx);
}

#[test]
fn the_stages_run_in_order_are_the_engines_frame() {
    // The parts the benchmarks time (the sort's key pass, network and gather, then the render
    // pass) draw the same pixels as the engine's own frame, for scenes with and without a sort.
    let ctx = common::context();
    for name in ["smoke-unlit", "e3", "fire", "spin"] {
        let mut scene = texflow::scene::load(name).unwrap();
        scene.particles.size = [16, 16];
        scene.render.resolution = [32, 32];
        let build = || texflow::engine::build_gpu(&ctx, &scene, 3).unwrap();
        let (mut whole, mut parts) = (build(), build());
        for _ in 0..4 {
            whole.advance_frame().unwrap();
            parts.advance_frame().unwrap();
        }
        let expected = whole.render().unwrap();
        let sorts = parts.sort_keys().unwrap().is_some();
        assert_eq!(sorts, parts.sorter().is_some(), "{name}");
        parts.sort_network();
        parts.sort_gather().unwrap();
        parts.render_pass(sorts).unwrap();
        let got = parts.target().read_rgb().unwrap();
        let corner = *expected.get_pixel(0, 0);
        assert!(
            expected.pixels().any(|p| *p != corner),
            "{name}: nothing drawn"
        );
        assert_eq!(got, expected, "{name}");
    }
    common::no_gl_error(&ctx);
}

/// A lit render (half-angle slices) is bounded by its chain of slices as well: an eye and a
/// light pass for each batch of particles drawn, one point each, the eye passes fetching the
/// light buffer; and by the fill floor, the same slices' quads. `smoke` at 32² (every texel
/// live after its warm-up) draws all its slices; at `render.slices = 4` as many as 4. The
/// light and eye passes timed apart have the fill floor's passes of their kind beside them.
#[test]
fn a_lit_render_is_bounded_by_its_chain_of_slices() {
    let ctx = common::context();
    for slices in [32u32, 4] {
        let mut scene = texflow::scene::load("smoke").unwrap();
        scene.render.slices = slices;
        let records = bench_scene(&ctx, &scene, &[32], &opts(), |_| {}).unwrap();
        let r = &records[0];
        let drawn = (r.live as u32).min(slices) as u64;
        let phase = |prefix: &str| {
            (r.phases.iter().find(|p| p.phase.starts_with(prefix)))
                .unwrap_or_else(|| panic!("no phase {prefix}"))
        };
        let bound = |p: &texflow::bench::scene::PhaseRecord, prefix: &str| {
            let b = (p.bounds.iter().find(|b| b.floor.starts_with(prefix)))
                .unwrap_or_else(|| panic!("no bound {prefix} among {:?}", p.bounds));
            b.drawn.expect("a drawn bound")
        };
        let render = phase("render");
        let chain = bound(render, "the slices' chain");
        let s = chain.stats;
        assert_eq!(
            (s.draws, s.points, s.vertices, s.bytes_written),
            (2 * drawn, 2 * drawn, 2 * drawn, 0),
            "{slices} slices, {} live",
            r.live
        );
        // One pixel a pass, every one blended (none dropped by a test).
        assert_eq!(chain.fragments, Some(2 * drawn), "{slices} slices");
        // The fill floor draws the render's quads, pass for pass, and the slices number
        // 2 × those drawn.
        for prefix in ["render", "light-buffer passes", "eye passes"] {
            let p = phase(prefix);
            let (f, d) = (
                bound(p, "fill floor").stats,
                p.drawn.expect("counted").stats,
            );
            assert_eq!((f.draws, f.vertices), (d.draws, d.vertices), "{prefix}");
            let slices_drawn = if prefix == "render" { 2 * drawn } else { drawn };
            // The eye passes may end with the background's composite (one triangle).
            assert!(
                [slices_drawn, slices_drawn + 1].contains(&d.draws),
                "{prefix}: {} draws, {slices_drawn} slices",
                d.draws
            );
        }
    }
}
