//! The frame loop (`engine::FrameLoop`) that `texflow render`, the examples and these tests
//! share: what is written, dumped or shown never changes the state (issue 12, item 2), and the
//! loop's summary counts what it did.

mod common;

use std::ops::ControlFlow;

use texflow::engine::{FrameLoop, LoopOptions, MemorySink, NonFinitePolicy};
use texflow::{engine, scene, EngineKind};

/// Runs `frames` frames of a built-in scene on a tiny state, writing every `every`-th frame and
/// dumping every `dump_every`-th, and returns the sink.
fn run(name: &str, frames: u64, every: u64, dump_every: Option<u64>) -> MemorySink {
    let ctx = common::context();
    let mut s = match name.strip_suffix("+spread") {
        // Latta's sort spread over frames (§3.4.4) under an orbiting camera: the sort's state
        // carries over from frame to frame.
        Some(base) => {
            let mut s = scene::load(base).unwrap();
            s.render.sort.passes_per_frame = Some(3);
            s.render.camera.orbit = 30.0;
            s
        }
        None => scene::load(name).unwrap(),
    };
    s.particles.size = [16, 16];
    s.render.resolution = [48, 32];
    if let Some(c) = s.collisions.as_mut() {
        c.cell = None;
    }
    let mut engine = engine::build(&ctx, &s, 3, EngineKind::Gpu).unwrap();
    let options = LoopOptions {
        frames,
        every,
        dump_every,
        ..LoopOptions::default()
    };
    let run = FrameLoop::new(&ctx, engine.as_ref(), options).unwrap();
    let mut sink = MemorySink::default();
    let summary = run
        .run(engine.as_mut(), &mut sink, |_| ControlFlow::Continue(()))
        .unwrap();
    assert_eq!(summary.frames, frames);
    assert_eq!(summary.written, sink.frames.len() as u64);
    assert_eq!(summary.dumps, sink.dumps.len() as u64);
    common::no_gl_error(&ctx);
    sink
}

#[test]
fn what_is_written_does_not_change_any_frame() {
    // Every built-in scene, the spread sort of `smoke-unlit` among them: frame 20 is the same
    // whether every frame, every 20th or every 10th with dumps was written.
    for name in scene::BUILTIN.iter().copied().chain(["smoke-unlit+spread"]) {
        let all = run(name, 21, 1, None);
        let sparse = run(name, 21, 20, None);
        let dumped = run(name, 21, 10, Some(3));
        let last = |m: &MemorySink| m.frames.iter().find(|(i, _)| *i == 20).unwrap().1.clone();
        assert_eq!(sparse.frames.len(), 2, "{name}: frames 0 and 20");
        assert!(
            last(&all) == last(&sparse),
            "{name}: frame 20 differs between --every 1 and --every 20"
        );
        assert!(
            last(&all) == last(&dumped),
            "{name}: frame 20 differs when the state is dumped"
        );
        // Dumps are reads: the state they hold at frame 12 is the same in every run that takes it.
        assert_eq!(dumped.dumps.len(), 7, "{name}: frames 0, 3, ..., 18");
    }
}

#[test]
fn the_loop_can_be_stopped_between_frames() {
    let ctx = common::context();
    let s = {
        let mut s = scene::load("fountain").unwrap();
        s.particles.size = [16, 16];
        s.render.resolution = [16, 16];
        s
    };
    let mut engine = engine::build(&ctx, &s, 1, EngineKind::Gpu).unwrap();
    let run = FrameLoop::new(&ctx, engine.as_ref(), LoopOptions::default()).unwrap();
    let mut sink = MemorySink::default();
    let summary = run
        .run(engine.as_mut(), &mut sink, |e| match e {
            texflow::engine::Event::Frame { index: 4 } => ControlFlow::Break(()),
            _ => ControlFlow::Continue(()),
        })
        .unwrap();
    assert!(summary.stopped);
    assert_eq!(summary.frames, 5);
    assert_eq!(sink.frames.len(), 5);
    assert_eq!(summary.steps, 5 * s.time.substeps as u64);
    common::no_gl_error(&ctx);
}

#[test]
fn the_sort_follows_the_viewers_camera() {
    // The live window turns the camera (`Engine::set_view`): alpha blending must stay back to
    // front for the new eye, not the scene's.
    let ctx = common::context();
    let mut s = scene::load("smoke-unlit").unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [32, 32];
    let mut e = texflow::ParticleEngine::new(&ctx, &s, 2).unwrap();
    for _ in 0..30 {
        e.advance_frame().unwrap();
    }
    let start = *e.camera();
    let view = texflow::render::ViewOffset {
        azimuth: 150.0,
        elevation: -20.0,
        zoom: 0.7,
    };
    e.set_view(view);
    assert!(e.order_for_drawing().unwrap());
    let eye = e.camera().eye();
    assert!((e.camera().azimuth - (start.azimuth + 150.0)).abs() < 1e-3);
    assert!((eye - start.eye()).length() > 1.0, "the eye moved");
    let sorted = e.sorted().unwrap().texture(0).read_f32().unwrap();
    let live: Vec<f32> = sorted
        .chunks_exact(4)
        .filter(|p| p[3] > 0.0)
        .map(|p| (glam::Vec3::new(p[0], p[1], p[2]) - eye).length())
        .collect();
    assert!(live.len() > 20, "{} live", live.len());
    for w in live.windows(2) {
        assert!(
            w[0] >= w[1] - 1e-4,
            "not back to front for the new eye: {w:?}"
        );
    }
    // The identity view is the scene's camera again.
    e.set_view(texflow::render::ViewOffset::default());
    assert_eq!(e.camera().eye(), start.eye());
    common::no_gl_error(&ctx);
}

/// A texel whose life turned NaN is neither alive nor dead: never drawn and never dumped, but
/// lost state all the same. The census counts it, and the run stops with `Error::NonFinite`
/// (exit 3) naming it; allowed, it is counted in the summary.
#[test]
fn a_nan_life_stops_the_run() {
    let ctx = common::context();
    let src = "name = \"n\"\nintegrator = \"euler\"\n[particles]\nsize = [4, 4]\n\
               [[emitters.initial]]\nshape = \"point\"\ncenter = [0.0, 0.0, 0.0]\n\
               direction = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n\
               [render]\nresolution = [16, 16]\n";
    let s = common::scene::parse("n.toml", src);
    for policy in [NonFinitePolicy::Fail, NonFinitePolicy::Report] {
        let mut engine = texflow::ParticleEngine::new(&ctx, &s, 1).unwrap();
        let mut pos = engine.sim().read_positions().unwrap();
        let vel = engine.sim().read_velocities().unwrap();
        let st = engine.sim().statics().read_f32().unwrap();
        pos[4 * 5 + 3] = f32::NAN;
        engine.sim_mut().set_state(&pos, &vel, &st).unwrap();
        let options = LoopOptions {
            frames: 2,
            non_finite: policy,
            ..LoopOptions::default()
        };
        let run = FrameLoop::new(&ctx, &engine, options).unwrap();
        let mut sink = MemorySink::default();
        let r = run.run(&mut engine, &mut sink, |_| ControlFlow::Continue(()));
        match policy {
            NonFinitePolicy::Fail => {
                let e = r.unwrap_err();
                assert_eq!(e.exit_code(), 3, "{e}");
                assert!(e.to_string().contains("1 texel(s) have a NaN life"), "{e}");
            }
            NonFinitePolicy::Report => assert_eq!(r.unwrap().max_non_finite, 1),
        }
    }
    common::no_gl_error(&ctx);
}
