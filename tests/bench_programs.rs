//! `bench scene` builds every program it draws before its timed repetitions: a program built
//! within them would be drawn first inside a timed range, where a driver pays for its code (on
//! llvmpipe a compile at the first draw of each state), and a floor that pays it is no bound.
//! The render's placed points were built anew each repetition, and sat above the renders they
//! bounded on llvmpipe (0.60-0.66 at 32²). Checked as a count, not a time: more repetitions
//! build no more programs.
//!
//! One test in its own binary: the count is the process's, and no other test may build
//! programs meanwhile.

mod common;

use texflow::bench::{bench_scene, SceneBenchOptions};
use texflow::gl::Program;

/// Programs built by one `bench scene` run of `scene` at 16² with `repeats` repetitions.
fn built(ctx: &texflow::gl::Context, scene: &texflow::scene::SceneFile, repeats: usize) -> u64 {
    let opts = SceneBenchOptions {
        repeats,
        warmup_frames: Some(3),
        resolution: Some([48, 32]),
        ..Default::default()
    };
    let before = Program::made();
    let records = bench_scene(ctx, scene, &[16], &opts, |_| {}).unwrap();
    assert!(!records[0].phases.is_empty());
    Program::made() - before
}

#[test]
fn more_repetitions_build_no_more_programs() {
    let ctx = common::context();
    let scene = |name: &str, set: &[&str]| {
        let (label, src) = texflow::scene::load_source(name).unwrap();
        let set: Vec<String> = set.iter().map(|s| s.to_string()).collect();
        texflow::scene::parse_with(&label, &src, &set).unwrap()
    };
    // Placed points that write (e1) and that do not (the soft fire's round sprites), a sorted
    // render with its gather (smoke-unlit), the blocked sort's layers and its integer entries,
    // a collision stage's walk (dem).
    let cases = [
        ("e1", vec![]),
        ("fire", vec![]),
        ("smoke-unlit", vec![]),
        ("e3", vec!["render.sort.variant=\"blocked\""]),
        (
            "e3",
            vec![
                "render.sort.variant=\"blocked\"",
                "render.sort.entries=\"compact\"",
            ],
        ),
        ("dem", vec![]),
    ];
    for (name, set) in cases {
        let s = scene(name, &set);
        let (one, four) = (built(&ctx, &s, 1), built(&ctx, &s, 4));
        assert!(one > 0, "{name} {set:?}: no program built");
        assert_eq!(
            one, four,
            "{name} {set:?}: programs built with 1 repetition and with 4"
        );
    }
}
