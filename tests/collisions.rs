//! Collisions between particles against CPU references: the exact detection finds every pair
//! of random gases (brute force on the CPU), the response separates resting overlaps without
//! adding kinetic energy and conserves momentum.

mod common;

use common::scene::{brute_counts, collide_scene, random_gas};
use common::{context, no_gl_error};
use std::collections::{HashMap, HashSet};

use texflow::report::collide_stats::{LatticeSnapshot, Snapshot};
use texflow::scene;
use texflow::sim::ParticleSim;

/// Uploads particles (position, velocity) as type 0, permanent; the rest of the texture dead.
fn set(sim: &mut ParticleSim, particles: &[([f32; 3], [f32; 3])]) {
    common::set_particles(sim, particles, |i, n| (i as f32 + 0.5) / n as f32);
}

/// The exact mode finds every pair of random gases from 0.3 to about 30 overlapping neighbours
/// per particle: each particle's partner count equals the brute-force count, and the statistics
/// report no miss.
#[test]
fn exact_mode_finds_every_pair_of_random_gases() {
    let ctx = context();
    for (radius, seed) in [(0.02f32, 1u32), (0.04, 2), (0.06, 3), (0.1, 4)] {
        let s = collide_scene(
            [32, 32],
            &format!(
                "[collisions]\nradius = {radius}\ndetection = \"exact\"\n\
                 bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]"
            ),
        );
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        set(&mut sim, &random_gas(1000, seed, 0.0, 1.0));
        sim.run(texflow::sim::Stage::Collide).unwrap();
        let snap = Snapshot::read(sim.collisions().unwrap()).unwrap();
        let brute = brute_counts(&snap.first.positions, 2.0 * radius);
        let found: Vec<usize> = snap
            .first
            .partners
            .chunks(4)
            .map(|c| c[0] as usize)
            .collect();
        let pairs: usize = brute.iter().sum::<usize>() / 2;
        assert!(pairs > 50, "radius {radius}: only {pairs} pairs");
        assert_eq!(found, brute, "radius {radius}: partner counts");
        let stats = snap.stats();
        assert_eq!(stats.pairs_true, pairs);
        assert_eq!(
            (stats.missed, stats.false_pairs, stats.truncated),
            (0, 0, 0)
        );
        assert_eq!(stats.partnered, stats.overlapping);
        eprintln!(
            "radius {radius}: {pairs} pairs, {:.2} overlaps per particle, all found",
            stats.overlaps_per_particle
        );
        no_gl_error(&ctx);
    }
}

/// A moving dense gas under the exact response: momentum conserved and kinetic energy never
/// above its start (elastic, every partner at once, weights 1/max(n_i, n_j)).
#[test]
fn exact_response_conserves_momentum_and_adds_no_energy() {
    let ctx = context();
    let s = collide_scene(
        [16, 16],
        "[collisions]\nradius = 0.06\nrestitution = 1.0\ndetection = \"exact\"\n\
         bounds = [[-1.0, -1.0, -1.0], [2.0, 2.0, 2.0]]",
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    let gas: Vec<_> = random_gas(256, 5, 1.0, 1.0)
        .into_iter()
        .map(|(p, v)| (p.map(|c| c * 0.5), v))
        .collect();
    set(&mut sim, &gas);
    let sums = |sim: &ParticleSim| -> ([f64; 3], f64) {
        let v = sim.read_velocities().unwrap();
        let mut p = [0.0; 3];
        let mut e = 0.0;
        for c in v.chunks(4) {
            for k in 0..3 {
                p[k] += c[k] as f64;
            }
            e += 0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) as f64;
        }
        (p, e)
    };
    let (p0, e0) = sums(&sim);
    for _ in 0..40 {
        sim.step().unwrap();
        let (p, e) = sums(&sim);
        for k in 0..3 {
            assert!((p[k] - p0[k]).abs() < 1e-4, "momentum {p:?} vs {p0:?}");
        }
        assert!(e <= e0 * (1.0 + 1e-5), "energy {e} above {e0}");
    }
    no_gl_error(&ctx);
}

/// Two particles at rest overlapping by half a diameter are separated to contact within a few
/// steps, in both modes, without gaining kinetic energy; momentum stays zero.
#[test]
fn response_separates_a_resting_overlap() {
    let ctx = context();
    for mode in ["uberflow", "exact"] {
        let s = collide_scene(
            [2, 1],
            &format!(
                "[collisions]\nradius = 0.1\nrestitution = 0.5\ndetection = \"{mode}\"\n\
                 bounds = [[-2.0, -2.0, -2.0], [2.0, 2.0, 2.0]]"
            ),
        );
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        set(
            &mut sim,
            &[([0.25, 0.3, 0.3], [0.0; 3]), ([0.35, 0.3, 0.3], [0.0; 3])],
        );
        for _ in 0..3 {
            sim.step().unwrap();
        }
        let x = sim.read_positions().unwrap();
        let v = sim.read_velocities().unwrap();
        let d: f32 = (0..3)
            .map(|k| (x[k] - x[4 + k]).powi(2))
            .sum::<f32>()
            .sqrt();
        assert!(d >= 0.2 - 1e-5, "{mode}: still overlapping, distance {d}");
        assert!(v.iter().all(|c| *c == 0.0), "{mode}: velocities {v:?}");
        let mid = (x[0] + x[4]) / 2.0;
        assert!(
            (mid - 0.3).abs() < 1e-6,
            "{mode}: centre of mass moved to {mid}"
        );
        no_gl_error(&ctx);
    }
}

/// A time-stamp scene of 16x16 particles whose cycle is 16 steps: with row-coherent phases each
/// step's release is one row.
fn release_scene(collisions: &str) -> scene::SceneFile {
    let src = format!(
        r#"
name = "release"
integrator = "euler"
[particles]
size = [16, 16]
[time]
dt = 0.01
[[emitters.timestamp]]
cycle = 0.16
shape = "disc"
center = [0.0, 0.5, 0.0]
radius = 0.1
normal = [0.0, 1.0, 0.0]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
life = [0.16, 0.16]
[collisions]
radius = 0.02
bounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]
{collisions}
"#
    );
    common::scene::parse("test", &src)
}

/// With row-coherent emission the particles of each row share one birth time, and the rows are
/// the 16 steps of the cycle in order.
#[test]
fn row_coherent_emission_shares_birth_time_per_row() {
    let ctx = context();
    let sim = ParticleSim::new(&ctx, &release_scene(""), 1).unwrap();
    let st = sim.statics().read_f32().unwrap();
    for y in 0..16 {
        let want = (y as f32 + 0.5) * 0.01;
        for x in 0..16 {
            let phase = st[(y * 16 + x) * 4];
            assert!(
                (phase - want).abs() < 1e-6,
                "texel ({x}, {y}): phase {phase}, row {want}"
            );
        }
    }
    no_gl_error(&ctx);
}

fn found_after_first_release(collisions: &str) -> texflow::report::collide_stats::CollisionStats {
    let ctx = context();
    let mut sim = ParticleSim::new(&ctx, &release_scene(collisions), 1).unwrap();
    sim.step().unwrap();
    let stats = Snapshot::read(sim.collisions().unwrap()).unwrap().stats();
    no_gl_error(&ctx);
    stats
}

/// Rows-only sorting finds the collisions of one release as the full sort does when the
/// release shares a row; with random phases the release is spread over the rows and rows-only
/// sorting finds almost nothing.
#[test]
fn rows_only_sorting_finds_a_release_s_collisions() {
    let full = found_after_first_release("");
    let rows = found_after_first_release("rows_only = 1");
    let random = found_after_first_release("rows_only = 1\nrow_phases = false");
    eprintln!("full {full:?}\nrows {rows:?}\nrandom {random:?}");
    assert_eq!(rows.particles, 16);
    assert!(full.pairs_true >= 8, "{full:?}");
    assert_eq!(rows.pairs_true, full.pairs_true);
    assert_eq!((rows.found, rows.missed), (full.found, full.missed));
    assert!(
        random.found < rows.found,
        "random {random:?}\nrows {rows:?}"
    );
}

/// A particle's place in a layout: its position's bits.
fn bits(p: [f32; 3]) -> [u32; 3] {
    p.map(f32::to_bits)
}

/// Particle `i`'s position in RGBA texels `v`.
fn at(v: &[f32], i: usize) -> [f32; 3] {
    [v[i * 4], v[i * 4 + 1], v[i * 4 + 2]]
}

/// The cell of lattice `l` that holds `p` (clamped to the lattice).
fn lattice_cell(l: &texflow::sim::collide::Lattice, p: [f32; 3]) -> Vec<u32> {
    (0..3)
        .map(|d| {
            let v = ((p[d] - l.origin[d]) / l.spacing).floor();
            v.clamp(0.0, (l.dims[d] - 1) as f32) as u32
        })
        .collect()
}

/// The pairs the lattices found, named by the first layout's indices (smaller first).
fn found_pairs(
    lattices: &[&LatticeSnapshot],
    place: &[HashMap<[u32; 3], usize>],
) -> HashSet<(usize, usize)> {
    let mut found = HashSet::new();
    for (g, l) in lattices.iter().enumerate() {
        for i in 0..1024 {
            let raw = l.partners[i * 4 + 3];
            if raw >= 0.0 {
                let x = place[0][&bits(at(&l.positions, i))];
                let y = place[0][&bits(at(&l.positions, raw as usize))];
                found.insert((x.min(y), x.max(y)));
                assert!(g < 2);
            }
        }
    }
    found
}

/// Every overlapping pair (by brute force) and the cause of each one missed, in the layout of
/// the lattice that could have found it: adjacent cells, other row, far along the row, a closer
/// partner.
fn brute_force_causes(
    lattices: &[&LatticeSnapshot],
    place: &[HashMap<[u32; 3], usize>],
    found: &HashSet<(usize, usize)>,
) -> ([usize; 4], usize) {
    let a = &lattices[0].positions;
    let (w, k) = (32usize, 4usize);
    let mut causes = [0usize; 4]; // adjacent, other row, far, closer
    let mut pairs = 0;
    for i in 0..1024 {
        for j in i + 1..1024 {
            let (p, q) = (at(a, i), at(a, j));
            let d: f32 = (0..3).map(|c| (p[c] - q[c]).powi(2)).sum::<f32>().sqrt();
            if d >= 0.06 {
                continue;
            }
            pairs += 1;
            if found.contains(&(i, j)) {
                continue;
            }
            let idx: Vec<(usize, usize)> =
                place.iter().map(|m| (m[&bits(p)], m[&bits(q)])).collect();
            if idx
                .iter()
                .any(|&(x, y)| x / w == y / w && x.abs_diff(y) <= k)
            {
                causes[3] += 1;
            } else if let Some(g) = (0..lattices.len()).find(|&g| {
                lattice_cell(&lattices[g].lattice, p) == lattice_cell(&lattices[g].lattice, q)
            }) {
                let (x, y) = idx[g];
                causes[if x / w != y / w { 1 } else { 2 }] += 1;
            } else {
                causes[0] += 1;
            }
        }
    }
    (causes, pairs)
}

/// collide-stats' attribution of misses against a brute-force classification of a small random
/// gas: all pairs by brute force, each particle found in each lattice's layout by its position,
/// and each missed pair classified in the layout of the lattice that could have found it.
#[test]
fn miss_causes_match_a_brute_force_classification() {
    let ctx = context();
    let s = collide_scene(
        [32, 32],
        "[collisions]\nradius = 0.03\nneighbours = 4\nbounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]",
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    set(&mut sim, &random_gas(1024, 9, 0.0, 1.0));
    sim.run(texflow::sim::Stage::Collide).unwrap();
    let snap = Snapshot::read(sim.collisions().unwrap()).unwrap();
    let stats = snap.stats();
    no_gl_error(&ctx);
    let lattices: Vec<_> = std::iter::once(&snap.first).chain(&snap.second).collect();
    // Each particle's place in every layout, by position (the first layout names particles).
    let place: Vec<HashMap<[u32; 3], usize>> = lattices
        .iter()
        .map(|l| (0..1024).map(|i| (bits(at(&l.positions, i)), i)).collect())
        .collect();
    let found = found_pairs(&lattices, &place);
    let (causes, pairs) = brute_force_causes(&lattices, &place, &found);
    eprintln!("{pairs} pairs; brute-force causes {causes:?}; {stats:?}");
    assert_eq!(stats.pairs_true, pairs);
    assert!(
        causes.iter().sum::<usize>() > 20,
        "too few misses to test: {causes:?}"
    );
    assert_eq!(
        [
            stats.missed_adjacent_cells,
            stats.missed_other_row,
            stats.missed_far_along_row,
            stats.missed_closer_partner
        ],
        causes
    );
}

/// E4 reports what it found: its record carries the fraction of overlapping pairs, and the
/// markdown table prints it beside the fps.
#[test]
fn e4_reports_the_fraction_of_pairs_found() {
    use texflow::bench::scenes::{bench_scenes, markdown, ScenesOptions};
    let ctx = context();
    let opts = ScenesOptions {
        repeats: 1,
        warmup_frames: Some(60),
        resolution: Some([64, 64]),
        experiments: vec!["E4".into()],
        ..ScenesOptions::default()
    };
    let records = bench_scenes(&ctx, &[32], &opts, |_, _| {}).expect("bench");
    let e4 = records.iter().find(|r| r.experiment == "E4").unwrap();
    let f = e4.pairs_found.expect("E4 measures the pairs it found");
    assert!((0.0..=1.0).contains(&f), "{e4:?}");
    assert!(e4.pairs_true.is_some());
    assert!(markdown(&records).contains("% of pairs found"));
    no_gl_error(&ctx);
}

/// Bad `[collisions]` keys of the new modes are errors that name the key and the fix.
#[test]
fn exact_mode_settings_are_validated() {
    let base = scene::load_source("collide").unwrap().1;
    for (extra, want) in [
        ("detection = \"exact\"\nrows_only = 1", "remove rows_only"),
        ("detection = \"exact\"\ncell = 0.01", "at least radius"),
        ("detection = \"exakt\"", "expected `uberflow` or `exact`"),
        ("iterations = 0", "iterations must lie in 1..=16"),
    ] {
        let src = base
            .replace("cell = 0.024\n", "")
            .replace("staggered = true", &format!("staggered = true\n{extra}"));
        let err = scene::parse("bad.toml", &src).expect_err(extra).to_string();
        assert!(
            err.contains(want) && err.contains("bad.toml:"),
            "{extra}: {err}"
        );
    }
}

/// Restitution 1 in `gas` (16,384 spheres, elastic walls): kinetic energy within 1 % over 100
/// steps in both detection modes (UberFlow's, and the exact one at a cell its search can walk).
/// Before, the projection after the response stopped what it pushed into a wall instead of
/// bouncing it, and UberFlow's mode lost 1.05 %.
#[test]
fn elastic_gas_keeps_its_energy_in_both_modes() {
    for extra in [
        &[][..],
        &["--detection", "exact", "--set", "collisions.cell=0.016"][..],
    ] {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_texflow"))
            .args(["collide-stats", "gas", "--steps", "100", "--json"])
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
        let e = v
            .pointer("/records/kinetic_energy")
            .and_then(|e| e.as_array())
            .unwrap_or_else(|| panic!("no kinetic_energy in {v}"));
        let (e0, e1) = (e[0].as_f64().unwrap(), e[1].as_f64().unwrap());
        assert!(
            ((e1 - e0) / e0).abs() < 0.01,
            "{extra:?}: kinetic energy {e0} J -> {e1} J"
        );
    }
}

/// The benchmarks' pair census (`CollisionStage::census`) counts what the full statistics count:
/// the same overlapping pairs, and of them the ones found, in both detection modes.
#[test]
fn census_agrees_with_the_full_statistics() {
    let ctx = context();
    for (detection, seed) in [("staggered = true", 5u32), ("detection = \"exact\"", 6)] {
        let s = collide_scene(
            [32, 32],
            &format!(
                "[collisions]\nradius = 0.05\n{detection}\n\
                 bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]"
            ),
        );
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        set(&mut sim, &random_gas(1000, seed, 0.0, 1.0));
        sim.run(texflow::sim::Stage::Collide).unwrap();
        let stage = sim.collisions().unwrap();
        let census = stage.census().unwrap();
        let stats = Snapshot::read(stage).unwrap().stats();
        eprintln!(
            "{detection}: {census:?}; statistics: {} pairs, {} missed",
            stats.pairs_true, stats.missed
        );
        assert!(stats.pairs_true > 50, "{detection}: {stats:?}");
        assert_eq!(census.pairs, stats.pairs_true, "{detection}");
        assert_eq!(
            census.found,
            stats.pairs_true - stats.missed.min(stats.pairs_true),
            "{detection}: {stats:?}"
        );
        no_gl_error(&ctx);
    }
}
