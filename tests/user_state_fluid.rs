//! User states in a fluid (`[[state]]` with `[fluid]`, src/sim/particles/fluid.rs): the fluid
//! writes the state in cell order every step, and the states follow their particles (a closed
//! form of each particle's number and age, checked at every texel after the re-sorts); `pair`
//! exchanges a state over the fluid's neighbour search, against an all-pairs CPU twin of one
//! step and the conservation of an antisymmetric exchange.

mod common;

use common::fluid::twin_scene_source;
use common::{context, no_gl_error};
use texflow::scene::{self, SceneFile};
use texflow::sim::{particle_live, ParticleSim};

/// The fluid of tests/fluid.rs's twin (216 particles in 256 texels, h = 2.4 cm) with `state`.
fn fluid_scene(state: &str) -> SceneFile {
    let src = format!("{}\n{state}", twin_scene_source());
    scene::parse("fluid_state.toml", &src).expect("a valid scene")
}

fn texel(a: &[f32], i: usize) -> [f32; 4] {
    [a[4 * i], a[4 * i + 1], a[4 * i + 2], a[4 * i + 3]]
}

/// The state follows its particle through the fluid's sorts: `x` is the particle's random
/// number (its static texel's w, which the fluid carries itself), `y` its texel at the start,
/// `w` the count of updates, the step count for every live particle.
#[test]
fn states_follow_their_particles_through_the_fluid_sort() {
    let ctx = context();
    for resort in ["", "resort = \"coherent\"\n"] {
        let mut s = fluid_scene(
            "[[state]]\nname = \"tag\"\ninit = \"vec4(random, float(index), 0.0, 0.0)\"\n\
             update = \"tag + vec4(0.0, 0.0, 0.0, 1.0)\"\n",
        );
        if !resort.is_empty() {
            s.fluid.as_mut().unwrap().resort = scene::Resort::Coherent;
        }
        let mut sim = ParticleSim::new(&ctx, &s, 7).unwrap();
        let steps = 30;
        for _ in 0..steps {
            sim.step().unwrap();
        }
        let tag = sim.read_user_state("tag").unwrap();
        let statics = sim.statics().read_f32().unwrap();
        let pos = sim.read_positions().unwrap();
        let (mut moved, mut live) = (0, 0);
        for i in 0..256 {
            let t = texel(&tag, i);
            assert_eq!(t[0], statics[4 * i + 3], "{resort}texel {i}: {t:?}");
            if particle_live(texel(&pos, i)) {
                live += 1;
                assert_eq!(t[3], steps as f32, "{resort}texel {i}: updates");
            } else {
                assert_eq!(t[3], 0.0, "{resort}texel {i}: a dead texel keeps its value");
            }
            moved += (t[1] != i as f32) as usize;
        }
        assert_eq!(live, 216);
        // The sort did reorder the particles (lattice order into cell order): the checks above
        // could fail.
        assert!(moved > 100, "only {moved} texels changed particle");
    }
    no_gl_error(&ctx);
}

const REACH: f32 = 0.04;
const K: f32 = 0.02;

/// An antisymmetric exchange over the fluid's search: one step against an all-pairs twin over
/// the fluid's sorted layout, and the sum of the state kept over many steps while it spreads.
#[test]
fn pair_exchanges_over_the_fluid_search() {
    let ctx = context();
    let s = fluid_scene(&format!(
        "[[state]]\nname = \"heat\"\ninit = \"vec4(x.x < 0.06 ? 1000.0 : 300.0, random, 0.0, \
         0.0)\"\npair = \"vec4({K:?} * (other.heat.x - heat.x) * (1.0 - r / {REACH:?}), 0.0, \
         0.0, 0.0)\"\nradius = {REACH}\n"
    ));
    let mut sim = ParticleSim::new(&ctx, &s, 3).unwrap();
    let before = sim.read_user_state("heat").unwrap();
    let total = |h: &[f32]| -> f64 { (0..256).map(|i| h[4 * i] as f64).sum() };
    sim.step().unwrap();
    let after = sim.read_user_state("heat").unwrap();
    let layout = sim.fluid().unwrap().read_back().unwrap();
    // The twin: each particle's value before the step (found by its random number, .y), plus
    // the pair over every live particle within REACH in the layout the exchange read.
    let old: std::collections::HashMap<u32, f32> = (0..256)
        .map(|i| (before[4 * i + 1].to_bits(), before[4 * i]))
        .collect();
    assert_eq!(
        old.len(),
        256,
        "the random numbers tell the particles apart"
    );
    let x = |i: usize| texel(&layout.positions, i);
    let mut exchanged = 0;
    for a in 0..256 {
        let h0 = old[&after[4 * a + 1].to_bits()];
        let mut want = h0;
        if particle_live(x(a)) {
            for b in (0..256).filter(|&b| b != a && particle_live(x(b))) {
                let r = (0..3)
                    .map(|k| (x(a)[k] - x(b)[k]).powi(2))
                    .sum::<f32>()
                    .sqrt();
                if r < REACH {
                    let hb = old[&after[4 * b + 1].to_bits()];
                    want += K * (hb - h0) * (1.0 - r / REACH);
                }
            }
        }
        let got = after[4 * a];
        exchanged += ((got - h0).abs() > 1.0) as usize;
        assert!(
            (got - want).abs() <= 1e-3 * want.abs(),
            "texel {a}: {got} against the twin's {want}"
        );
    }
    assert!(exchanged > 20, "only {exchanged} particles exchanged");
    let start = total(&before);
    for _ in 0..40 {
        sim.step().unwrap();
    }
    let end = sim.read_user_state("heat").unwrap();
    assert!(
        (total(&end) - start).abs() <= 1e-5 * start,
        "the sum moved from {start} to {}",
        total(&end)
    );
    no_gl_error(&ctx);
}

/// A `pair` reach beyond the fluid's 2h is refused at its line and column.
#[test]
fn a_reach_past_the_fluid_cell_is_refused() {
    let src = format!(
        "{}\n[[state]]\nname = \"heat\"\ninit = \"vec4(0.0)\"\npair = \"vec4(0.0)\"\n\
         radius = 0.06\n",
        twin_scene_source()
    );
    let line = src
        .lines()
        .position(|l| l.starts_with("radius = 0.06"))
        .unwrap()
        + 1;
    let e = scene::parse("bad.toml", &src).unwrap_err().to_string();
    assert!(
        e.contains(&format!("bad.toml:{line}:")) && e.contains("the fluid's reach 2h 0.048"),
        "{e}"
    );
}
