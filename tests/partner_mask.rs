//! The passes that work on the partners a neighbour search finds (the exact count, the DEM and
//! pair forces, the fluid's force) test a whole run of cells first and then work on its partners
//! in the order visited (`PARTNER_MASK`, `glsl/collide/cells.glsl`): the state after a run is the
//! same, bit for bit, as when each visit worked on its partner at once. Runs of more than 32
//! particles (tested 32 at a time), more than 64 (the fluid's search goes to 128) and past the
//! search's bound are among the cases.

mod common;

use common::scene::random_gas;
use common::{context, no_gl_error};
use texflow::scene;
use texflow::sim::collide::cells::{with_partner_work, with_search};
use texflow::sim::ParticleSim;

/// A 16×16 exact-collision scene over [0, 1)³, cells of 0.1 (2.5 r), two iterations.
fn exact_scene() -> scene::SceneFile {
    common::scene::collide_scene(
        [16, 16],
        "[collisions]\nradius = 0.04\nrestitution = 0.9\ndetection = \"exact\"\ncell = 0.1\n\
         iterations = 2\nbounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]",
    )
}

/// A gas over the lower half of the box, a crowd of 48 in one cell (runs of 33 to 64) and one
/// of 80 in another (past the bound of 64), the rest of the 256 texels dead.
fn particles() -> Vec<([f32; 3], [f32; 3])> {
    let mut p = random_gas(100, 3, 2.0, 0.5);
    for (n, seed, at) in [(48, 5, [0.71, 0.11, 0.31]), (80, 9, [0.21, 0.61, 0.81])] {
        let crowd = random_gas(n, seed, 0.5, 0.08);
        p.extend(
            crowd
                .into_iter()
                .map(|(x, v)| ([x[0] + at[0], x[1] + at[1], x[2] + at[2]], v)),
        );
    }
    assert!(48 > 32 && 48 <= scene::EXACT_SCAN as usize && 80 > scene::EXACT_SCAN as usize);
    p
}

/// `steps` steps of `s` with each partner worked as visited and with the mask (in that order):
/// positions and velocities after them, and the pass list's words for each.
fn both_ways(
    ctx: &texflow::gl::Context,
    s: &scene::SceneFile,
    steps: usize,
    set: impl Fn(&mut ParticleSim),
) -> [(Vec<f32>, Vec<f32>, String); 2] {
    [false, true].map(|deferred| {
        with_partner_work(deferred, || {
            let mut sim = ParticleSim::new(ctx, s, 1).unwrap();
            set(&mut sim);
            for _ in 0..steps {
                sim.step().unwrap();
            }
            let x = sim.read_positions().unwrap();
            let v = sim.read_velocities().unwrap();
            let passes = format!("{:?}", common::plan_of(ctx, s).passes);
            (x, v, passes)
        })
    })
}

fn assert_same_runs(name: &str, runs: [(Vec<f32>, Vec<f32>, String); 2]) {
    let [(x1, v1, p1), (x2, v2, p2)] = runs;
    let words = "partners worked after its tests";
    assert!(
        !p1.contains(words) && p2.contains(words),
        "{name}: {p1}\n{p2}"
    );
    for (what, a, b) in [("positions", &x1, &x2), ("velocities", &v1, &v2)] {
        assert_eq!(a.len(), b.len());
        for (i, (p, q)) in a.iter().zip(b.iter()).enumerate() {
            assert_eq!(
                p.to_bits(),
                q.to_bits(),
                "{name} {what}: float {i}: {p} against {q}"
            );
        }
    }
    // The runs moved: a comparison of untouched states would prove nothing.
    assert!(v1.iter().any(|v| *v != 0.0), "{name}: nothing moves");
}

#[test]
fn the_exact_count_gives_the_same_state_either_way() {
    let ctx = context();
    let set = |sim: &mut ParticleSim| {
        common::set_particles(sim, &particles(), |i, n| (i as f32 + 0.5) / n as f32)
    };
    for table in [true, false] {
        let s = exact_scene();
        let runs = with_search(table, || both_ways(&ctx, &s, 4, set));
        assert_same_runs(&format!("exact, table {table}"), runs);
    }
    // The trimmed walk (a cell of 1.25 r, below 2 r).
    let mut trimmed = exact_scene();
    trimmed.collisions.as_mut().unwrap().cell = Some(0.05);
    assert_same_runs("exact, trimmed", both_ways(&ctx, &trimmed, 4, set));
    no_gl_error(&ctx);
}

#[test]
fn the_forces_give_the_same_state_either_way() {
    let ctx = context();
    for name in ["dem", "spin", "dam", "drop"] {
        let mut s = scene::load(name).unwrap();
        s.particles.size = [16, 16];
        assert_same_runs(name, both_ways(&ctx, &s, 6, |_| {}));
    }
    // A fluid on a lattice smaller than the tank: the particles outside crowd its edge cells,
    // runs of more than 64 (the fluid's bound is 128), on cells of h (trimmed) and 2h.
    let src = common::fluid::twin_scene_source();
    let full = "bounds = [[0.0, 0.0, 0.0], [0.24, 1.0, 0.12]]";
    assert!(src.contains(full));
    for cell in ["h", "2h"] {
        let small = format!("bounds = [[0.03, 0.02, 0.03], [0.15, 0.12, 0.09]]\ncell = \"{cell}\"");
        let s = common::scene::parse("fluid", &src.replace(full, &small));
        assert_same_runs(
            &format!("small lattice, {cell}"),
            both_ways(&ctx, &s, 151, |_| {}),
        );
    }
    no_gl_error(&ctx);
}

/// Outside `with_partner_work`, the exact count defers its partners' work and the forces work
/// on each as they visit it (the choice measured on llvmpipe and an NVIDIA H100:
/// docs/collisions.md).
#[test]
fn the_exact_count_defers_by_default_and_the_forces_do_not() {
    use texflow::sim::collide::cells::PartnerWork;
    assert!(PartnerWork::Contacts.deferred());
    assert!(!PartnerWork::Forces.deferred());
    let ctx = context();
    let words = "partners worked after its tests";
    for (name, deferred) in [("spin", true), ("dem", false), ("drop", false)] {
        let s = scene::load(name).unwrap();
        let passes = format!("{:?}", common::plan_of(&ctx, &s).passes);
        assert_eq!(passes.contains(words), deferred, "{name}: {passes}");
    }
    let passes = format!("{:?}", common::plan_of(&ctx, &exact_scene()).passes);
    assert!(passes.contains(words), "{passes}");
    no_gl_error(&ctx);
}
