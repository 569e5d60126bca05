//! The fluid's coherent re-sort (`fluid.resort = "coherent"`, src/sim/fluid/resort.rs): the
//! same state bit for bit as the full sort, step after step (the sorted layout is the same, so
//! every neighbour is found), with the check's fallback taken where the state was far from
//! sorted (the first step: the particles in lattice order, not cell order); and its keys'
//! refusals at their line.

mod common;

use common::fluid::tank;
use common::scene::{parse, scene_error};
use common::{context, no_gl_error};
use texflow::scene;
use texflow::sim::{ParticleSim, Simulation};

/// A small dam break: 16 × 16 × 4 particles of 1 cm at the left wall of a 24 cm × 4 cm tank,
/// in a 32×32 state; `extra` fluid keys.
fn dam(extra: &str) -> scene::SceneFile {
    let fluid = format!("speed_of_sound = 10.0\nviscosity = 0.1\nspacing = 0.01\n{extra}");
    parse(
        "dam",
        &tank(
            [32, 32],
            [0.24, 0.04],
            ([0.08, 0.08, 0.02], [0.16, 0.16, 0.04]),
            2e-4,
            &fluid,
        ),
    )
}

#[test]
fn the_coherent_resort_keeps_the_full_sorts_state_and_falls_back_when_far_from_sorted() {
    let ctx = context();
    let mut full = ParticleSim::new(&ctx, &dam(""), 1).unwrap();
    let coherent_scene = dam("resort = \"coherent\"\nresort_block = 64");
    let mut coherent = ParticleSim::new(&ctx, &coherent_scene, 1).unwrap();
    for step in 1..=120 {
        full.step().unwrap();
        coherent.step().unwrap();
        if step % 20 == 0 || step == 1 {
            let (a, b) = (full.read_state().unwrap(), coherent.read_state().unwrap());
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert!(
                bits(&a.0) == bits(&b.0) && bits(&a.1) == bits(&b.1),
                "step {step}: the states differ"
            );
        }
    }
    let s = coherent.fluid_stats().unwrap().expect("fluid stats");
    // The first step starts from the lattice order: the check finds it out of order.
    assert!(s.resort_fallbacks >= 1 && s.out_of_order >= 1, "{s:?}");
    assert!(s.coherent_resorts > 0, "{s:?}");
    assert_eq!(s.coherent_resorts + s.resort_fallbacks, 120, "{s:?}");
    let f = full.fluid_stats().unwrap().unwrap();
    assert_eq!(f.coherent_resorts + f.resort_fallbacks + f.out_of_order, 0);
    assert_eq!(coherent.truncated_searches().unwrap(), 0);
    let passes: Vec<String> = (coherent.features().step_passes().into_iter())
        .map(|p| p.name)
        .collect();
    let passes = passes.join("\n");
    assert!(passes.contains("fluid re-sort: blocks of 64"), "{passes}");
    no_gl_error(&ctx);
}

#[test]
fn resort_keys_are_refused_at_their_line() {
    let line_of = |src: &str| {
        1 + src
            .lines()
            .position(|l| l.starts_with("resort_block"))
            .unwrap()
    };
    let base = |extra: &str| {
        let fluid = format!("speed_of_sound = 10.0\nspacing = 0.01\n{extra}");
        tank(
            [32, 32],
            [0.24, 0.04],
            ([0.08, 0.08, 0.02], [0.16, 0.16, 0.04]),
            2e-4,
            &fluid,
        )
    };
    for (extra, says) in [
        ("resort_block = 64", "resort = \"coherent\""),
        ("resort = \"coherent\"\nresort_block = 96", "power of two"),
        ("resort = \"coherent\"\nresort_block = 16", "width (32)"),
        (
            "resort = \"coherent\"\nresort_block = 1024",
            "half its entries (512)",
        ),
    ] {
        let src = base(extra);
        let (line, _, message) = scene_error(scene::parse("bad.toml", &src));
        assert_eq!(line, line_of(&src), "{message}\n{src}");
        assert!(message.contains(says), "{message}");
    }
    let (_, _, m) = scene_error(scene::parse("bad.toml", &base("resort = \"partial\"")));
    assert!(m.contains("full") && m.contains("coherent"), "{m}");
}
