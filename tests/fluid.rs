//! Weakly compressible SPH (`[fluid]`, src/sim/fluid/) against references texflow did not write:
//! an all-pairs CPU twin of one step in f64 (density, Tait pressure, pressure and viscous forces,
//! the walls' ghost particles made for every pair instead of within the search);
//! the integration pass against `sim::reference`; hydrostatic pressure in a resting column
//! against the weight of the fluid above (ρ g h). The dam break, `render --json` and the
//! refusals: tests/fluid_scenes.rs.

mod common;

use common::fluid::{tank, twin_scene_source};
use common::scene::parse;
use common::{context, no_gl_error};
use glam::Vec3;
use texflow::scene::{self, SceneFile};
use texflow::sim::{ParticleSim, Simulation, Stage};

/// The cubic spline W(r) and dW/dr of smoothing length h (Monaghan 1992), in f64.
fn w(r: f64, h: f64) -> f64 {
    let q = r / h;
    let s = 1.0 / (std::f64::consts::PI * h * h * h);
    if q < 1.0 {
        s * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
    } else if q < 2.0 {
        s * 0.25 * (2.0 - q).powi(3)
    } else {
        0.0
    }
}

fn dw(r: f64, h: f64) -> f64 {
    let q = r / h;
    let s = 1.0 / (std::f64::consts::PI * h.powi(4));
    if q < 1.0 {
        s * (-3.0 * q + 2.25 * q * q)
    } else if q < 2.0 {
        -s * 0.75 * (2.0 - q).powi(2)
    } else {
        0.0
    }
}

/// A plane of a scene: unit normal, offset (n · x = offset on the plane), and whether its
/// ghosts' velocity is reversed (`wall = "no_slip"`) instead of mirrored.
type Plane = (Vec3, f64, bool);

/// The planes of a scene whose ghosts count (none without `fluid.wall_correction`).
fn planes(s: &SceneFile) -> Vec<Plane> {
    let walls = s.fluid.as_ref().is_some_and(|f| f.wall_correction);
    (s.colliders.plane.iter())
        .filter(|_| walls)
        .map(|p| {
            let n = Vec3::from(p.normal).normalize();
            let no_slip = p.wall == scene::Wall::NoSlip;
            (n, n.dot(Vec3::from(p.point)) as f64, no_slip)
        })
        .collect()
}

/// The gravity of the tank scenes (m/s²).
const GRAVITY: [f64; 3] = [0.0, -9.81, 0.0];

fn v3(t: &[f32]) -> [f64; 3] {
    [t[0] as f64, t[1] as f64, t[2] as f64]
}
fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// One particle's density and pressure, and its acceleration with the sum of the magnitudes of
/// the terms (the scale of its rounding) and the acceleration per pascal of error in the
/// pressures (f32 densities carry about 1e-6 of error, which Tait's (ρ/ρ0)^γ − 1 turns into an
/// absolute error of about B γ 1e-6 in every pressure, however small).
struct Twin {
    rho: Vec<f64>,
    p: Vec<f64>,
    a: Vec<[f64; 3]>,
    scale: Vec<f64>,
    per_pascal: Vec<f64>,
}

/// The ghosts of a particle at x with velocity u in the planes closer than 2h to `at`: position,
/// velocity (mirrored, or reversed at a no-slip plane) and the depth the reflection adds under gravity, 2 d (−g · n) (a ghost's
/// pressure exceeds its original's by ρ g times that).
fn ghosts_of(
    walls: &[Plane],
    h: f64,
    at: [f64; 3],
    x: [f64; 3],
    u: [f64; 3],
) -> Vec<([f64; 3], [f64; 3], f64)> {
    (walls.iter())
        .filter(|wl| dot(v3(&wl.0.to_array()), at) - wl.1 < 2.0 * h)
        .map(|wl| {
            let n = v3(&wl.0.to_array());
            let (d, vn) = (dot(n, x) - wl.1, dot(n, u));
            let depth = -2.0 * d * dot(GRAVITY, n);
            let y = [0, 1, 2].map(|k| x[k] - 2.0 * d * n[k]);
            let w = match wl.2 {
                true => u.map(|c| -c),
                false => [0, 1, 2].map(|k| u[k] - 2.0 * vn * n[k]),
            };
            (y, w, depth)
        })
        .collect()
}

/// The CPU twin of the density and force passes over all pairs of live particles of `x`, `v`
/// (RGBA texels), for `f` with the planes `walls`.
fn twin(f: &scene::Fluid, walls: &[Plane], x: &[f32], v: &[f32]) -> Twin {
    let n = x.len() / 4;
    let live: Vec<usize> = (0..n).filter(|&i| x[i * 4 + 3] > 0.0).collect();
    let (h, m, rho0) = (f.h() as f64, f.mass() as f64, f.rest_density as f64);
    let (b, gamma) = (f.stiffness() as f64, f.gamma as f64);
    let pos = |i: usize| v3(&x[i * 4..]);
    let ghosts = |i: usize, x: [f64; 3], u: [f64; 3]| ghosts_of(walls, h, pos(i), x, u);
    let vel = |i: usize| v3(&v[i * 4..]);
    let mut rho = vec![0.0; n];
    let mut p = vec![0.0; n];
    for &i in &live {
        let mut r = 0.0;
        for &j in &live {
            let mut at = vec![pos(j)];
            at.extend(ghosts(i, pos(j), vel(j)).into_iter().map(|g| g.0));
            for y in at {
                let d = sub(pos(i), y);
                r += m * w(dot(d, d).sqrt(), h);
            }
        }
        rho[i] = r;
        p[i] = (b * ((r / rho0).powf(gamma) - 1.0)).max(0.0);
    }
    let mut a = vec![[0.0; 3]; n];
    let mut scale = vec![0.0; n];
    let mut per_pascal = vec![0.0; n];
    let (alpha, c) = (f.viscosity as f64, f.speed_of_sound as f64);
    for &i in &live {
        let pi = p[i] / (rho[i] * rho[i]);
        let mut others = Vec::new();
        for &j in &live {
            others.push((pos(j), vel(j), j, 0.0));
            others.extend(
                ghosts(i, pos(j), vel(j))
                    .into_iter()
                    .map(|g| (g.0, g.1, j, g.2)),
            );
        }
        for (y, u, j, depth) in others {
            let xij = sub(pos(i), y);
            let r = dot(xij, xij).sqrt();
            if r >= 2.0 * h || r == 0.0 {
                continue;
            }
            let mut term = pi + (p[j] + rho[j] * depth) / (rho[j] * rho[j]);
            let vij = sub(vel(i), u);
            let vx = dot(vij, xij);
            if vx < 0.0 {
                let nu = 2.0 * alpha * h * c / (rho[i] + rho[j]);
                term += -nu * vx / (r * r + 0.01 * h * h);
            }
            let k = m * term * dw(r, h) / r;
            for (ak, xk) in a[i].iter_mut().zip(xij) {
                *ak -= k * xk;
            }
            scale[i] += (k * r).abs();
            per_pascal[i] +=
                m * dw(r, h).abs() * (1.0 / (rho[i] * rho[i]) + 1.0 / (rho[j] * rho[j]));
        }
    }
    Twin {
        rho,
        p,
        a,
        scale,
        per_pascal,
    }
}

/// The fluid of the twin: 216 particles (6³ on a lattice of 2 cm) collapsing in the corner of
/// a 24 cm × 12 cm tank, in 256 texels (40 dead), h = 1.2 Δx.
fn twin_scene() -> SceneFile {
    parse("fluid", &twin_scene_source())
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol
}

/// One GPU step after 150 (the column falling and spreading) against the twins: the integration
/// pass against `sim::reference`, the gather as a permutation in cell order, the density pass
/// and the kick against the all-pairs twin.
#[test]
fn one_step_matches_the_cpu_twin() {
    check_twin(twin_scene());
}

/// As above on a lattice of cells of h (the trimmed walk; 216 particles take 2h by default),
/// with the wall treatment and without it: then every particle's force pass visits only the
/// neighbours its density pass marked within 2h.
#[test]
fn one_step_matches_the_cpu_twin_on_cells_of_h() {
    let src = twin_scene_source();
    let k = "smoothing = 0.024";
    assert!(src.contains(k), "{src}");
    // Without the walls' ghosts the column starts compressed (`initial = "hydrostatic"`) and
    // is checked on its first step, while it has pressure.
    for (walls, steps) in [
        ("", 150),
        ("\nwall_correction = false\ninitial = \"hydrostatic\"", 0),
    ] {
        let keys = format!("{k}\ncell = \"h\"{walls}");
        let s = parse("fluid", &src.replace(k, &keys));
        let lattice = texflow::sim::fluid::lattice_of(&s);
        assert_eq!(lattice.spacing, 0.024);
        check_twin_after(s, steps);
    }
}

/// As above with the floor and the wall behind the column no-slip (their ghosts' velocity
/// reversed, `colliders.plane.wall = "no_slip"`), the other three planes free-slip.
#[test]
fn one_step_matches_the_cpu_twin_with_no_slip_walls() {
    let mut src = twin_scene_source();
    for n in ["[0.0, 1.0, 0.0]", "[1.0, 0.0, 0.0]"] {
        let k = format!("normal = {n}\nresilience = 0.0");
        assert!(src.contains(&k), "{k}");
        src = src.replace(&k, &format!("{k}\nwall = \"no_slip\""));
    }
    let s = parse("fluid", &src);
    let no_slip = planes(&s).iter().filter(|p| p.2).count();
    assert_eq!(no_slip, 2, "floor and back wall");
    check_twin(s);
}

/// As the first, with a neighbour lattice smaller than the fluid on every side, of cells of h
/// and of 2h: particles outside it sit in its edge cells (clamped), and the trimmed search must
/// still find every neighbour within 2h (counts, densities and forces against all pairs).
#[test]
fn one_step_matches_the_cpu_twin_with_particles_outside_the_lattice() {
    let src = twin_scene_source();
    let full = "bounds = [[0.0, 0.0, 0.0], [0.24, 1.0, 0.12]]";
    assert!(src.contains(full), "{src}");
    for cell in ["h", "2h"] {
        let small = format!("bounds = [[0.03, 0.02, 0.03], [0.15, 0.12, 0.09]]\ncell = \"{cell}\"");
        let s = parse("fluid", &src.replace(full, &small));
        let lattice = texflow::sim::fluid::lattice_of(&s);
        let h = s.fluid.as_ref().unwrap().h();
        let want = if cell == "h" { h } else { 2.0 * h };
        assert_eq!(lattice.spacing, want, "cell = {cell}");
        assert!(lattice.cells() > 8, "{cell}: {:?}", lattice.dims);
        check_twin(s);
    }
}

fn check_twin(s: SceneFile) {
    check_twin_after(s, 150);
}

/// The twin's checks on the step after `steps` steps.
fn check_twin_after(s: SceneFile, steps: usize) {
    let ctx = context();
    let mut sim = ParticleSim::new(&ctx, &s, 1).expect("fluid scene");
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let (x0, v0) = sim.read_state().unwrap();
    sim.run(Stage::Integrate).unwrap();
    let (x1, v1) = sim.read_state().unwrap();
    let reference = texflow::sim::reference::Reference::new(&s).unwrap();
    let live: Vec<usize> = (0..x0.len() / 4).filter(|&i| x0[i * 4 + 3] > 0.0).collect();
    assert_eq!(live.len(), 216, "6³ lattice points, the rest dead");
    for &i in &live {
        let t = |a: &[f32]| Vec3::from_slice(&a[i * 4..i * 4 + 3]);
        let (x, v, _) = reference.step_explicit(t(&x0), t(&v0), 1.0, 0);
        assert!(
            (x - t(&x1)).length() <= 1e-6,
            "integration x {i}: {x} vs {}",
            t(&x1)
        );
        assert!(
            (v - t(&v1)).length() <= 1e-5,
            "integration v {i}: {v} vs {}",
            t(&v1)
        );
    }
    sim.run(Stage::Collide).unwrap();
    let f = sim.fluid().expect("the fluid stage");
    let rb = f.read_back().unwrap();
    check_gather(f, &x1, &v1, &rb);
    let (x2, v2) = sim.read_state().unwrap();
    let t = twin(f.config(), &planes(&s), &rb.positions, &rb.velocities);
    let b = f.config().stiffness() as f64;
    let dt = s.time.dt as f64;
    let (mut worst_rho, mut worst_v, mut moving) = (0.0f64, 0.0f64, 0);
    for i in 0..x2.len() / 4 {
        if rb.positions[i * 4 + 3] <= 0.0 {
            continue;
        }
        assert_eq!(
            &x2[i * 4..i * 4 + 4],
            &rb.positions[i * 4..i * 4 + 4],
            "positions copied"
        );
        let d = &rb.density[i * 4..i * 4 + 4];
        let e = (d[0] as f64 - t.rho[i]).abs() / t.rho[i];
        worst_rho = worst_rho.max(e);
        assert!(e <= 1e-4, "density {i}: {} vs {}", d[0], t.rho[i]);
        assert!(
            close(d[1] as f64, t.p[i], 1e-3 * t.p[i] + 1e-5 * b),
            "pressure {i}: {} vs {}",
            d[1],
            t.p[i]
        );
        assert_eq!(d[3], 0.0, "no truncated search");
        for k in 0..3 {
            let want = rb.velocities[i * 4 + k] as f64 + t.a[i][k] * dt;
            let tol = 1e-6 + (2e-4 * t.scale[i] + 1e-5 * b * t.per_pascal[i]) * dt;
            worst_v = worst_v.max((v2[i * 4 + k] as f64 - want).abs() / tol);
            assert!(
                close(v2[i * 4 + k] as f64, want, tol),
                "velocity {i}.{k}: {} vs {want}",
                v2[i * 4 + k]
            );
        }
        if t.p[i] > 0.0 {
            moving += 1;
        }
    }
    eprintln!("twin: worst density error {worst_rho:.2e}, worst velocity error {worst_v:.3} of its tolerance, {moving} particles under pressure");
    assert!(
        moving > 50,
        "the step must exercise the pressure: {moving} particles under pressure"
    );
    assert_eq!(f.truncated_searches().unwrap(), 0);
    no_gl_error(&ctx);
}

/// The gathered layout is the integrated state, reordered by cell key (a permutation: no
/// particle lost or doubled), and the density pass counted each particle's neighbours within
/// 2h exactly as all pairs do (no neighbour lost to the search).
fn check_gather(
    f: &texflow::sim::fluid::Fluid,
    x1: &[f32],
    v1: &[f32],
    rb: &texflow::sim::fluid::FluidReadback,
) {
    let key = |t: &[f32]| -> Vec<u32> { t.iter().map(|c| c.to_bits()).collect() };
    let live = |x: &[f32], v: &[f32]| {
        let mut out: Vec<Vec<u32>> = (0..x.len() / 4)
            .filter(|&i| x[i * 4 + 3] > 0.0)
            .map(|i| [key(&x[i * 4..i * 4 + 4]), key(&v[i * 4..i * 4 + 3])].concat())
            .collect();
        out.sort();
        out
    };
    assert_eq!(
        live(x1, v1),
        live(&rb.positions, &rb.velocities),
        "the gather is a permutation"
    );
    let lattice = f.lattice();
    let mut last = 0;
    let h = f.config().h() as f64;
    let n = rb.positions.len() / 4;
    for i in 0..n {
        let p = &rb.positions[i * 4..i * 4 + 4];
        if p[3] <= 0.0 {
            continue;
        }
        let k = lattice.key(lattice.cell(Vec3::from_slice(&p[..3])));
        assert!(k >= last, "cell order at {i}");
        last = k;
        let count = (0..n)
            .filter(|&j| j != i && rb.positions[j * 4 + 3] > 0.0)
            .filter(|&j| {
                let d = sub(v3(p), v3(&rb.positions[j * 4..]));
                dot(d, d).sqrt() < 2.0 * h
            })
            .count();
        assert_eq!(rb.density[i * 4 + 2] as usize, count, "neighbours of {i}");
    }
}

/// A column of `base` × `base` × `layers` particles on a lattice of 1 cm in a tank that just
/// holds it, settled for `steps` steps of 0.35 ms under gravity and a damping of 20/s (which
/// leaves the equilibrium alone); per layer, top down: (mean y, mean pressure, pressure of the
/// weight above, ρ g h with the mass above the layer's centre).
fn settled_column(base: u32, layers: u32, steps: u32, size: [u32; 2]) -> Vec<(f64, f64, f64)> {
    let ctx = context();
    let dx = 0.01f32;
    let (side, height) = (base as f32 * dx, layers as f32 * dx);
    let fluid = "speed_of_sound = 10.0\nviscosity = 0.5\nspacing = 0.01";
    let block = ([side / 2.0, height / 2.0, side / 2.0], [side, height, side]);
    let src = tank(size, [side, side], block, 3.5e-4, fluid) + "[[forces.damping]]\nrate = 20.0\n";
    let s = parse("column", &src);
    let mut sim = ParticleSim::new(&ctx, &s, 1).expect("column scene");
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let f = sim.fluid().unwrap();
    let rb = f.read_back().unwrap();
    let (m, g) = (f.config().mass() as f64, 9.81f64);
    let mut ps: Vec<(f64, f64)> = (0..rb.positions.len() / 4)
        .filter(|&i| rb.positions[i * 4 + 3] > 0.0)
        .map(|i| (rb.positions[i * 4 + 1] as f64, rb.density[i * 4 + 1] as f64))
        .collect();
    assert_eq!(
        ps.len() as u32,
        base * base * layers,
        "every particle placed"
    );
    ps.sort_by(|a, b| b.0.total_cmp(&a.0));
    // Layers by rank, top down: the particles of layer k are ranks k n..(k + 1) n by height,
    // and the weight above a particle of rank r is that of the r above it and half its own.
    let n = (base * base) as usize;
    let area = (side as f64).powi(2);
    let out = (ps.chunks(n).enumerate())
        .map(|(k, layer)| {
            let y = layer.iter().map(|p| p.0).sum::<f64>() / n as f64;
            let p = layer.iter().map(|p| p.1).sum::<f64>() / n as f64;
            (
                y,
                p,
                g * m * (k * n) as f64 / area + g * m * n as f64 / (2.0 * area),
            )
        })
        .collect();
    no_gl_error(&ctx);
    out
}

/// The pressure below the top three layers (whose kernels reach past the surface) of a resting
/// column is the weight of the fluid above (ρ g h) within 2 %: the fast variant, a column of
/// 4 × 4 × 12 settled for 0.35 s. Single layers alternate about ±5 % around it (the odd-even
/// pressure noise of SPH on a lattice), so each two neighbouring layers are compared together;
/// the layer on the floor reads about 12 % high (its ghosts are closer to it than the spacing)
/// and is left out.
#[test]
fn a_resting_column_holds_hydrostatic_pressure() {
    let layers = settled_column(4, 12, 1000, [16, 16]);
    check_hydrostatic(&layers, 12, 3);
}

/// `initial = "hydrostatic"` starts a column in equilibrium: after the first step, in a column
/// of 8 × 8 × 12 particles (c = 10 m/s), the particles of the middle 4 × 4 (further than 2h from
/// the side walls, so no corner misses its ghosts) hold the weight above them, ρ g h, within 3 %
/// layer by layer from the fourth down to the one above the floor (measured: 1.2 to 1.8 % high;
/// the cubic spline's lattice sum at h = Δx reads a 1 % compression 0.02 % of ρ0 high, 1.6 % of
/// its pressure); the uniform lattice starts them without pressure (under 5 % of ρ g h).
#[test]
fn a_hydrostatic_start_holds_the_weight_from_the_first_step() {
    let (n, layers, dx) = (8u32, 12u32, 0.01f32);
    let (side, height) = (n as f32 * dx, layers as f32 * dx);
    let block = ([side / 2.0, height / 2.0, side / 2.0], [side, height, side]);
    let ctx = context();
    for start in ["hydrostatic", "uniform"] {
        let fluid = format!("speed_of_sound = 10.0\nspacing = 0.01\ninitial = \"{start}\"");
        let s = parse(
            "column",
            &tank([32, 32], [side, side], block, 3.5e-4, &fluid),
        );
        let mut sim = ParticleSim::new(&ctx, &s, 1).expect("column scene");
        sim.step().unwrap();
        let f = sim.fluid().unwrap();
        let rb = f.read_back().unwrap();
        let inner = |c: f32| c > 2.0 * dx && c < side - 2.0 * dx;
        let mut ps: Vec<(f64, f64)> = (0..rb.positions.len() / 4)
            .filter(|&i| rb.positions[i * 4 + 3] > 0.0)
            .filter(|&i| inner(rb.positions[i * 4]) && inner(rb.positions[i * 4 + 2]))
            .map(|i| (rb.positions[i * 4 + 1] as f64, rb.density[i * 4 + 1] as f64))
            .collect();
        assert_eq!(
            ps.len() as u32,
            16 * layers,
            "the middle 4 × 4 of every layer"
        );
        ps.sort_by(|a, b| b.0.total_cmp(&a.0));
        // Top down: layer k has k whole layers and half its own above it.
        let (m, g) = (f.config().mass() as f64, 9.81f64);
        let area = (dx as f64).powi(2);
        for (k, layer) in ps.chunks(16).enumerate().take(layers as usize - 1) {
            let p = layer.iter().map(|q| q.1).sum::<f64>() / 16.0;
            let w = g * m * (k as f64 + 0.5) / area;
            eprintln!(
                "{start}: layer {k}: p {p:.1} Pa, ρ g h {w:.1} Pa, ratio {:.4}",
                p / w
            );
            match start {
                "hydrostatic" if k >= 3 => {
                    assert!(
                        (p / w - 1.0).abs() <= 0.03,
                        "layer {k}: {p} Pa against {w} Pa"
                    )
                }
                "uniform" => assert!(p < 0.05 * w, "uniform start, layer {k}: {p} Pa"),
                _ => {}
            }
        }
    }
    no_gl_error(&ctx);
}

/// As above, 8 × 8 × 24 particles settled for 1.05 s (2.3 minutes on llvmpipe).
#[test]
#[ignore]
fn a_tall_resting_column_holds_hydrostatic_pressure() {
    let layers = settled_column(8, 24, 3000, [64, 32]);
    check_hydrostatic(&layers, 24, 3);
}

/// Each two neighbouring layers below the `top` ones and above the floor's: their mean
/// pressure against ρ g h within 2 %.
fn check_hydrostatic(layers: &[(f64, f64, f64)], expected: usize, top: usize) {
    for (k, (y, p, w)) in layers.iter().enumerate() {
        eprintln!(
            "layer {k}: y {y:.4} m, p {p:.1} Pa, ρ g h {w:.1} Pa, ratio {:.4}",
            p / w
        );
    }
    assert_eq!(layers.len(), expected, "every layer");
    let inner = &layers[top..layers.len() - 1];
    for (k, pair) in inner.windows(2).enumerate() {
        let (p, w) = (pair[0].1 + pair[1].1, pair[0].2 + pair[1].2);
        eprintln!("layers {} and {}: ratio {:.4}", k + top, k + top + 1, p / w);
        assert!(
            (p / w - 1.0).abs() <= 0.02,
            "layers {}, {}: {p} Pa against ρ g h = {w} Pa",
            k + top,
            k + top + 1
        );
    }
}
