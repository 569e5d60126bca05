//! The pass list is what runs: for every built-in scene, the programs one frame draws (recorded
//! by the GL layer, `texflow::gl::DrawRecorder`) are those of the passes its engine lists
//! (`texflow scene passes`), each as many times as listed: the steps' passes times the substeps,
//! the sort's network passes as its schedule has them. A pass whose draws depend on the data
//! (births, half-angle slices over the live particles) draws at most as many, and at least once.

mod common;

use texflow::engine::{build, plan::Plan};
use texflow::EngineKind;

/// The programs `drawn` by count, in the order of their first draw.
fn counts(drawn: &[String]) -> Vec<(String, u64)> {
    let mut out: Vec<(String, u64)> = Vec::new();
    for d in drawn {
        match out.iter_mut().find(|(n, _)| n == d) {
            Some((_, c)) => *c += 1,
            None => out.push((d.clone(), 1)),
        }
    }
    out
}

/// What differs between the listed draws of `plan` and the `drawn` programs of one frame.
fn mismatches(plan: &Plan, drawn: &[String]) -> Vec<String> {
    let listed = plan.frame_draws();
    let drawn = counts(drawn);
    let mut out = Vec::new();
    for (program, n) in &drawn {
        match listed.iter().find(|(p, ..)| p == program) {
            None => out.push(format!("{program}: drawn {n} times, listed in no pass")),
            Some((_, m, true)) if n > m => {
                out.push(format!("{program}: drawn {n} times, listed at most {m}"))
            }
            Some((_, m, false)) if n != m => {
                out.push(format!("{program}: drawn {n} times, listed {m}"))
            }
            Some(_) => {}
        }
    }
    for (program, m, _) in &listed {
        if *m > 0 && !drawn.iter().any(|(p, _)| p == program) {
            out.push(format!("{program}: listed {m} times, never drawn"));
        }
    }
    out
}

#[test]
fn every_built_in_scene_draws_the_passes_it_lists() {
    let ctx = common::context();
    let mut failures = Vec::new();
    for name in texflow::scene::BUILTIN {
        let mut s = texflow::scene::load(name).unwrap();
        s.particles.size = [16, 16];
        s.render.resolution = [32, 32];
        let mut e = build(&ctx, &s, 1, EngineKind::Gpu).unwrap_or_else(|e| panic!("{name}: {e}"));
        // A first frame, so that the recorded one is an ordinary frame (births under way).
        e.advance_frame().unwrap();
        e.render().unwrap();
        let recorder = texflow::gl::DrawRecorder::start();
        e.advance_frame().unwrap();
        e.draw().unwrap();
        let drawn = recorder.finish();
        let plan = e.plan();
        assert_eq!(plan.passes, e.passes(), "{name}");
        for m in mismatches(&plan, &drawn) {
            failures.push(format!("{name}: {m}"));
        }
    }
    common::no_gl_error(&ctx);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The comparison fails both ways: a program drawn but not listed, and a pass listed but not
/// drawn (here with a plan whose list lost one pass, and one that gained a pass).
#[test]
fn a_pass_drawn_but_not_listed_or_listed_but_not_drawn_fails() {
    let ctx = common::context();
    let mut s = texflow::scene::load("smoke-unlit").unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [32, 32];
    let mut e = build(&ctx, &s, 1, EngineKind::Gpu).unwrap();
    e.advance_frame().unwrap();
    let recorder = texflow::gl::DrawRecorder::start();
    e.advance_frame().unwrap();
    e.draw().unwrap();
    let drawn = recorder.finish();
    let plan = e.plan();
    assert!(
        mismatches(&plan, &drawn).is_empty(),
        "{:?}",
        mismatches(&plan, &drawn)
    );
    let mut fewer = plan.clone();
    let integrate = fewer
        .passes
        .iter()
        .position(|p| p.stage == "integrate")
        .unwrap();
    fewer.passes.remove(integrate);
    assert!(mismatches(&fewer, &drawn)
        .iter()
        .any(|m| m.contains("sim/integrate.frag") && m.contains("listed in no pass")));
    let mut more = plan.clone();
    more.passes.push(
        texflow::gl::PassInfo::new("render", "composite background under").draws(
            &texflow::gl::Program::new(
                &ctx,
                texflow::gl::FULLSCREEN_VERTEX,
                "render/background.frag",
                &Vec::new(),
            )
            .unwrap(),
            1,
        ),
    );
    assert!(mismatches(&more, &drawn)
        .iter()
        .any(|m| m.contains("background.frag") && m.contains("never drawn")));
    // A sort pass fewer than the schedule has is a count that differs.
    let mut short = plan.clone();
    let sort = short
        .passes
        .iter_mut()
        .find(|p| p.name.starts_with("sort:"))
        .unwrap();
    sort.draws[0].1 -= 1;
    assert!(mismatches(&short, &drawn)
        .iter()
        .any(|m| m.contains("sort/") && m.contains("listed")));
    common::no_gl_error(&ctx);
}
