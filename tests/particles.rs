//! The particle pipeline on the GPU against CPU references: integrators against exact solutions,
//! collisions against their analytic guarantees, birth and death against the allocator.

mod common;

use common::scene::parse;
use common::{context, no_gl_error};
use texflow::scene;
use texflow::sim::ParticleSim;

fn small(name: &str) -> scene::SceneFile {
    let mut s = scene::load(name).unwrap();
    s.particles.size = [32, 16];
    s
}

/// Every built-in particle scene compiles and steps without GL errors or non-finite live state.
#[test]
fn builtin_scenes_step() {
    let ctx = context();
    for name in scene::BUILTIN
        .iter()
        .filter(|n| scene::load(n).unwrap().fire.is_none())
    {
        let s = small(name);
        let mut sim = ParticleSim::new(&ctx, &s, 3).unwrap_or_else(|e| panic!("{name}: {e}"));
        for _ in 0..120 {
            sim.step().unwrap();
        }
        let pos = sim.read_positions().unwrap();
        let live: Vec<&[f32]> = pos.chunks(4).filter(|p| p[3] > 0.0).collect();
        assert!(!live.is_empty(), "{name}: nothing alive after 2 s");
        for p in &live {
            assert!(p[..3].iter().all(|v| v.is_finite()), "{name}: {p:?}");
        }
        no_gl_error(&ctx);
    }
}

/// A scene of permanent particles (state set by the test) with the given integrator and extra
/// TOML (forces, colliders).
fn scene_with(size: [u32; 2], integrator: &str, dt: f32, extra: &str) -> scene::SceneFile {
    parse(
        "test",
        &format!(
            r#"
name = "test"
integrator = "{integrator}"
[particles]
size = [{}, {}]
[time]
dt = {dt}
[[emitters.initial]]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
{extra}
"#,
            size[0], size[1]
        ),
    )
}

/// Uploads particles (position, velocity) as type 0, permanent; the rest of the texture dead.
fn set(sim: &mut ParticleSim, particles: &[([f32; 3], [f32; 3])]) {
    common::set_particles(sim, particles, |_, _| 0.5);
}

fn xyz(v: &[f32], i: usize) -> [f32; 3] {
    [v[i * 4], v[i * 4 + 1], v[i * 4 + 2]]
}

/// Projectile under gravity: UberFlow's update and Verlet (with its second-order start) are exact
/// for constant acceleration; Latta's Euler follows its own discrete solution
/// x_N = x0 + v0 t + g dt² N(N+1)/2 exactly, an O(dt) error against the true parabola.
#[test]
fn projectile_is_exact_where_theory_says() {
    let ctx = context();
    let g = [0.0f32, -9.81, 0.0];
    let dt = 0.01f32;
    let steps = 100usize;
    let starts = [
        ([0.0, 1.0, 0.0], [1.0, 5.0, 0.0]),
        ([-2.0, 0.5, 1.0], [0.0, 12.0, -3.0]),
        ([3.0, 10.0, -1.0], [-4.0, 0.0, 2.0]),
    ];
    for integrator in ["uberflow", "verlet", "euler"] {
        let s = scene_with(
            [4, 1],
            integrator,
            dt,
            "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]",
        );
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        set(&mut sim, &starts);
        for _ in 0..steps {
            sim.step().unwrap();
        }
        let pos = sim.read_positions().unwrap();
        let t = dt as f64 * steps as f64;
        let n = steps as f64;
        for (i, (x0, v0)) in starts.iter().enumerate() {
            let got = xyz(&pos, i);
            for k in 0..3 {
                let exact = x0[k] as f64 + v0[k] as f64 * t + 0.5 * g[k] as f64 * t * t;
                let expect = if integrator == "euler" {
                    x0[k] as f64
                        + v0[k] as f64 * t
                        + g[k] as f64 * (dt as f64).powi(2) * n * (n + 1.0) / 2.0
                } else {
                    exact
                };
                // Explicit schemes: 100 f32 additions on values up to ~15 m, about 100 ulps.
                // Position Verlet carries the velocity as a difference of two positions, so
                // each step's rounding (an ulp of |x|) is summed twice: N² ulps in all.
                let ulp = f32::EPSILON as f64 * (1.0 + expect.abs().max(x0[k].abs() as f64));
                let tol = if integrator == "verlet" {
                    (steps * steps) as f64 * ulp
                } else {
                    2e-4 * (1.0 + expect.abs())
                };
                assert!(
                    (got[k] as f64 - expect).abs() < tol,
                    "{integrator} particle {i} axis {k}: {} vs {expect} (exact {exact})",
                    got[k]
                );
                if integrator == "euler" && g[k] != 0.0 {
                    // And Euler really is off the parabola by g dt t / 2.
                    let off = (got[k] as f64 - exact).abs();
                    let theory = (g[k] as f64 * dt as f64 * t / 2.0).abs();
                    assert!((off - theory).abs() < 0.05 * theory, "{off} vs {theory}");
                }
            }
        }
        no_gl_error(&ctx);
    }
}

/// Highest point of particle 0 after its first bounce.
fn bounce_apex(integrator: &str, resilience: f32, friction: f32) -> f32 {
    let ctx = context();
    let s = scene_with(
        [1, 1],
        integrator,
        1.0 / 1000.0,
        &format!(
            "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n\
             [[colliders.plane]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\n\
             friction = {friction}\nresilience = {resilience}"
        ),
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    set(&mut sim, &[([0.0, 1.0, 0.0], [0.0, 0.0, 0.0])]);
    // Fall (0.45 s), bounce, rise: stop after 1.2 s, before a second landing for e <= 0.8.
    let (mut bounced, mut apex, mut last) = (false, 0.0f32, 1.0f32);
    for _ in 0..1200 {
        sim.step().unwrap();
        let y = sim.read_positions().unwrap()[1];
        assert!(y >= 0.0, "below the plane: {y}");
        if y > last {
            bounced = true;
        }
        if bounced {
            apex = apex.max(y);
        }
        last = y;
    }
    no_gl_error(&ctx);
    apex
}

/// A ball dropped from h = 1 m on a plane of resilience e rises to about e² h (Latta eq. 5).
#[test]
fn bounce_height_is_resilience_squared() {
    for e in [0.3f32, 0.6, 0.8] {
        let apex = bounce_apex("euler", e, 0.0);
        // The step that crosses the plane loses or gains up to g dt² per step of travel: about
        // 1% at dt = 1 ms; 3% leaves room for where in the step the contact falls.
        assert!(
            (apex - e * e).abs() < 0.03 * e * e + 2e-3,
            "e = {e}: apex {apex}, expected {}",
            e * e
        );
    }
}

/// Sliding on a plane with friction μ: the tangential speed decays by (1 - μ) per contact and
/// never reverses; below the slow-speed threshold friction stops acting (Latta §3.4.2).
#[test]
fn friction_slows_sliding_without_reversal() {
    let ctx = context();
    let slow = 0.2f32;
    let s = scene_with(
        [1, 1],
        "euler",
        1.0 / 240.0,
        &format!(
            "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n[colliders]\nslow_speed = {slow}\n\
             [[colliders.plane]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\n\
             friction = 0.05\nresilience = 0.0"
        ),
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    set(&mut sim, &[([0.0, 1e-3, 0.0], [3.0, 0.0, 1.0])]);
    let mut last = f32::INFINITY;
    for _ in 0..400 {
        sim.step().unwrap();
        let v = sim.read_velocities().unwrap();
        let (vx, vz) = (v[0], v[2]);
        assert!(vx >= 0.0 && vz >= 0.0, "sliding reversed: ({vx}, {vz})");
        let speed = (vx * vx + vz * vz).sqrt();
        assert!(
            speed <= last + 1e-5,
            "sliding sped up: {speed} after {last}"
        );
        last = speed;
        let y = sim.read_positions().unwrap()[1];
        assert!(y >= 0.0, "below the plane: {y}");
    }
    // 400 contacts at 5% each would take 3.16 m/s to 1e-8: the threshold stops it near `slow`.
    assert!(
        last <= slow * 1.05 && last > 0.5 * slow,
        "final speed {last}"
    );
    no_gl_error(&ctx);
}

/// A box of planes around a sphere, over a height field, under gravity.
const BOX_SPHERE_TERRAIN: &str = r#"
[[colliders.plane]]
point = [0.0, -1.0, 0.0]
normal = [0.0, 1.0, 0.0]
resilience = 0.9
[[colliders.plane]]
point = [2.0, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
resilience = 0.9
[[colliders.plane]]
point = [-2.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
resilience = 0.9
[[colliders.plane]]
point = [0.0, 0.0, 2.0]
normal = [0.0, 0.0, -1.0]
resilience = 0.9
[[colliders.plane]]
point = [0.0, 0.0, -2.0]
normal = [0.0, 0.0, 1.0]
resilience = 0.9
[[colliders.plane]]
point = [0.0, 3.0, 0.0]
normal = [0.0, -1.0, 0.0]
resilience = 0.9
[[colliders.sphere]]
center = [0.5, 1.0, 0.0]
radius = 0.6
friction = 0.2
resilience = 0.7
[[colliders.heightfield]]
extent = [-2.0, -2.0, 2.0, 2.0]
resolution = 64
base = -0.3
amplitude = 0.4
frequency = 3.0
friction = 0.1
resilience = 0.8
[[forces.gravity]]
acceleration = [0.0, -9.81, 0.0]
"#;

/// 256 particles spread over the box, 20-40 m/s in all directions (a third to two thirds of the
/// box per step).
fn fast_starts() -> Vec<([f32; 3], [f32; 3])> {
    let mut rng = texflow::sim::emit::Rng::new(0, 0, 5);
    (0..256)
        .map(|_| {
            let mut p = [0.0; 3];
            let mut v = [0.0; 3];
            for k in 0..3 {
                p[k] = rng.uniform() * 3.0 - 1.5;
                v[k] = (rng.uniform() * 2.0 - 1.0) * 25.0;
            }
            p[1] = 1.8 + rng.uniform();
            if ((p[0] - 0.5f32).powi(2) + (p[1] - 1.0).powi(2) + p[2] * p[2]).sqrt() < 0.7 {
                p[1] = 2.5;
            }
            (p, v)
        })
        .collect()
}

/// After 1,000 steps at high speed in a box of planes around a sphere, over a height field, no
/// particle is below a plane, inside the sphere or under the landscape, for every integrator.
#[test]
fn no_particle_ends_inside_a_collider() {
    let ctx = context();
    for integrator in ["euler", "uberflow", "verlet"] {
        let s = scene_with([16, 16], integrator, 1.0 / 60.0, BOX_SPHERE_TERRAIN);
        let hf = texflow::sim::HeightField::new(&s.colliders.heightfield[0]).unwrap();
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        let starts = fast_starts();
        set(&mut sim, &starts);
        for step in 0..1000 {
            sim.step().unwrap();
            if step % 100 != 99 {
                continue;
            }
            let pos = sim.read_positions().unwrap();
            for i in 0..starts.len() {
                let [x, y, z] = xyz(&pos, i);
                let ctx_msg = format!("{integrator} step {step} particle {i} at ({x}, {y}, {z})");
                assert!(x.is_finite() && y.is_finite() && z.is_finite(), "{ctx_msg}");
                assert!(
                    (-1.0..=3.0).contains(&y) && x.abs() <= 2.0 && z.abs() <= 2.0,
                    "{ctx_msg}"
                );
                let r = ((x - 0.5).powi(2) + (y - 1.0).powi(2) + z * z).sqrt();
                assert!(r >= 0.6 - 1e-5, "inside the sphere (r = {r}): {ctx_msg}");
                let (h, _) = hf.sample(x, z);
                // The GPU samples the same texture; 1e-5 covers the different rounding.
                assert!(y >= h - 1e-5, "under the height field ({h}): {ctx_msg}");
            }
        }
        no_gl_error(&ctx);
    }
}

/// Latta's allocator on the GPU: with the min-heap every live particle sits below the high-water
/// mark, which stays within the rows the passes cover; every index the CPU holds live is alive on
/// the GPU unless its death is due within the reclaim margin; the GPU has no live particle the
/// CPU does not know about.
#[test]
fn min_heap_keeps_live_particles_packed() {
    let ctx = context();
    let s = parse(
        "test",
        r#"
name = "alloc"
[particles]
size = [32, 32]
[time]
dt = 0.02
[[emitters.allocator]]
rate = 400.0
allocator = "min_heap"
direction = [0.0, 1.0, 0.0]
speed = [1.0, 2.0]
life = [0.3, 1.5]
[[forces.gravity]]
acceleration = [0.0, -9.81, 0.0]
"#,
    );
    let mut sim = ParticleSim::new(&ctx, &s, 9).unwrap();
    let width = 32usize;
    let mut max_live = 0;
    for step in 0..150 {
        sim.step().unwrap();
        let pos = sim.read_positions().unwrap();
        let alloc = sim.allocator().unwrap();
        let rows = sim.active_rows() as usize;
        for (i, p) in pos.chunks(4).enumerate() {
            if p[3] > 0.0 {
                assert!(
                    alloc.is_live(i as u32),
                    "step {step}: texel {i} alive on the GPU only"
                );
                assert!(
                    i < rows * width,
                    "step {step}: live texel {i} beyond {rows} rows"
                );
            }
        }
        // The CPU frees an index 3 steps after the particle's death time, and the GPU kills it
        // in the step that reaches that time: an index live on the CPU but dead on the GPU must
        // have died (birth + life, from the static texture) within the last 4 steps.
        let statics = sim.statics().read_f32().unwrap();
        let now = sim.time() as f32;
        for (i, p) in pos.chunks(4).enumerate() {
            if alloc.is_live(i as u32) && p[3] <= 0.0 {
                let death = statics[i * 4] + statics[i * 4 + 2];
                assert!(
                    death <= now + 1e-4 && death >= now - 4.0 * 0.02 - 1e-4,
                    "step {step}: index {i} died at {death}, now {now}, still held by the CPU"
                );
            }
        }
        max_live = max_live.max(alloc.live_count());
        // Packed: the high-water mark stays near the live count (the min-heap refills holes first).
        assert!(
            alloc.high_water() <= alloc.live_count() + 60,
            "step {step}: holes"
        );
    }
    // A steady state of rate * mean life = 360 particles was reached.
    assert!(max_live > 250, "{max_live}");
    let (emitted, dropped) = sim.emitted();
    assert_eq!(dropped, 0);
    assert!((emitted as i64 - 400 * 3).abs() <= 1, "{emitted}");
    no_gl_error(&ctx);
}

/// Each built-in scene's pass list holds exactly what it needs.
#[test]
fn builtin_pass_lists_hold_what_each_scene_needs() {
    let ctx = context();
    let text = |n: &str| common::plan_of(&ctx, &scene::load(n).unwrap()).to_string();
    for n in scene::BUILTIN {
        let t = text(n);
        let alpha = scene::load(n).unwrap().render.blending == scene::Blending::Alpha;
        assert_eq!(
            t.contains("- sort"),
            alpha,
            "{n}: sort iff alpha blending\n{t}"
        );
        let collisions = scene::load(n).unwrap().collisions.is_some();
        assert_eq!(
            t.contains("collision"),
            collisions,
            "{n}: collision passes\n{t}"
        );
    }
    assert!(!text("fire").contains("sort"));
    assert!(text("collide").contains("staggered lattice"));
    let smoke = text("smoke-unlit");
    assert!(
        smoke.contains("sort: oddeven") && smoke.contains("back to front"),
        "{smoke}"
    );
    assert!(text("e3").contains("front to back"));
    // Colliders only where the scene has them.
    for n in ["e1", "e3", "smoke-unlit"] {
        assert!(!text(n).contains("colliders"), "{n}");
    }
    assert!(text("e2").contains("height field") && text("snow").contains("height field"));
    let f = text("fountain");
    assert!(f.contains("1 plane") && f.contains("1 sphere") && f.contains("min-heap"));
    assert!(f.contains("live rows only"));
    // Birth and death only for particles that have a life.
    let permanent = scene_with([4, 4], "verlet", 0.01, "");
    let p = common::plan_of(&ctx, &permanent).to_string();
    assert!(
        !p.contains("emit") && !p.contains("death") && !p.contains("forces"),
        "{p}"
    );
    assert!(p.contains("Verlet") && !p.contains("velocity ("), "{p}");
}

/// Position error at t = 2 (not a turning point) of x'' = -x from x = 1, v = 0.
fn oscillator_error(integrator: &str, dt: f32) -> f64 {
    let ctx = context();
    let s = scene_with(
        [1, 1],
        integrator,
        dt,
        "[[forces.spring]]\nanchor = [0.0, 0.0, 0.0]\nstiffness = 1.0",
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    set(&mut sim, &[([1.0, 0.0, 0.0], [0.0, 0.0, 0.0])]);
    let steps = (2.0 / dt).round() as usize;
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let x = sim.read_positions().unwrap()[0] as f64;
    no_gl_error(&ctx);
    (x - (steps as f64 * dt as f64).cos()).abs()
}

/// Convergence orders from step halving on a harmonic oscillator (../shared/docs/numerics.md):
/// 1 for Latta's Euler, 1 for UberFlow's update (exact only for constant acceleration),
/// 2 for Verlet with its second-order start; each within ±0.2.
#[test]
fn oscillator_convergence_orders() {
    // ω dt from 0.2 to 0.05: errors from 1e-2 to 1e-4, well above f32 rounding (~1e-6).
    let dts = [0.2f32, 0.1, 0.05];
    for (integrator, expected) in [("euler", 1.0), ("uberflow", 1.0), ("verlet", 2.0)] {
        let e: Vec<f64> = dts
            .iter()
            .map(|&dt| oscillator_error(integrator, dt))
            .collect();
        let orders: Vec<f64> = e.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        eprintln!("{integrator}: |x(2) - cos 2| = {e:.3?} at dt = {dts:?}: orders {orders:.3?}");
        for w in e.windows(2) {
            let order = (w[0] / w[1]).log2();
            assert!(
                (order - expected).abs() <= 0.2,
                "{integrator}: errors {e:?} give order {order:.3}, expected {expected}"
            );
        }
    }
}
