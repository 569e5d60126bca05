//! Emitter values as curves over time (`src/scene/curve.rs`): births per step and newborn
//! velocities read back from the state against the curves' closed forms, the curve terms against
//! their formulas, errors at their line and column, and the CPU engine against the GPU's.

mod common;

use common::{context, no_gl_error};
use glam::Vec3;
use texflow::scene::curve::{value_noise, Animated};
use texflow::scene::{self, SceneFile};
use texflow::sim::ParticleSim;

const DT: f64 = 0.01;

/// An allocator scene of 64×64 long-lived particles, no forces, a narrow cone straight along
/// `direction`; `keys` are the emitter's other keys.
fn allocator(keys: &str) -> SceneFile {
    let src = format!(
        "name = \"curves\"\n[particles]\nsize = [64, 64]\n[time]\ndt = {DT}\n\
         [[emitters.allocator]]\nlife = [50.0, 50.0]\n{keys}\n"
    );
    common::scene::parse("curves.toml", &src)
}

fn smoothstep(u: f64) -> f64 {
    u * u * (3.0 - 2.0 * u)
}

/// A linear rate ramp 93.7 → 1234.5 per second over 1 s: the live count after step k (births
/// at time k dt owe the interval (k dt - dt, k dt], the rate held at 93.7 before 0) is the floor
/// of the integral of the rate from -dt to k dt, as the allocator carries the fractions.
#[test]
fn a_rate_ramp_births_its_integral_per_step() {
    let ctx = context();
    let s = allocator(
        "rate = { keys = [[0.0, 93.7], [1.0, 1234.5]] }\ndirection = [0.0, 1.0, 0.0]\n\
         speed = 0.0",
    );
    let (r0, r1) = (93.7, 1234.5);
    let integral = |t: f64| {
        // ∫ from -dt: dt · r0, then r0 t + (r1 - r0) t² / 2 up to 1 s, then r1 per second.
        let ramp = t.min(1.0);
        DT * r0 + r0 * ramp + 0.5 * (r1 - r0) * ramp * ramp + r1 * (t - 1.0).max(0.0)
    };
    let mut sim = ParticleSim::new(&ctx, &s, 3).unwrap();
    let mut last = 0usize;
    for k in 0..120u32 {
        sim.step().unwrap();
        let want = integral(k as f64 * DT);
        let live = sim
            .read_positions()
            .unwrap()
            .chunks_exact(4)
            .filter(|p| p[3] > 0.0)
            .count();
        // Within rounding of an integer either side is right.
        let near = (want - want.round()).abs() < 1e-6;
        assert!(
            live == want.floor() as usize || (near && live == want.round() as usize),
            "step {k}: {live} live, integral {want}"
        );
        assert!(live >= last, "step {k}: births only");
        last = live;
    }
    assert_eq!(sim.dropped_births(), 0);
    no_gl_error(&ctx);
}

/// Every live particle's velocity (no forces: what it was born with) against the curves at its
/// birth time, read from the static texture: `speed` and `direction` given by `keys`, `expect`
/// the closed form (speed, unit direction) at a birth time.
fn check_newborns(keys: &str, expect: impl Fn(f64) -> (f64, Vec3)) {
    let ctx = context();
    let s = allocator(&format!("rate = 300.0\ncone_degrees = 0.0\n{keys}"));
    let mut sim = ParticleSim::new(&ctx, &s, 4).unwrap();
    for _ in 0..100 {
        sim.step().unwrap();
    }
    let v = sim.read_velocities().unwrap();
    let st = sim.statics().read_f32().unwrap();
    let p = sim.read_positions().unwrap();
    let mut checked = 0;
    for i in 0..64 * 64 {
        if p[4 * i + 3] <= 0.0 {
            continue;
        }
        let born = st[4 * i] as f64;
        let got = Vec3::from_slice(&v[4 * i..4 * i + 3]);
        let (speed, dir) = expect(born);
        let tol = 1e-5 * speed.max(1.0);
        assert!(
            (got.length() as f64 - speed).abs() <= tol,
            "particle {i} born at {born}: speed {} want {speed}",
            got.length()
        );
        if speed > 0.0 {
            let d = got.normalize().dot(dir);
            assert!(
                d > 1.0 - 1e-5,
                "particle {i} born at {born}: direction {got}"
            );
        }
        checked += 1;
    }
    assert!(checked > 25_000 / 100, "{checked} particles checked");
    no_gl_error(&ctx);
}

/// Smooth keys: speed 1 → 3 over 0.5 s as 1 + 2 (3u² - 2u³); the newborns' speeds follow it.
#[test]
fn newborn_speeds_follow_a_smooth_curve() {
    check_newborns(
        "direction = [0.0, 1.0, 0.0]\n\
         speed = { keys = [[0.0, 1.0], [0.5, 3.0]], interpolation = \"smooth\" }",
        |t| (1.0 + 2.0 * smoothstep((t / 0.5).min(1.0)), Vec3::Y),
    );
}

/// A periodic term: speed 2 + 0.5 sin(2π (t / 0.2 + 0.25)); and a direction turning linearly from
/// +x to +y over the run's first second.
#[test]
fn newborns_follow_a_periodic_speed_and_a_turning_direction() {
    check_newborns(
        "direction = { keys = [[0.0, [1.0, 0.0, 0.0]], [1.0, [0.0, 1.0, 0.0]]] }\n\
         speed = { keys = [[0.0, 2.0]], periodic = { amplitude = 0.5, period = 0.2, phase = 0.25 } }",
        |t| {
            let s = 2.0 + 0.5 * (std::f64::consts::TAU * (t / 0.2 + 0.25)).sin();
            let u = t.min(1.0) as f32;
            (s, Vec3::new(1.0 - u, u, 0.0).normalize())
        },
    );
}

fn value(src: &str) -> Animated<f32> {
    #[derive(serde::Deserialize)]
    struct Doc {
        v: Animated<f32>,
    }
    toml::from_str::<Doc>(src).unwrap().v
}

/// Smooth interpolation between three keys at quarter points, against 3u² - 2u³.
#[test]
fn smooth_keys_follow_smoothstep() {
    let c =
        value("v = { keys = [[1.0, 2.0], [3.0, -2.0], [4.0, 5.0]], interpolation = \"smooth\" }");
    let keys = [(1.0, 2.0), (3.0, -2.0), (4.0, 5.0)];
    for w in keys.windows(2) {
        let ((t0, a), (t1, b)) = (w[0], w[1]);
        for q in [0.25, 0.5, 0.75] {
            let t = t0 + q * (t1 - t0);
            let want = a + (b - a) * smoothstep(q);
            assert!((c.at(t as f32) as f64 - want).abs() < 1e-5, "t {t}");
        }
    }
    assert_eq!((c.at(0.0), c.at(10.0)), (2.0, 5.0));
}

/// Noise: the same values for the same seed, other values for another seed, never beyond its
/// amplitude around the keys, and not flat (it spans most of its range over 100 s).
#[test]
fn noise_is_deterministic_and_bounded() {
    let src = |seed| {
        format!("v = {{ keys = [[0.0, 1.0]], noise = {{ amplitude = 0.3, frequency = 4.0, seed = {seed} }} }}")
    };
    let (a, b, c) = (value(&src(7)), value(&src(7)), value(&src(8)));
    let (mut lo, mut hi, mut differ) = (f32::MAX, f32::MIN, 0);
    for i in 0..10_000 {
        let t = i as f32 * 0.01;
        let v = a.at(t);
        assert_eq!(v, b.at(t));
        assert!((v - 1.0).abs() <= 0.3 + 1e-6, "t {t}: {v}");
        differ += (v != c.at(t)) as usize;
        (lo, hi) = (lo.min(v), hi.max(v));
    }
    assert!(differ > 9_000, "{differ}");
    assert!(hi - lo > 0.4, "[{lo}, {hi}]");
    // The noise alone lies in [-1, 1] wherever it is evaluated.
    assert!((0..100_000).all(|i| value_noise(3, i as f64 * 0.137 - 5000.0).abs() <= 1.0));
}

/// `src` with `emitter` as the allocator emitter's keys fails at `line:column` with `words`.
fn refused(emitter: &str, kind: &str, at: &str, words: &str) {
    let src = format!(
        "name = \"bad\"\n[particles]\nsize = [16, 16]\n[[emitters.{kind}]]\nlife = [1.0, 1.0]\n{emitter}\n"
    );
    let e = scene::parse("bad.toml", &src).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("bad.toml:{at}: ")) && e.contains(words),
        "{e}\n{src}"
    );
}

/// Malformed curves and values out of their range over the curve are refused where they are.
#[test]
fn bad_curves_are_refused_at_their_line_and_column() {
    let ok = "direction = [0.0, 1.0, 0.0]\nspeed = 1.0";
    refused(
        &format!("rate = {{ keys = [[1.0, 5.0], [0.5, 6.0]] }}\n{ok}"),
        "allocator",
        "6:30",
        "must ascend",
    );
    refused(
        &format!("rate = {{ keys = [] }}\n{ok}"),
        "allocator",
        "6:17",
        "at least one key",
    );
    refused(
        &format!("rate = {{ keys = [[0.0, 5.0]], periodic = {{ amplitude = 1.0, period = 0.0 }} }}\n{ok}"),
        "allocator",
        "6:70",
        "period 0 s must be above 0",
    );
    // 5 - 3 - 3 < 0: the rate may go negative.
    refused(
        &format!(
            "rate = {{ keys = [[0.0, 5.0], [1.0, 9.0]], periodic = {{ amplitude = 3.0, period = 1.0 }}, \
             noise = {{ amplitude = 3.0, frequency = 1.0 }} }}\n{ok}"
        ),
        "allocator",
        "6:1",
        "rate may reach -1",
    );
    refused(
        "rate = 10.0\nspeed = 1.0\ndirection = { keys = [[0.0, [0.0, 1.0]]] }",
        "allocator",
        "8:23",
        "key 0 has 2 numbers",
    );
    refused(
        "rate = 10.0\nspeed = 1.0\ndirection = { keys = [[0.0, [1.0, 0.0, 0.0]], [1.0, [-1.0, 0.0, 0.0]]] }",
        "allocator",
        "8:1",
        "may pass through zero: between its keys it comes within 0",
    );
    refused(
        "rate = 10.0\ndirection = [0.0, 1.0, 0.0]\nspeed = { keys = [[0.0, [1.0, 2.0]]], noise = { amplitude = 1.5, frequency = 2.0 } }",
        "allocator",
        "8:1",
        "0 <= min <= max over the curve",
    );
    refused(
        "direction = [0.0, 1.0, 0.0]\nspeed = { keys = [[0.0, 1.0], [1.0, 2.0]] }",
        "initial",
        "7:1",
        "initial emitter spawns once",
    );
    refused(
        "rate = 10.0\nspeed = 1.0\ndirection = { keys = [[0.0, [0.0, 1.0, 0.0]]], periodic = { amplitude = [0.1, 0.2], period = 1.0 } }",
        "allocator",
        "8:73",
        "amplitude has 2 numbers",
    );
    refused(
        "rate = 10.0\ndirection = [0.0, 1.0, 0.0]\nspeed = [1.0]",
        "allocator",
        "8:9",
        "found an array of 1 numbers",
    );
    refused(
        &format!("rate = \"fast\"\n{ok}"),
        "allocator",
        "6:8",
        "a number, or a curve",
    );
}

/// The CPU engine takes a time-stamp emitter's curves at every step as the GPU does: after 60
/// frames of E1 with a flickering direction and speed, every live particle is where the GPU put
/// it (the tolerance of tests/bench_scenes.rs: 2e-4 m + 1e-5 relative).
#[test]
fn cpu_engine_follows_the_curves_as_the_gpu() {
    use texflow::engine::cpu::CpuSim;
    let ctx = context();
    let src = scene::builtin_source("e1").unwrap().replace(
        "direction = [0.0, 1.0, 0.0]\ncone_degrees = 30.0\nspeed = [4.0, 6.0]",
        "direction = { keys = [[0.0, [0.0, 1.0, 0.0]]], noise = { amplitude = [0.4, 0.0, 0.4], \
         frequency = 6.0, seed = 2 } }\ncone_degrees = { keys = [[0.0, 5.0], [1.0, 30.0]] }\n\
         speed = { keys = [[0.0, [4.0, 5.0]], [0.5, [5.0, 6.0]]], interpolation = \"smooth\", \
         periodic = { amplitude = 0.8, period = 0.3 } }",
    );
    let mut s = common::scene::parse("e1-curves.toml", &src);
    assert!(scene::has_curves(&s));
    s.particles.size = [32, 32];
    let mut gpu = texflow::ParticleEngine::new(&ctx, &s, 7).unwrap();
    let mut cpu = CpuSim::new(&s, 7).unwrap();
    for _ in 0..60 {
        gpu.advance_frame().unwrap();
        cpu.advance_frame();
    }
    let p = gpu.sim().read_positions().unwrap();
    let mut compared = 0;
    for i in 0..32 * 32 {
        let g = glam::Vec4::from_slice(&p[4 * i..4 * i + 4]);
        if !(g.is_finite() && g.w > 0.0 && cpu.is_live(i)) {
            continue;
        }
        let d = (cpu.positions()[i].truncate() - g.truncate()).length();
        assert!(
            d <= 2e-4 + 1e-5 * g.truncate().length(),
            "particle {i}: {d}"
        );
        compared += 1;
    }
    assert!(compared > 200, "{compared} compared");
    no_gl_error(&ctx);
}

/// The built-in `flicker`: the fire's emitter with its direction and speed as curves; it runs.
#[test]
fn flicker_varies_its_emitters_direction_and_speed() {
    let mut s = scene::load("flicker").unwrap();
    let e = &s.emitters.allocator[0];
    assert!(e.direction.curve().is_some() && e.speed.curve().is_some());
    // The direction it emits along changes from step to step.
    assert_ne!(e.direction.at(0.0), e.direction.at(0.25));
    s.particles.size = [32, 32];
    let ctx = context();
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    for _ in 0..30 {
        sim.step().unwrap();
    }
    assert!(sim.emitted().0 > 0);
    no_gl_error(&ctx);
}
