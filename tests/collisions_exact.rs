//! The exact mode keeps its promises: every iteration finds every pair (each one sorts again),
//! restitution 1 keeps kinetic energy, each particle collides with its own mass, and a cell whose
//! runs could overflow the search is refused with the largest that fits.

mod common;

use common::scene::{brute_counts, random_gas};
use common::{context, no_gl_error};
use texflow::report::collide_iterations::energy_momentum;
use texflow::scene;
use texflow::sim::ParticleSim;

fn gas_scene(collisions: &str, emitter: &str) -> scene::SceneFile {
    let src = format!(
        r#"
name = "gas"
integrator = "euler"
[particles]
size = [16, 16]
[time]
dt = 0.01
[[emitters.initial]]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
{emitter}
[collisions]
radius = 0.04
restitution = 1.0
detection = "exact"
bounds = [[-2.0, -2.0, -2.0], [3.0, 3.0, 3.0]]
{collisions}
"#
    );
    common::scene::parse("test", &src)
}

/// Four iterations of a step on a dense moving gas: each iteration's partner counts equal the
/// all-pairs count of the state that iteration searched (later iterations used to reuse the
/// first sort's cells and miss pairs that had changed cell). Pairs the separation left at
/// contact, 2r to rounding, may count on either side: the count lies between the all-pairs
/// counts at 2r (1 ∓ 1e-5). On the default cell (2r, the 27 cells) and on cells of r and 1.5r
/// (the trimmed walk), each through the cell-start table and the binary search.
#[test]
fn every_exact_iteration_finds_every_pair() {
    let ctx = context();
    for cell in [None, Some(0.04), Some(0.06)] {
        for table in [false, true] {
            let line = cell.map_or(String::new(), |g| format!("cell = {g}"));
            let s = gas_scene(&format!("iterations = 4\n{line}"), "");
            let trimmed = texflow::sim::collide::CellTables::of(&s).collisions_trimmed;
            assert_eq!(trimmed, cell.is_some(), "{cell:?}");
            let sim = texflow::sim::collide::cells::with_search(table, || {
                ParticleSim::new(&ctx, &s, 1).unwrap()
            });
            let gas = random_gas(256, 7, 4.0, 0.6);
            every_iteration_finds_every_pair(sim, &gas, &format!("cell {cell:?}, table {table}"));
        }
    }
    no_gl_error(&ctx);
}

/// The count pass takes the particles in tiles of 16 × 16 pixels (`walk_order`) and writes in
/// that order: in a 32 × 64 state (two tiles a row, four rows of them) with 1,900 live
/// particles among 2,048 texels at the dense gas's density, and in an 8 × 64 one (narrower than
/// a tile: sorted order), every iteration's counts, read back in sorted order, equal all pairs'.
#[test]
fn counts_in_tiles_find_every_pair() {
    let ctx = context();
    for (size, tiled) in [([32, 64], true), ([8, 64], false)] {
        let mut s = gas_scene("iterations = 4", "");
        s.resize_particles(size);
        assert_eq!(texflow::sim::collide::walk_order::tiled(size), tiled);
        let sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        let n = size[0] as usize * size[1] as usize * 1900 / 2048;
        let extent = 0.6 * (n as f32 / 256.0).cbrt();
        every_iteration_finds_every_pair(sim, &random_gas(n, 7, 4.0, extent), &format!("{size:?}"));
    }
    no_gl_error(&ctx);
}

/// Three steps of `sim` on the dense `gas`, every iteration's counts against all pairs.
fn every_iteration_finds_every_pair(
    mut sim: ParticleSim,
    gas: &[([f32; 3], [f32; 3])],
    case: &str,
) {
    common::set_particles(&mut sim, gas, |i, n| (i as f32 + 0.5) / n as f32);
    sim.collisions_mut().unwrap().record_iterations(true);
    let mut later_pairs = 0;
    for step in 0..3 {
        sim.step().unwrap();
        let rec = sim.collisions().unwrap().recorded();
        assert_eq!(rec.len(), 4);
        for (it, r) in rec.iter().enumerate() {
            let lo = brute_counts(&r.positions, 0.08 * (1.0 - 1e-5));
            let hi = brute_counts(&r.positions, 0.08 * (1.0 + 1e-5));
            for (i, c) in r.partners.chunks(4).enumerate() {
                let found = c[0] as usize;
                assert!(
                    (lo[i]..=hi[i]).contains(&found),
                    "{case}: step {step}, iteration {}, particle {i}: {found} found, {} true",
                    it + 1,
                    lo[i]
                );
            }
            if it > 0 {
                later_pairs += lo.iter().sum::<usize>() / 2;
            }
        }
    }
    assert!(
        later_pairs > 20,
        "{case}: later iterations saw only {later_pairs} pairs"
    );
}

/// Restitution 1 without walls: kinetic energy is kept (to rounding) and momentum conserved, in
/// a gas where many particles touch two or more others at once.
#[test]
fn elastic_exact_collisions_keep_kinetic_energy() {
    let ctx = context();
    // The 27 cells, and the trimmed walk on a cell of r.
    for (iterations, cell) in [(1, 0.08), (3, 0.08), (3, 0.04)] {
        let s = gas_scene(&format!("iterations = {iterations}\ncell = {cell}"), "");
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        common::set_particles(&mut sim, &random_gas(256, 3, 2.0, 0.6), |i, n| {
            (i as f32 + 0.5) / n as f32
        });
        let (e0, p0) = energy_momentum(&sim).unwrap();
        for _ in 0..40 {
            sim.step().unwrap();
        }
        let (e1, p1) = energy_momentum(&sim).unwrap();
        let scale = (2.0 * e0 * 256.0).sqrt();
        assert!(
            ((e1 - e0) / e0).abs() < 1e-4,
            "{iterations} iterations, cell {cell}: energy {e0} -> {e1}"
        );
        for k in 0..3 {
            assert!(
                (p1[k] - p0[k]).abs() < 1e-5 * scale,
                "momentum {p0:?} -> {p1:?}"
            );
        }
    }
    no_gl_error(&ctx);
}

/// With `mass_range` the response weighs each particle by its own mass: momentum Σ m v with
/// those masses is conserved, and energy is kept, which one mass for all would not give.
#[test]
fn collisions_use_each_particle_s_own_mass() {
    let ctx = context();
    let s = gas_scene("", "mass_range = [0.5, 8.0]");
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    common::set_particles(&mut sim, &random_gas(256, 5, 2.0, 0.6), |i, n| {
        (i as f32 + 0.5) / n as f32
    });
    let (e0, p0) = energy_momentum(&sim).unwrap();
    for _ in 0..30 {
        sim.step().unwrap();
    }
    let (e1, p1) = energy_momentum(&sim).unwrap();
    let scale = (2.0 * e0 * 256.0 * 8.0).sqrt();
    for k in 0..3 {
        assert!(
            (p1[k] - p0[k]).abs() < 1e-5 * scale,
            "momentum {p0:?} -> {p1:?}"
        );
    }
    assert!(((e1 - e0) / e0).abs() < 1e-4, "energy {e0} -> {e1}");
    no_gl_error(&ctx);
}

/// A cell whose run of three could hold more non-overlapping spheres than the search walks is
/// refused, naming the largest cell that fits; that cell is accepted.
#[test]
fn an_exact_cell_too_large_is_refused_with_the_largest_that_fits() {
    let largest = scene::largest_exact_cell(0.04);
    assert!((largest / 0.04 - 2.96).abs() < 0.01, "{largest}");
    assert!(scene::run_capacity(largest, 0.04) <= scene::EXACT_SCAN as f64);
    let src = |cell: f32| {
        format!(
            "name = \"g\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
             dt = 0.01\n[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n[collisions]\n\
             radius = 0.04\ndetection = \"exact\"\ncell = {cell}\n\
             bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\n"
        )
    };
    let err = scene::parse("big.toml", &src(0.32))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("big.toml:") && err.contains(&format!("at most {largest:.6} m")),
        "{err}"
    );
    scene::parse("ok.toml", &src(largest)).unwrap();
    // Down to the radius the trimmed walk takes any cell (its runs cover x ± 2r, far under the
    // bound); below it, a lattice finer than the walk is built for is refused.
    for g in [0.04, 0.05, 0.079] {
        assert!(
            scene::run_capacity(g, 0.04) <= scene::EXACT_SCAN as f64,
            "{g}"
        );
        scene::parse("fine.toml", &src(g)).unwrap();
    }
    let err = scene::parse("small.toml", &src(0.03))
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("small.toml:") && err.contains("at least radius = 0.04 m"),
        "{err}"
    );
}

/// Searches that hit their bound are counted on the GPU over the run (one texel read back at
/// the end): the count equals the sum of the flags that each iteration's count pass wrote, read
/// back iteration by iteration; and `render` warns once and puts it in its JSON.
#[test]
fn truncated_searches_are_counted_over_the_run_and_reported() {
    let ctx = context();
    // 256 particles born on one point: every run of cells holds all of them, past the bound.
    let s = gas_scene("iterations = 2", "");
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    sim.collisions_mut().unwrap().record_iterations(true);
    let mut flagged = 0u64;
    for _ in 0..3 {
        sim.step().unwrap();
        for r in sim.collisions().unwrap().recorded() {
            flagged += r.partners.chunks(4).filter(|t| t[1] > 0.5).count() as u64;
        }
    }
    let tallied = sim.collisions().unwrap().truncated_searches().unwrap();
    assert!(flagged > 0, "the cluster should truncate");
    assert_eq!(tallied, flagged);
    // A gas the search can walk: nothing counted.
    let s = gas_scene("", "shape = \"box\"\nsize = [4.0, 4.0, 4.0]");
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    sim.step().unwrap();
    assert_eq!(sim.collisions().unwrap().truncated_searches().unwrap(), 0);
    no_gl_error(&ctx);

    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("cluster.toml");
    let src = "name = \"cluster\"\n[particles]\nsize = [16, 16]\n[time]\ndt = 0.01\n\
               [[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n[collisions]\nradius = 0.04\n\
               detection = \"exact\"\nbounds = [[-2.0, -2.0, -2.0], [3.0, 3.0, 3.0]]\n\
               [render]\nresolution = [32, 32]\n";
    std::fs::write(&file, src).unwrap();
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args(["render"])
        .arg(&file)
        .args(["--frames", "2", "--json", "--quiet", "--out"])
        .arg(dir.path().join("frames"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let n = v
        .pointer("/records/truncated_searches")
        .and_then(|n| n.as_u64());
    assert!(n.is_some_and(|n| n > 0), "{v}");
    assert_eq!(err.matches("exact collision search").count(), 1, "{err}");
}
