//! The cell-start table of the exact neighbour search (`src/sim/collide/cells.rs`): read back,
//! it holds for every cell the CPU's lower bound of the cell over the sorted keys read back
//! (dead particles, empty cells and a crowded cell among them); and a search with the table
//! leaves the same state, bit for bit, as the binary search it replaces, in the exact collision
//! detection, the DEM response and the fluid.

mod common;

use common::scene::random_gas;
use common::{context, no_gl_error};
use texflow::scene;
use texflow::sim::collide::cells::{uses_table, with_search, Walk, TABLE_MAX_CELLS};
use texflow::sim::ParticleSim;

/// A 16×16 exact-collision scene on a lattice of 10³ cells of 0.1 over [0, 1)³, one iteration
/// (the table read back is that of the state the step's integration left).
fn exact_scene() -> scene::SceneFile {
    common::scene::parse(
        "cell table",
        r#"
name = "cell table"
integrator = "euler"
[particles]
size = [16, 16]
[time]
dt = 0.01
[[emitters.initial]]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
[collisions]
radius = 0.04
restitution = 0.9
detection = "exact"
cell = 0.1
bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]
"#,
    )
}

/// 150 particles of a gas over the lower half of the box (the upper cells stay empty), 80 more
/// crowded into one cell (more than the search's bound), the rest of the 256 texels dead.
fn particles() -> Vec<([f32; 3], [f32; 3])> {
    let mut p = random_gas(150, 3, 2.0, 0.5);
    let crowd = random_gas(80, 5, 0.5, 0.08);
    p.extend(
        crowd
            .into_iter()
            .map(|(x, v)| ([x[0] + 0.71, x[1] + 0.11, x[2] + 0.31], v)),
    );
    assert!(80 > scene::EXACT_SCAN as usize);
    p
}

/// The first index of `keys` (no NaN among them) not below `c`, by a linear scan.
fn lower_bound(keys: &[f32], c: f32) -> usize {
    keys.iter().position(|&k| k >= c).unwrap_or(keys.len())
}

fn simulation(ctx: &texflow::gl::Context, s: &scene::SceneFile) -> ParticleSim {
    let mut sim = ParticleSim::new(ctx, s, 1).unwrap();
    common::set_particles(&mut sim, &particles(), |i, n| (i as f32 + 0.5) / n as f32);
    sim
}

#[test]
fn the_table_holds_the_lower_bound_of_every_cell() {
    let ctx = context();
    let mut sim = simulation(&ctx, &exact_scene());
    for step in 0..3 {
        sim.step().unwrap();
        let c = sim.collisions().unwrap();
        let keys = c.read_sorted_keys().unwrap().unwrap();
        let table = c.search().unwrap().read_table().unwrap().unwrap();
        assert_eq!(table.len(), 1000 + 1);
        assert!(keys.iter().all(|k| !k.is_nan()), "step {step}");
        let dead = keys.iter().filter(|k| **k == f32::INFINITY).count();
        assert_eq!(dead, 256 - 230, "step {step}");
        let mut empty = 0;
        let mut crowded = 0;
        for (cell, &start) in table.iter().enumerate() {
            let want = lower_bound(&keys, cell as f32);
            assert_eq!(start, want as f32, "step {step}, cell {cell}");
            if cell < 1000 {
                let n = lower_bound(&keys, (cell + 1) as f32) - want;
                empty += (n == 0) as usize;
                crowded += (n > scene::EXACT_SCAN as usize) as usize;
            }
        }
        // The sentinel ends the live particles; the state holds both kinds of cell.
        assert_eq!(table[1000], 230.0);
        assert!(empty > 500, "{empty} empty cells");
        // The crowd is still in its cell after the first step's integration (separated after).
        if step == 0 {
            assert_eq!(crowded, 1);
        }
    }
    no_gl_error(&ctx);
}

/// `steps` steps of `s` from `set` with the table and with the binary search: the positions
/// and velocities after them, and whether each searched with the table.
fn both_searches(
    ctx: &texflow::gl::Context,
    s: &scene::SceneFile,
    steps: usize,
    set: impl Fn(&mut ParticleSim),
) -> [(Vec<f32>, Vec<f32>, bool); 2] {
    let run = |sim: &mut ParticleSim| {
        set(sim);
        for _ in 0..steps {
            sim.step().unwrap();
        }
        let table = match (sim.collisions(), sim.fluid()) {
            (Some(c), _) => c.search().unwrap().has_table(),
            (None, Some(f)) => f.search().has_table(),
            (None, None) => panic!("no search"),
        };
        let x = sim.read_positions().unwrap();
        let v = sim.read_velocities().unwrap();
        (x, v, table)
    };
    // The table forced: the built-in scenes' lattices at 16×16 have more cells than the rule
    // takes a table for.
    let mut with = with_search(true, || ParticleSim::new(ctx, s, 1).unwrap());
    let mut without = with_search(false, || ParticleSim::new(ctx, s, 1).unwrap());
    [run(&mut with), run(&mut without)]
}

fn assert_same_bits(label: &str, a: &[f32], b: &[f32]) {
    assert_eq!(a.len(), b.len());
    for (i, (x, y)) in a.iter().zip(b).enumerate() {
        assert_eq!(
            x.to_bits(),
            y.to_bits(),
            "{label}: float {i}: {x} against {y}"
        );
    }
}

fn assert_same_runs(name: &str, runs: [(Vec<f32>, Vec<f32>, bool); 2]) {
    let [(x1, v1, t1), (x2, v2, t2)] = runs;
    assert!(t1 && !t2, "{name}: the table in the first run only");
    assert_same_bits(&format!("{name} positions"), &x1, &x2);
    assert_same_bits(&format!("{name} velocities"), &v1, &v2);
    // The runs moved: a comparison of untouched states would prove nothing.
    assert!(v1.iter().any(|v| *v != 0.0), "{name}: nothing moves");
}

#[test]
fn the_table_and_the_binary_search_give_the_same_state() {
    let ctx = context();
    let s = exact_scene();
    let runs = both_searches(&ctx, &s, 6, |sim| {
        common::set_particles(sim, &particles(), |i, n| (i as f32 + 0.5) / n as f32)
    });
    assert_same_runs("exact", runs);
    // The trimmed walk (a cell of 1.25 r, below 2 r) reads the same runs from either.
    let mut s = exact_scene();
    s.collisions.as_mut().unwrap().cell = Some(0.05);
    let runs = both_searches(&ctx, &s, 6, |sim| {
        common::set_particles(sim, &particles(), |i, n| (i as f32 + 0.5) / n as f32)
    });
    assert_same_runs("exact, trimmed", runs);
    for name in ["dem", "dam"] {
        let mut s = scene::load(name).unwrap();
        s.particles.size = [16, 16];
        assert_same_runs(name, both_searches(&ctx, &s, 6, |_| {}));
    }
    no_gl_error(&ctx);
}

#[test]
fn a_lattice_far_larger_than_the_state_keeps_the_binary_search() {
    // 256 entries: up to 8 cells each take the table for the 27 cells, up to 32 for the
    // fluid's trimmed walk, more keep the binary search.
    assert!(uses_table(2048, 256, Walk::Cells27));
    assert!(!uses_table(2049, 256, Walk::Cells27));
    let fluid = Walk::Fluid { trimmed: true };
    assert!(uses_table(8192, 256, fluid));
    assert!(!uses_table(8193, 256, fluid));
    // A million entries: up to the table's size.
    assert!(uses_table(TABLE_MAX_CELLS, 1 << 20, Walk::Cells27));
    assert!(!uses_table(TABLE_MAX_CELLS + 1, 1 << 20, fluid));
    assert!(!with_search(true, || uses_table(
        TABLE_MAX_CELLS + 1,
        1 << 20,
        Walk::Cells27
    )));
    let ctx = context();
    let mut s = exact_scene();
    // 20³ cells of 0.1 over [0, 2)³: more than 8 per entry.
    s.collisions.as_mut().unwrap().bounds[1] = [2.0; 3];
    let sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    assert!(!sim.collisions().unwrap().search().unwrap().has_table());
    let plan = common::plan_of(&ctx, &s);
    let text = format!("{:?}", plan.passes);
    assert!(text.contains("too large for a cell-start table"), "{text}");
    assert!(!text.contains("cell start:"), "{text}");
    no_gl_error(&ctx);
}

/// `fluid.cell = "auto"` takes cells of h from 262,144 placed particles (the box emitters'
/// lattice points, at most the texels), else 2h; the walk is trimmed on cells of h only, and
/// the pass list names the cell.
#[test]
fn the_fluid_lattice_follows_its_particle_count() {
    let dam = |size: u32, cell: &str| {
        let mut s = scene::load("dam").unwrap();
        // A box of 64 × 128 × 128 lattice points (the million-particle dam's).
        let f = s.fluid.as_mut().unwrap();
        f.spacing = 0.003125;
        f.smoothing = None;
        f.bounds = [[0.0; 3], [0.8, 0.6, 0.4]];
        f.cell = match cell {
            "h" => scene::FluidCell::H,
            "2h" => scene::FluidCell::TwoH,
            _ => scene::FluidCell::Auto,
        };
        s.emitters.initial[0].size = [0.2, 0.4, 0.4];
        s.particles.size = [size, size];
        s
    };
    for (size, cell, placed, fine) in [
        (256, "auto", 65_536, false),
        (512, "auto", 262_144, true),
        (1024, "auto", 1_048_576, true),
        (1024, "2h", 1_048_576, false),
        (256, "h", 65_536, true),
    ] {
        let s = dam(size, cell);
        assert_eq!(scene::fluid_particles(&s), placed, "{size} {cell}");
        let l = texflow::sim::fluid::lattice_of(&s);
        let h = s.fluid.as_ref().unwrap().h();
        assert_eq!(l.spacing, if fine { h } else { 2.0 * h }, "{size} {cell}");
        assert_eq!(l.walk, Walk::Fluid { trimmed: fine }, "{size} {cell}");
        let d = texflow::sim::collide::cells::search_defines(&Vec::new(), &l, s.particles.size);
        let trim = ("SEARCH_TRIM".to_string(), "1".to_string());
        assert_eq!(d.contains(&trim), fine, "{d:?}");
    }
    // The built-in dam (4,096 particles) keeps cells of 2h, and says so.
    let ctx = context();
    let plan = common::plan_of(&ctx, &scene::load("dam").unwrap());
    let text = format!("{:?}", plan.passes);
    assert!(text.contains("lattice of cell 2h"), "{text}");
    no_gl_error(&ctx);
}
