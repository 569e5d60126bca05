//! Fast particles at colliders: a path longer than the gap between walls bounces at every wall
//! it reaches in a step (glsl/sim/colliders.glsl, `bounce_on`), keeps its speed up to the
//! resilience, and the twin (src/sim/reference) follows the GPU bounce for bounce. Before, the
//! step was replayed from its start once per collider and what still ended inside lost its speed
//! into the wall: a 1,000 m/s gas in a unit box lost over 99 % of its kinetic energy in a step.

mod common;

use common::scene::random_gas;
use common::{context, no_gl_error};
use glam::Vec3;
use texflow::report::collide_iterations::energy_momentum;
use texflow::scene::SceneFile;
use texflow::sim::reference::{Events, Reference};
use texflow::sim::ParticleSim;

/// The unit box of elastic frictionless planes.
const BOX: &str = "
[[colliders.plane]]
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
[[colliders.plane]]
point = [1.0, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
[[colliders.plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
[[colliders.plane]]
point = [0.0, 1.0, 0.0]
normal = [0.0, -1.0, 0.0]
[[colliders.plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
[[colliders.plane]]
point = [0.0, 0.0, 1.0]
normal = [0.0, 0.0, -1.0]
";

/// A solid sphere and a solid box on the floor inside the unit box (elastic, frictionless unless
/// `friction`). Gaps to the walls of 0.1 m and more: at 200 m/s (1 m per step) a path meets at
/// most about ten surfaces in a step, within the bound.
fn obstacles(friction: f32, resilience: f32) -> String {
    format!(
        "[[colliders.sphere]]\ncenter = [0.3, 0.6, 0.3]\nradius = 0.2\nfriction = {friction}\n\
         resilience = {resilience}\n[[colliders.box]]\nmin = [0.55, 0.0, 0.55]\n\
         max = [0.85, 0.25, 0.85]\nfriction = {friction}\nresilience = {resilience}\n"
    )
}

/// `integrator` at dt = 5 ms, 256 permanent particles, the colliders in `body`.
fn scene(integrator: &str, body: &str) -> SceneFile {
    let src = format!(
        "name = \"fast\"\nintegrator = \"{integrator}\"\n[particles]\nsize = [16, 16]\n\
         [time]\ndt = 0.005\n[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\n\
         speed = [0.0, 0.0]\n[colliders]\n{body}"
    );
    common::scene::parse("fast", &src)
}

/// 256 particles at `speed` (1,000 m/s: 5 m per step, about a dozen walls), in random
/// directions, at random places inside the unit box outside the obstacles (`r`).
fn fast_gas(r: &Reference, speed: f32) -> Vec<([f32; 3], [f32; 3])> {
    random_gas(4096, 3, 2.0, 1.0)
        .into_iter()
        .filter(|(x, v)| {
            r.distance_to_colliders(Vec3::from(*x)) > 0.01 && Vec3::from(*v).length() > 0.1
        })
        .take(256)
        .map(|(x, v)| (x, (Vec3::from(v).normalize() * speed).to_array()))
        .collect()
}

fn start(ctx: &common::TestContext, s: &SceneFile, gas: &[([f32; 3], [f32; 3])]) -> ParticleSim {
    let mut sim = ParticleSim::new(ctx, s, 1).unwrap();
    common::set_particles(&mut sim, gas, |i, n| (i as f32 + 0.5) / n as f32);
    sim
}

/// The least signed distance of any live particle to the colliders.
fn deepest(sim: &ParticleSim, r: &Reference) -> f32 {
    let x = sim.read_positions().unwrap();
    x.chunks(4)
        .filter(|p| p[3] > 0.0)
        .map(|p| r.distance_to_colliders(Vec3::new(p[0], p[1], p[2])))
        .fold(f32::INFINITY, f32::min)
}

/// The 1,000 m/s elastic gas in the unit box keeps its kinetic energy to 1 % over 100 steps, and
/// no particle leaves; so does a 200 m/s gas with a sphere and a box inside; in both explicit
/// integrators of the papers. On llvmpipe the change is 0 to rounding (-99 % before).
#[test]
fn a_fast_elastic_gas_keeps_its_energy_in_a_box() {
    let ctx = context();
    for integrator in ["euler", "uberflow"] {
        for (body, speed) in [
            (BOX.to_string(), 1000.0),
            (format!("{BOX}{}", obstacles(0.0, 1.0)), 200.0),
        ] {
            let s = scene(integrator, &body);
            let r = Reference::new(&s).unwrap();
            let gas = fast_gas(&r, speed);
            assert_eq!(gas.len(), 256);
            let mut sim = start(&ctx, &s, &gas);
            let (e0, _) = energy_momentum(&sim).unwrap();
            for _ in 0..100 {
                sim.step().unwrap();
            }
            let (e1, _) = energy_momentum(&sim).unwrap();
            let change = e1 / e0 - 1.0;
            let d = deepest(&sim, &r);
            eprintln!(
                "{integrator}, {} colliders: kinetic energy {e0:.1} J -> {e1:.1} J ({:+.2e}), \
                 deepest {d:e}, {} bound(s) reached",
                s.colliders.plane.len() + s.colliders.sphere.len() + s.colliders.boxes.len(),
                change,
                sim.truncated_bounces().unwrap()
            );
            assert!(
                change.abs() < 0.01,
                "{integrator}: energy changed by {change}"
            );
            assert_eq!(sim.truncated_bounces().unwrap(), 0, "{integrator}");
            assert!(d >= -1e-5, "{integrator}: a particle is {} inside", -d);
            let x = sim.read_positions().unwrap();
            let inside = x
                .chunks(4)
                .filter(|p| p[..3].iter().all(|c| (0.0..=1.0).contains(c)));
            assert_eq!(inside.count(), 256, "{integrator}: particles left the box");
        }
    }
    no_gl_error(&ctx);
}

/// The GPU against the twin, one step at a time from the GPU's state, for fast particles among
/// planes, a sphere and a box with friction and resilience below 1 (every bounce takes its share),
/// and the bounces happen. A convex surface spreads what rounding puts into a path (two paths
/// 1 ulp apart leave a sphere further apart), so the allowance is 1e-5 of the size or four
/// times how far the twin's own step moves when its input is nudged by a few ulps.
#[test]
fn twin_follows_the_gpu_bounce_for_bounce() {
    let ctx = context();
    for integrator in ["euler", "uberflow"] {
        let s = scene(integrator, &format!("{BOX}{}", obstacles(0.2, 0.8)));
        let r = Reference::new(&s).unwrap();
        let mut sim = start(&ctx, &s, &fast_gas(&r, 200.0));
        let mut ev = Events::default();
        let mut worst = 0.0f32;
        for step in 0..5 {
            let (x0, v0) = (
                sim.read_positions().unwrap(),
                sim.read_velocities().unwrap(),
            );
            sim.step().unwrap();
            let (x1, v1) = (
                sim.read_positions().unwrap(),
                sim.read_velocities().unwrap(),
            );
            for i in 0..256 {
                let g = |a: &[f32]| Vec3::new(a[i * 4], a[i * 4 + 1], a[i * 4 + 2]);
                let (xc, vc, _, e) = r.step_explicit_events(g(&x0), g(&v0), x0[i * 4 + 3], 0);
                ev += e;
                let (tx, tv) = allowance(&r, g(&x0), g(&v0), (xc, vc), i);
                let (dx, dv) = (
                    (xc - g(&x1)).abs().max_element(),
                    (vc - g(&v1)).abs().max_element(),
                );
                let err = (dx / tx).max(dv / tv);
                assert!(
                    err <= 1.0,
                    "{integrator}, step {step}, particle {i}: GPU {} {} vs twin {xc} {vc}",
                    g(&x1),
                    g(&v1)
                );
                worst = worst.max(err);
            }
        }
        eprintln!("{integrator}: worst {worst:.3} of the tolerance; {ev:?}");
        assert!(ev.bounces > 100, "{integrator}: too few bounces: {ev:?}");
        assert_eq!(ev.bounces_truncated, 0, "{integrator}: {ev:?}");
    }
    no_gl_error(&ctx);
}

/// The allowance for particle `i`'s step: 1e-5 of the position's and the speed's size, or four
/// times the furthest the twin's step lands from `(xc, vc)` from inputs nudged by up to 4 ulps.
fn allowance(r: &Reference, x: Vec3, v: Vec3, (xc, vc): (Vec3, Vec3), i: usize) -> (f32, f32) {
    let mut rng = common::scene::Rng(i as u64 * 31 + 5);
    let (mut sx, mut sv) = (1e-5f32, 1e-5 * v.length().max(1.0));
    for _ in 0..16 {
        let mut nudge = |a: Vec3| a + rng.vec(-4.0, 4.0) * f32::EPSILON * a.abs().max_element();
        let (xn, vn, _, _) = r.step_explicit_events(nudge(x), nudge(v), 1.0, 0);
        sx = sx.max(4.0 * (xn - xc).abs().max_element());
        sv = sv.max(4.0 * (vn - vc).abs().max_element());
    }
    (sx, sv)
}

/// Past `MAX_BOUNCES` in a step the path is counted and the run warns: a 40,000 m/s particle
/// (200 m per step in a unit box, a hundred walls or more) reaches the bound every step; the
/// GPU's count equals the twin's, and the bound in the shader is the library's constant.
#[test]
fn bounces_past_the_bound_are_counted() {
    let glsl = include_str!("../glsl/sim/colliders.glsl");
    let line = format!("const int MAX_BOUNCES = {};", texflow::sim::MAX_BOUNCES);
    assert!(glsl.contains(&line), "colliders.glsl lacks `{line}`");
    let ctx = context();
    let s = scene("euler", BOX);
    let r = Reference::new(&s).unwrap();
    let gas: Vec<_> = fast_gas(&r, 1000.0)
        .into_iter()
        .enumerate()
        .map(|(i, (x, v))| {
            (
                x,
                (Vec3::from(v) * if i % 4 == 0 { 40.0 } else { 1.0 }).to_array(),
            )
        })
        .collect();
    let mut sim = start(&ctx, &s, &gas);
    let mut twin = 0;
    for _ in 0..3 {
        let (x0, v0) = (
            sim.read_positions().unwrap(),
            sim.read_velocities().unwrap(),
        );
        for i in 0..256 {
            let g = |a: &[f32]| Vec3::new(a[i * 4], a[i * 4 + 1], a[i * 4 + 2]);
            twin += r
                .step_explicit_events(g(&x0), g(&v0), 1.0, 0)
                .3
                .bounces_truncated;
        }
        sim.step().unwrap();
    }
    let gpu = sim.truncated_bounces().unwrap();
    eprintln!("truncated: GPU {gpu}, twin {twin}");
    // The fast quarter reaches the bound in the first step (then keep_outside takes its speed
    // into the wall it was left in).
    assert!(
        twin >= 60,
        "the fast quarter should reach the bound: {twin}"
    );
    assert_eq!(gpu, twin as u64);
    no_gl_error(&ctx);
}

/// `render` reads the count back once at the end of the run, warns once and puts it in its JSON.
#[test]
fn render_warns_about_bounces_past_the_bound() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("fast.toml");
    let src = format!(
        "name = \"fast\"\n[particles]\nsize = [8, 8]\n[time]\ndt = 0.005\n\
         [[emitters.initial]]\nshape = \"box\"\ncenter = [0.5, 0.5, 0.5]\nsize = [0.8, 0.8, 0.8]\n\
         direction = [0.0, 1.0, 0.0]\ncone_degrees = 180.0\nspeed = [40000.0, 40000.0]\n\
         [colliders]\n{BOX}[render]\nresolution = [32, 32]\n"
    );
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
        .pointer("/records/truncated_bounces")
        .and_then(|n| n.as_u64());
    assert!(n.is_some_and(|n| n >= 64), "{v}");
    assert_eq!(err.matches("bounces in one step").count(), 1, "{err}");
}
