//! `bench passes` times every draw of a frame and groups them by program: checked against the
//! GL layer's own counters of an unprofiled frame of the same engine (the draw recorder's
//! programs and `DrawStats`' bytes), and against the pass list (every program drawn is listed).
//! Times are not compared (no timing in tests); they are only checked to be measured.

mod common;

use texflow::bench::{bench_passes, PassesOptions};
use texflow::engine::build_gpu;

/// Per program: draws and bytes of one frame after `warmup` frames, by the recorder and the
/// GL layer's counters (an engine of its own, built and run as `bench passes` does).
fn reference(
    ctx: &texflow::gl::Context,
    s: &texflow::scene::SceneFile,
    warmup: usize,
) -> (Vec<(String, u64)>, u64) {
    let mut e = build_gpu(ctx, s, 1).unwrap();
    for _ in 0..warmup {
        e.advance_frame().unwrap();
        e.draw().unwrap();
    }
    ctx.take_draw_stats();
    let recorder = texflow::gl::DrawRecorder::start();
    e.advance_frame().unwrap();
    e.draw().unwrap();
    let drawn = recorder.finish();
    let bytes = ctx.take_draw_stats().bytes_written;
    let mut counts: Vec<(String, u64)> = Vec::new();
    for d in drawn {
        match counts.iter_mut().find(|(n, _)| *n == d) {
            Some((_, c)) => *c += 1,
            None => counts.push((d, 1)),
        }
    }
    (counts, bytes)
}

#[test]
fn every_draw_of_a_frame_is_timed_and_named() {
    let ctx = common::context();
    for name in ["collide", "dam", "fountain", "smoke-unlit"] {
        let mut s = texflow::scene::load(name).unwrap();
        s.particles.size = [16, 16];
        s.render.resolution = [32, 24];
        s.time.substeps = s.time.substeps.min(2);
        let opts = PassesOptions {
            repeats: 1,
            warmup_frames: Some(3),
            clock: None,
        };
        let r = bench_passes(&ctx, &s, &opts, || {}).unwrap();
        // `bench passes` profiles frame 5 (3 of warm-up, one timed whole, then the profiled one).
        let (counts, bytes) = reference(&ctx, &s, 4);
        for (program, n) in &counts {
            let got: u64 = (r.passes.iter())
                .filter(|p| p.program == *program)
                .map(|p| p.draws)
                .sum();
            assert_eq!(got, *n, "{name}: draws of {program}");
        }
        let listed: u64 = r.passes.iter().map(|p| p.draws).sum();
        let drawn: u64 = counts.iter().map(|(_, n)| n).sum();
        assert_eq!(listed, drawn, "{name}: draws in all");
        let profiled: u64 = r.passes.iter().map(|p| p.bytes).sum();
        assert_eq!(
            profiled, bytes,
            "{name}: bytes written by full-screen draws"
        );
        for p in &r.passes {
            assert_ne!(
                p.stage, "unlisted",
                "{name}: {} is in no pass line",
                p.program
            );
            assert!(
                p.ms.is_finite() && p.ms >= 0.0,
                "{name}: {}: {} ms",
                p.program,
                p.ms
            );
            match (p.floor_ms, p.ratio) {
                (Some(f), Some(q)) => assert!(f > 0.0 && q.is_finite(), "{name}: {p:?}"),
                (None, None) => assert!(p.bytes == 0 || p.stage == "render", "{name}: {p:?}"),
                _ => panic!("{name}: a floor without a ratio: {p:?}"),
            }
        }
        assert!(r.frame_ms > 0.0 && r.draws_ms > 0.0, "{name}");
    }
    common::no_gl_error(&ctx);
}

#[test]
fn the_command_prints_a_table_and_json() {
    let out = common::cli::texflow(&[
        "bench",
        "passes",
        "collide",
        "--particles",
        "16",
        "--repeats",
        "1",
        "--warmup",
        "1",
        "--resolution",
        "32x24",
        "--json",
        "--quiet",
    ]);
    assert!(out.status.success(), "{}", common::cli::stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["schema"], "texflow.bench.passes/1");
    let passes = v["records"][0]["passes"].as_array().unwrap();
    assert!(passes.iter().any(|p| p["stage"] == "collide"), "{v}");
    let out = common::cli::texflow(&["bench", "passes", "no-such-scene", "--quiet"]);
    assert!(!out.status.success());
    assert!(common::cli::stderr(&out).contains("unknown scene"));
}
