//! `collisions.sort`: the collision stage on our blocked network against the same stage on
//! UberFlow's packed network (the paper's sort, the independent reference). Both sort exact
//! (key, id) entries, a total order, so every lattice's sorted layout, every detection and every
//! response must agree bit for bit, in each detection mode and with rows-only sorting.

mod common;

use common::scene::{collide_scene, random_gas};
use common::{context, no_gl_error};

use texflow::report::collide_stats::{CollisionStats, LatticeSnapshot, Snapshot};
use texflow::sim::{ParticleSim, Simulation};

fn bits(v: &[f32]) -> Vec<u32> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn same_lattice(a: &LatticeSnapshot, b: &LatticeSnapshot, what: &str) {
    assert_eq!(a.lattice, b.lattice, "{what}");
    assert_eq!(
        bits(&a.positions),
        bits(&b.positions),
        "{what}: sorted positions"
    );
    assert_eq!(
        bits(&a.velocities),
        bits(&b.velocities),
        "{what}: sorted velocities"
    );
    assert_eq!(bits(&a.partners), bits(&b.partners), "{what}: partners");
}

/// A 32x32 gas of 900 moving spheres under `collisions` (a `[collisions]` body), sorted by
/// `sort`; three steps, each step's snapshot and statistics.
fn run(collisions: &str, sort: &str) -> (Vec<(Snapshot, CollisionStats)>, Vec<u32>) {
    let ctx = context();
    let s = collide_scene(
        [32, 32],
        &format!(
            "[collisions]\nradius = 0.025\nbounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\n\
             sort = \"{sort}\"\n{collisions}"
        ),
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    let net = match (sort, collisions.contains("rows_only")) {
        // Rows-only blocked sorts of this small lattice take 4-byte exact entries.
        ("blocked", true) => "merge passes, 4-byte exact entries: cell key and ",
        ("blocked", false) => "(blocked: a network pass, then merge passes)",
        _ => "(GP/FP packed bitonic network)",
    };
    assert!(
        sim.passes().iter().any(|p| p.name.contains(net)),
        "{sort}: the pass list names the network and its entries"
    );
    common::set_particles(&mut sim, &random_gas(900, 7, 0.5, 1.0), |i, n| {
        (i as f32 + 0.5) / n as f32
    });
    let mut steps = Vec::new();
    for _ in 0..3 {
        sim.step().unwrap();
        let snap = Snapshot::read(sim.collisions().unwrap()).unwrap();
        let stats = snap.stats();
        steps.push((snap, stats));
    }
    let v = bits(&sim.read_velocities().unwrap());
    no_gl_error(&ctx);
    (steps, v)
}

/// UberFlow's detection with and without the staggered lattice, rows-only, and the exact mode:
/// the blocked sort gives the packed sort's layouts, partners, found share and state.
#[test]
fn blocked_collision_sort_matches_the_packed_one_in_every_mode() {
    for mode in [
        "",
        "staggered = false",
        "rows_only = 1",
        "rows_only = 4\nstaggered = false",
        "detection = \"exact\"",
    ] {
        let (packed, vp) = run(mode, "packed");
        let (blocked, vb) = run(mode, "blocked");
        for (k, ((a, sa), (b, sb))) in packed.iter().zip(&blocked).enumerate() {
            let what = format!("mode [{mode}] step {k}");
            same_lattice(&a.first, &b.first, &what);
            match (&a.second, &b.second) {
                (Some(x), Some(y)) => same_lattice(x, y, &format!("{what}, staggered")),
                (None, None) => {}
                _ => panic!("{what}: one run has a staggered lattice, the other not"),
            }
            assert_eq!(sa, sb, "{what}: statistics");
            // Not vacuous: the gas overlaps and the detection finds pairs.
            assert!(sa.pairs_true >= 20, "{what}: {sa:?}");
            assert!(sa.found > 0, "{what}: {sa:?}");
        }
        assert_eq!(vp, vb, "mode [{mode}]: velocities after three steps");
        eprintln!("[{mode}] last step {:?}", packed[2].1);
    }
}

/// A misspelt network is refused at its place in the file, with the two names.
#[test]
fn a_bad_collision_sort_names_its_place() {
    let src = "name = \"c\"\n[particles]\nsize = [8, 8]\n[[emitters.initial]]\n\
               direction = [0.0, 1.0, 0.0]\n[collisions]\nradius = 0.1\n\
               bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\nsort = \"bitonic\"\n";
    let (line, column, m) = common::scene::scene_error(texflow::scene::parse("c.toml", src));
    assert_eq!((line, column), (9, 8), "{m}");
    assert!(m.contains("`blocked`") && m.contains("`packed`"), "{m}");
}
