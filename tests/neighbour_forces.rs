//! Neighbour forces over the sorted grid (UberFlow §6): the summed force per particle that the
//! GPU's force pass writes equals an all-pairs CPU twin of the same formulas (NVIDIA's DEM
//! contact force, and a user's `[[forces.pair]]` hook reading position, velocity, type and mass),
//! at several densities; the velocity pass adds F / m dt; bad scenes and bad hooks are refused.
//!
//! The exact search walks at most `EXACT_SCAN` (64) particles per run of three cells. Each test
//! gas is checked on the CPU to stay under it: its largest run of three cells is counted from
//! the positions the GPU searched, and must be at most 64 (the densest here holds about half).

mod common;

use common::{context, no_gl_error};
use texflow::scene;
use texflow::sim::collide::{Lattice, NeighbourReadback};
use texflow::sim::ParticleSim;

const RADIUS: f32 = 0.04;
/// The lattice's cell, 2.5 r: the reach of the pair hook, under the exact search's largest cell.
const CELL: f32 = 0.1;
const SPRING: f32 = 300.0;
const DAMPING: f32 = 0.7;
const SHEAR: f32 = 0.4;
const ATTRACTION: f32 = 50.0;
const MASS: [[f32; 2]; 2] = [[0.5, 2.0], [1.0, 3.0]];

/// A hook that reads every input it is given, so that a wrong one shows in the sum.
const HOOK: &str = "vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, vec3 vj,\n\
                    int type_j, float mass_j, float distance) {\n\
                    float s = float(type_j + 1) * mass_j - 0.25 * float(type) * mass;\n\
                    return s * (xj - x) + 0.3 * distance * (vj - v);\n\
                    }\n";

/// One particle as the hook sees it: position, velocity, type, mass.
struct Seen {
    x: [f32; 3],
    v: [f32; 3],
    ty: f32,
    m: f32,
}

/// The twin of HOOK, on `a` from `b`.
fn hook_cpu(a: &Seen, b: &Seen) -> [f64; 3] {
    let d = dist(a.x, b.x);
    let s = (b.ty as f64 + 1.0) * b.m as f64 - 0.25 * a.ty as f64 * a.m as f64;
    [0, 1, 2].map(|k| s * (b.x[k] - a.x[k]) as f64 + 0.3 * d * (b.v[k] - a.v[k]) as f64)
}

fn dist(a: [f32; 3], b: [f32; 3]) -> f64 {
    (0..3)
        .map(|k| ((b[k] - a[k]) as f64).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// NVIDIA's collideSpheres, on A from B (the twin of glsl/collide/dem.glsl), in f64.
fn dem_cpu(xa: [f32; 3], va: [f32; 3], xb: [f32; 3], vb: [f32; 3]) -> [f64; 3] {
    let d: [f64; 3] = [0, 1, 2].map(|k| (xb[k] - xa[k]) as f64);
    let l = dist(xa, xb);
    let reach = 2.0 * RADIUS as f64;
    if l >= reach || l == 0.0 {
        return [0.0; 3];
    }
    let n = d.map(|c| c / l);
    let u: [f64; 3] = [0, 1, 2].map(|k| (vb[k] - va[k]) as f64);
    let un: f64 = (0..3).map(|k| u[k] * n[k]).sum();
    [0, 1, 2].map(|k| {
        -SPRING as f64 * (reach - l) * n[k]
            + DAMPING as f64 * u[k]
            + SHEAR as f64 * (u[k] - un * n[k])
            + ATTRACTION as f64 * d[k]
    })
}

fn gas_scene(pair: Option<&str>) -> scene::SceneFile {
    gas_scene_in(pair, CELL)
}

/// The test gas on a lattice of cell `cell`.
fn gas_scene_in(pair: Option<&str>, cell: f32) -> scene::SceneFile {
    let src = format!(
        r#"
name = "neighbours"
integrator = "euler"
[particles]
size = [16, 16]
[time]
dt = 0.001
[[emitters.initial]]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
mass_range = {:?}
[[emitters.initial]]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
mass_range = {:?}
{}
[collisions]
radius = {RADIUS}
cell = {cell}
detection = "exact"
response = "dem"
bounds = [[-1.0, -1.0, -1.0], [2.0, 2.0, 2.0]]
[collisions.dem]
spring = {SPRING}
damping = {DAMPING}
shear = {SHEAR}
attraction = {ATTRACTION}
"#,
        MASS[0],
        MASS[1],
        match pair {
            Some(path) => format!("[[forces.pair]]\nglsl = {path:?}\nradius = {CELL}\n"),
            None => String::new(),
        }
    );
    scene::parse("test", &src).unwrap_or_else(|e| panic!("{e}\n{src}"))
}

/// 256 particles in a cube of side `side`, moving, of both types, with random static numbers
/// (so the masses spread over the ranges).
fn upload_gas(sim: &mut ParticleSim, side: f32, seed: u32) {
    let mut rng = texflow::sim::emit::Rng::new(seed, 0, 11);
    let n = 256;
    let (mut pos, mut vel, mut st) = (vec![0.0; n * 4], vec![0.0; n * 4], vec![0.0; n * 4]);
    for i in 0..n {
        let p = [0; 3].map(|_| rng.uniform() * side);
        let v = [0; 3].map(|_| rng.uniform() - 0.5);
        pos[i * 4..i * 4 + 4].copy_from_slice(&[p[0], p[1], p[2], 1.0]);
        vel[i * 4..i * 4 + 3].copy_from_slice(&v);
        st[i * 4 + 1] = (i % 2) as f32;
        st[i * 4 + 3] = rng.uniform();
    }
    sim.set_state(&pos, &vel, &st).unwrap();
}

/// The mass of a particle of type `ty` with static random number `r` (common/mass.glsl).
fn mass(ty: f32, r: f32) -> f32 {
    let [lo, hi] = MASS[ty as usize];
    lo + (hi - lo) * (4096.0 * r).fract()
}

struct Twin {
    /// Largest |F_gpu - F_cpu| / Σ_j |F_ij| over the particles with a neighbour.
    worst: f64,
    /// Mean neighbours closer than 2 r per particle.
    contacts: f64,
    /// Largest run of three cells.
    run: usize,
}

/// All pairs on the CPU against the GPU's summed force of `r` (both in the gathered order).
fn twin(r: &NeighbourReadback, hook: bool) -> Twin {
    let n = r.positions.len() / 4;
    let at = |a: &[f32], i: usize| [a[i * 4], a[i * 4 + 1], a[i * 4 + 2]];
    let live = |i: usize| r.positions[i * 4 + 3] > 0.0;
    let mut worst = 0.0f64;
    let mut contacts = 0usize;
    let mut lives = 0usize;
    for i in (0..n).filter(|&i| live(i)) {
        lives += 1;
        let seen = |i: usize| Seen {
            x: at(&r.positions, i),
            v: at(&r.velocities, i),
            ty: r.statics[i * 4 + 1],
            m: mass(r.statics[i * 4 + 1], r.statics[i * 4 + 3]),
        };
        let a = seen(i);
        let mut f = [0.0f64; 3];
        let mut scale = 0.0f64;
        let mut near = 0;
        for j in (0..n).filter(|&j| j != i && live(j)) {
            let b = seen(j);
            let d = dist(a.x, b.x);
            let mut terms = vec![dem_cpu(a.x, a.v, b.x, b.v)];
            if d < 2.0 * RADIUS as f64 {
                near += 1;
            }
            if hook && d < CELL as f64 {
                terms.push(hook_cpu(&a, &b));
            }
            for t in terms {
                for k in 0..3 {
                    f[k] += t[k];
                }
                scale += t.iter().map(|c| c * c).sum::<f64>().sqrt();
            }
        }
        let g = [0, 1, 2].map(|k| r.forces[i * 4 + k] as f64);
        let err = (0..3).map(|k| (g[k] - f[k]).powi(2)).sum::<f64>().sqrt();
        if scale > 0.0 {
            worst = worst.max(err / scale);
        } else {
            assert_eq!(err, 0.0, "particle {i}: no neighbour, force {g:?}");
        }
        // Contacts at 2r to rounding may count on either side.
        let counted = r.forces[i * 4 + 3] as i64;
        assert!(
            (counted - near).abs() <= 1,
            "particle {i}: {counted} contacts, {near} true"
        );
        contacts += near as usize;
    }
    // The search's limit: the particles of every run of three cells along x.
    let lattice = Lattice {
        origin: glam::Vec3::splat(-1.0),
        spacing: CELL,
        dims: glam::UVec3::splat(30),
        walk: texflow::sim::collide::cells::Walk::Cells27,
    };
    let mut cells = std::collections::HashMap::<u64, usize>::new();
    for i in (0..n).filter(|&i| live(i)) {
        let c = lattice.cell(glam::Vec3::from(at(&r.positions, i)));
        *cells.entry(lattice.key(c)).or_default() += 1;
    }
    let run = (cells.keys())
        .map(|&k| {
            (k.saturating_sub(1)..=k + 1)
                .map(|c| cells.get(&c).copied().unwrap_or(0))
                .sum()
        })
        .max()
        .unwrap_or(0);
    Twin {
        worst,
        contacts: contacts as f64 / lives as f64,
        run,
    }
}

/// The summed DEM force of every particle equals the all-pairs twin's, at four densities from
/// a sparse gas (about 0.5 contacts per particle) to a dense one (about 10).
#[test]
fn dem_force_matches_an_all_pairs_twin_at_several_densities() {
    let ctx = context();
    let mut worst = 0.0f64;
    let mut seen = Vec::new();
    for (k, side) in [1.0f32, 0.65, 0.45, 0.36].into_iter().enumerate() {
        let s = gas_scene(None);
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        upload_gas(&mut sim, side, 3 + k as u32);
        sim.step().unwrap();
        let r = sim
            .collisions()
            .unwrap()
            .read_neighbour_forces(sim.statics())
            .unwrap()
            .unwrap();
        let t = twin(&r, false);
        assert!(
            t.run <= scene::EXACT_SCAN as usize,
            "a run of {} particles",
            t.run
        );
        assert!(t.worst < 1e-5, "side {side}: relative error {}", t.worst);
        worst = worst.max(t.worst);
        seen.push(t.contacts);
        // The velocity pass: v' = v + F / m dt, in the same (gathered) order.
        let v = sim.read_velocities().unwrap();
        for i in (0..256).filter(|&i| r.positions[i * 4 + 3] > 0.0) {
            let m = mass(r.statics[i * 4 + 1], r.statics[i * 4 + 3]);
            for c in 0..3 {
                let want = r.velocities[i * 4 + c] + r.forces[i * 4 + c] / m * 0.001;
                assert!(
                    (v[i * 4 + c] - want).abs() <= 1e-6 * (1.0 + want.abs()),
                    "particle {i}: velocity {} want {want}",
                    v[i * 4 + c]
                );
            }
        }
    }
    println!("densities (contacts per particle) {seen:?}: largest relative error {worst:e}");
    assert!(seen[0] < 1.0 && seen[3] > 6.0, "densities {seen:?}");
    no_gl_error(&ctx);
}

/// On a cell below 2r (1.25 r) the search walks the cells within 2r, trimmed: the DEM force
/// still equals the all-pairs twin's, sparse and dense, through the table and without it.
#[test]
fn dem_force_on_a_trimmed_walk_matches_the_twin() {
    let ctx = context();
    let s = gas_scene_in(None, 1.25 * RADIUS);
    assert!(texflow::sim::collide::CellTables::of(&s).collisions_trimmed);
    for (k, side) in [0.65f32, 0.36].into_iter().enumerate() {
        for table in [false, true] {
            let mut sim = texflow::sim::collide::cells::with_search(table, || {
                ParticleSim::new(&ctx, &s, 1).unwrap()
            });
            upload_gas(&mut sim, side, 11 + k as u32);
            sim.step().unwrap();
            let r = (sim.collisions().unwrap())
                .read_neighbour_forces(sim.statics())
                .unwrap()
                .unwrap();
            let t = twin(&r, false);
            assert!(
                t.worst < 1e-5,
                "side {side}, table {table}: relative error {}",
                t.worst
            );
            assert!(t.contacts > 0.3, "side {side}: {} contacts", t.contacts);
        }
    }
    no_gl_error(&ctx);
}

/// A user's pair hook, called with each neighbour within its radius, reading position, velocity,
/// type and mass of both: the sum with the DEM force equals the twin's, at two densities.
#[test]
fn pair_hook_matches_an_all_pairs_twin() {
    let dir = std::env::temp_dir().join(format!("texflow-pair-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("hook.glsl");
    std::fs::write(&file, HOOK).unwrap();
    let ctx = context();
    for (k, side) in [0.8f32, 0.45].into_iter().enumerate() {
        let s = gas_scene(Some(file.to_str().unwrap()));
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        upload_gas(&mut sim, side, 9 + k as u32);
        sim.step().unwrap();
        let r = sim
            .collisions()
            .unwrap()
            .read_neighbour_forces(sim.statics())
            .unwrap()
            .unwrap();
        let t = twin(&r, true);
        println!(
            "side {side}: {} contacts per particle, relative error {:e}",
            t.contacts, t.worst
        );
        assert!(
            t.run <= scene::EXACT_SCAN as usize,
            "a run of {} particles",
            t.run
        );
        assert!(t.worst < 1e-5, "side {side}: relative error {}", t.worst);
    }
    no_gl_error(&ctx);
    // A hook that does not compile is refused naming its file and line.
    std::fs::write(&file, format!("{HOOK}\nvec3 broken() {{ return 1.0; }}\n")).unwrap();
    let s = gas_scene(Some(file.to_str().unwrap()));
    let err = ParticleSim::new(&ctx, &s, 1).unwrap_err().to_string();
    assert!(err.contains(&format!("{}:7", file.display())), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}

/// The dem response needs the exact detection and a spring the step can integrate; a pair
/// force needs the exact detection and a radius within the cell.
#[test]
fn bad_neighbour_force_scenes_are_refused() {
    let base = "name = \"d\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
                dt = 0.001\n[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n";
    let coll = |extra: &str| {
        format!(
            "{base}{extra}[collisions]\nradius = 0.04\nbounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\n"
        )
    };
    for (src, want) in [
        (
            format!(
                "{}response = \"dem\"\n[collisions.dem]\nspring = 10.0\n",
                coll("")
            ),
            "add detection = \"exact\"",
        ),
        (
            format!("{}detection = \"exact\"\nresponse = \"dem\"\n", coll("")),
            "add [collisions.dem]",
        ),
        (
            format!(
                "{}detection = \"exact\"\nresponse = \"dem\"\n[collisions.dem]\nspring = 8e5\n",
                coll("")
            ),
            "use a spring of at most 5.0000e5 N/m together",
        ),
        (
            format!(
                "{}detection = \"exact\"\n",
                coll("[[forces.pair]]\nglsl = \"a.glsl\"\nradius = 0.2\n")
            ),
            "at most the collision cell 0.08 m",
        ),
        (
            coll("[[forces.pair]]\nglsl = \"a.glsl\"\nradius = 0.05\n"),
            "add [collisions] with detection",
        ),
    ] {
        let err = scene::parse("bad.toml", &src).unwrap_err().to_string();
        assert!(
            err.contains("bad.toml:") && err.contains(want),
            "{want}: {err}"
        );
    }
}

/// A pair force file that is missing, or defines no `pair_force`, is refused at its `glsl` key
/// with the file named, before anything compiles.
#[test]
fn bad_pair_force_files_are_refused_at_their_key() {
    let dir = std::env::temp_dir().join(format!("texflow-pair-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml = dir.join("scene.toml");
    let scene_with = |glsl: &str| {
        let mut src = String::from(
            "name = \"p\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
             dt = 0.001\n[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n\
             [[forces.pair]]\n",
        );
        src += &format!("glsl = \"{glsl}\"\nradius = 0.05\n");
        src += "[collisions]\nradius = 0.04\ndetection = \"exact\"\n\
                bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\n";
        std::fs::write(&toml, src).unwrap();
        scene::load(toml.to_str().unwrap())
    };
    let err = scene_with("missing.glsl").unwrap_err().to_string();
    assert!(
        err.contains("scene.toml:11:") && err.contains("pair force: cannot read"),
        "{err}"
    );
    std::fs::write(dir.join("f.glsl"), "vec3 force(vec3 x) { return x; }\n").unwrap();
    let err = scene_with("f.glsl").unwrap_err().to_string();
    assert!(
        err.contains("scene.toml:11:") && err.contains("defines no `pair_force`"),
        "{err}"
    );
    std::fs::write(dir.join("ok.glsl"), HOOK).unwrap();
    let s = scene_with("ok.glsl").unwrap();
    assert_eq!(s.forces.pair[0].source.as_deref(), Some(HOOK));
    std::fs::remove_dir_all(&dir).ok();
}

/// Without walls or gravity the DEM force is the pairs' own (F_ji = -F_ij): momentum Σ m v,
/// each particle with its own mass, is kept over 200 steps of a dense moving gas, while the
/// dashpot takes kinetic energy out.
#[test]
fn dem_keeps_momentum_and_its_dashpot_takes_energy() {
    let ctx = context();
    let s = gas_scene(None);
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    upload_gas(&mut sim, 0.45, 21);
    let energy_momentum = texflow::report::collide_iterations::energy_momentum;
    let (e0, p0) = energy_momentum(&sim).unwrap();
    for _ in 0..200 {
        sim.step().unwrap();
    }
    let (e1, p1) = energy_momentum(&sim).unwrap();
    // The scale of the momenta that cancel: Σ m |v| ≤ sqrt(2 E Σ m).
    let scale = (2.0 * e0 * 256.0 * 3.0).sqrt();
    let drift = (0..3).map(|k| (p1[k] - p0[k]).abs()).fold(0.0, f64::max) / scale;
    println!("momentum drift {drift:e} of Σ m |v|; kinetic energy {e0} -> {e1} J");
    for k in 0..3 {
        assert!(
            (p1[k] - p0[k]).abs() < 1e-5 * scale,
            "momentum {p0:?} -> {p1:?}"
        );
    }
    assert!(e1 < e0, "kinetic energy {e0} -> {e1}");
    no_gl_error(&ctx);
}
