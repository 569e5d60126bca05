//! Bursts (`count` particles at `time`) on allocator and timestamp emitters, against counts worked
//! out here from the scene's numbers alone.

mod common;

use common::{context, no_gl_error};
use texflow::scene;
use texflow::sim::ParticleSim;

const DT: f64 = 0.01;

fn scene_with(kind: &str, extra: &str, bursts: &str) -> scene::SceneFile {
    let src = format!(
        "name = \"bursts\"\n[particles]\nsize = [32, 32]\n[time]\ndt = {DT}\n\
         [[emitters.{kind}]]\n{extra}direction = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n\
         life = [5.0, 5.0]\nbursts = {bursts}\n"
    );
    common::scene::parse("bursts.toml", &src)
}

fn alive(sim: &ParticleSim) -> Vec<bool> {
    let pos = sim.read_positions().unwrap();
    pos.chunks_exact(4).map(|p| p[3] > 0.0).collect()
}

/// An allocator burst fires in the step whose interval (t - dt, t] holds its time: after step k
/// (emitting at time k dt) the live particles are the bursts with time <= k dt, and nothing else
/// (no rate).
#[test]
fn allocator_bursts_add_their_counts_at_their_times() {
    let ctx = context();
    let bursts = [(0.105, 37usize), (0.305, 100)];
    let s = scene_with(
        "allocator",
        "",
        "[{ time = 0.105, count = 37 }, { time = 0.305, count = 100 }]",
    );
    let mut sim = ParticleSim::new(&ctx, &s, 5).unwrap();
    for k in 0..40u32 {
        sim.step().unwrap();
        let now = k as f64 * DT;
        let want: usize = bursts
            .iter()
            .filter(|(t, _)| *t <= now)
            .map(|(_, n)| n)
            .sum();
        let got = alive(&sim).iter().filter(|a| **a).count();
        assert_eq!(got, want, "after step {k} (time {now:.2} s)");
    }
    assert_eq!(sim.dropped_births(), 0);
    no_gl_error(&ctx);
}

/// A timestamp burst stamps the emitter's first texels with its time: 100 texels share 0.055 s
/// and the next 50 share 0.205 s; they are unborn before their time and alive after it.
#[test]
fn timestamp_bursts_share_one_time_stamp() {
    let ctx = context();
    let s = scene_with(
        "timestamp",
        "cycle = 10.0\n",
        "[{ time = 0.055, count = 100 }, { time = 0.205, count = 50 }]",
    );
    let mut sim = ParticleSim::new(&ctx, &s, 5).unwrap();
    let statics = sim.statics().read_f32().unwrap();
    let stamps: Vec<f32> = statics.chunks_exact(4).map(|t| t[0]).collect();
    assert!(
        stamps[..100].iter().all(|t| *t == 0.055f32),
        "{:?}",
        &stamps[..100]
    );
    assert!(stamps[100..150].iter().all(|t| *t == 0.205f32));
    // The rest keep phases spread over the cycle: none of them lands on a burst's time.
    assert!(stamps[150..]
        .iter()
        .all(|t| *t != 0.055f32 && *t != 0.205f32));
    let mut checked = 0;
    for _ in 0..30 {
        sim.step().unwrap();
        let t = sim.time();
        let a = alive(&sim);
        for (range, time) in [(0..100, 0.055), (100..150, 0.205)] {
            // A step away from the stamp either way, whatever side of the step the birth falls.
            if t < time - DT {
                assert!(a[range].iter().all(|x| !x), "born early at {t:.2} s");
                checked += 1;
            } else if t > time + DT {
                assert!(a[range].iter().all(|x| *x), "not born at {t:.2} s");
                checked += 1;
            }
        }
    }
    assert!(checked > 40);
    no_gl_error(&ctx);
}

/// Verlet's second-order start at every time-stamp birth (Latta eq. 9, x_prev = x0 − v0 dt +
/// a dt²/2): a particle born on its point emitter with v0 = (0, 2, 0) under gravity is, one and
/// two steps later, where the discrete closed form x_n = x0 + n v0 dt + n² a dt²/2 puts it, in
/// every cycle of 3⅓, for phases on step boundaries (bursts at 0.05, 0.1, 0.2 and 0.25 s of
/// 1/60 s steps) and spread ones alike. The start is made once, in the step after the birth
/// only: a second one would restart the motion from the spawn velocity.
#[test]
fn verlet_time_stamps_start_second_order_once_per_birth() {
    let ctx = context();
    let src = "name = \"verlet\"\nintegrator = \"verlet\"\n[particles]\nsize = [8, 8]\n\
               [time]\ndt = 0.016666668\n\
               [[emitters.timestamp]]\ncycle = 0.5\nshape = \"point\"\n\
               center = [0.0, 0.0, 0.0]\ndirection = [0.0, 1.0, 0.0]\ncone_degrees = 0.0\n\
               speed = [2.0, 2.0]\nlife = [0.3, 0.3]\n\
               bursts = [{ time = 0.05, count = 4 }, { time = 0.1, count = 4 }, \
               { time = 0.2, count = 4 }, { time = 0.25, count = 4 }]\n\
               [[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n";
    let s = common::scene::parse("verlet.toml", src);
    let mut sim = ParticleSim::new(&ctx, &s, 3).unwrap();
    let (dt, g) = (0.016666668f32 as f64, -9.81f64);
    // Steps since each particle's birth (0: born in the last step), None before it.
    let mut since: Vec<Option<usize>> = vec![None; 64];
    let mut checked = [0usize; 2];
    for step in 0..100 {
        sim.step().unwrap();
        let pos = sim.read_positions().unwrap();
        for (i, p) in pos.chunks_exact(4).enumerate() {
            if p[3] <= 0.0 {
                since[i] = None;
                continue;
            }
            if p[..3] == [0.0, 0.0, 0.0] {
                since[i] = Some(0);
                continue;
            }
            let Some(n) = since[i].map(|n| n + 1) else {
                continue;
            };
            since[i] = Some(n);
            if n <= 2 {
                let nf = n as f64;
                let want = [0.0, nf * 2.0 * dt + nf * nf * g * dt * dt / 2.0, 0.0];
                let err = (0..3)
                    .map(|a| (p[a] as f64 - want[a]).abs())
                    .fold(0.0, f64::max);
                assert!(
                    err < 1e-5,
                    "particle {i}, step {step}, {n} after its birth: {:?}, want {want:?}",
                    &p[..3]
                );
                checked[n - 1] += 1;
            }
        }
    }
    // Every particle is born 3 or 4 times in 100 steps of a 30-step cycle.
    assert!(checked.iter().all(|&c| c >= 3 * 64), "{checked:?}");
    no_gl_error(&ctx);
}

#[test]
fn bad_bursts_are_errors_at_their_place() {
    let src = |kind: &str, extra: &str, bursts: &str| {
        format!(
            "name = \"b\"\n[particles]\nsize = [8, 8]\n[[emitters.{kind}]]\n{extra}\
             direction = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\nlife = [1.0, 1.0]\n\
             bursts = {bursts}\n"
        )
    };
    let cases = [
        (
            src("initial", "", "[{ time = 0.0, count = 1 }]"),
            "belong to allocator and timestamp",
        ),
        (
            src("timestamp", "cycle = 2.0\n", "[{ time = 2.5, count = 1 }]"),
            "below the cycle",
        ),
        (
            src("allocator", "rate = 1.0\n", "[{ time = 1.0, count = 0 }]"),
            "at least 1",
        ),
        (
            src("timestamp", "cycle = 2.0\n", "[{ time = 1.0, count = 65 }]"),
            "more than the 64 texels",
        ),
        (
            src(
                "allocator",
                "",
                &format!("[{}]", ["{ time = 1.0, count = 1 }"; 5].join(", ")),
            ),
            "at most 4",
        ),
        (src("allocator", "", "[]"), "needs `rate`"),
    ];
    for (text, wanted) in cases {
        let e = scene::parse("b.toml", &text).unwrap_err().to_string();
        assert!(
            e.contains(wanted) && e.starts_with("b.toml:"),
            "`{wanted}` with a line and column expected: {e}"
        );
    }
}

/// A burst at time 0 is born like any other: the same burst at 0 and at dt gives the same
/// particles one step apart (same places, velocities and remaining lives), on time-stamp and
/// allocator emitters, with explicit and Verlet integration; none of them non-finite. The
/// emitter has no randomness (a point, one speed, one life), so one step apart is the same
/// state to rounding.
#[test]
fn a_burst_at_time_zero_is_the_burst_at_dt_one_step_earlier() {
    let ctx = context();
    let scene = |kind: &str, integrator: &str, time: f64| {
        let cycle = if kind == "timestamp" {
            "cycle = 10.0\n"
        } else {
            ""
        };
        let src = format!(
            "name = \"b\"\nintegrator = \"{integrator}\"\n[particles]\nsize = [8, 8]\n\
             [time]\ndt = {DT}\n[[emitters.{kind}]]\n{cycle}shape = \"point\"\n\
             center = [0.0, 1.0, 0.0]\ndirection = [1.0, 1.0, 0.0]\nspeed = [2.0, 2.0]\n\
             life = [5.0, 5.0]\nbursts = [{{ time = {time}, count = 8 }}]\n\
             [[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n"
        );
        common::scene::parse("b.toml", &src)
    };
    for (kind, integrator) in [
        ("timestamp", "euler"),
        ("timestamp", "verlet"),
        ("allocator", "euler"),
        ("allocator", "verlet"),
    ] {
        let what = format!("{kind}, {integrator}");
        let run = |time: f64, steps: usize| {
            let mut sim = ParticleSim::new(&ctx, &scene(kind, integrator, time), 5).unwrap();
            for _ in 0..steps {
                sim.step().unwrap();
            }
            let (p, v) = (
                sim.read_positions().unwrap(),
                sim.read_velocities().unwrap(),
            );
            let live: Vec<usize> = (0..64).filter(|&i| p[4 * i + 3] > 0.0).collect();
            let rows = |a: &[f32]| -> Vec<Vec<f32>> {
                live.iter().map(|&i| a[4 * i..4 * i + 4].to_vec()).collect()
            };
            (live.clone(), rows(&p), rows(&v))
        };
        for k in [0usize, 1, 5] {
            let (at0, p0, v0) = run(0.0, k + 1);
            let (at1, p1, v1) = run(DT, k + 2);
            assert_eq!(at0.len(), 8, "{what}: burst at 0 after {} steps", k + 1);
            assert_eq!(at0, at1, "{what}");
            for (a, b) in p0.iter().flatten().zip(p1.iter().flatten()) {
                assert!(a.is_finite(), "{what}: burst at 0: {p0:?}");
                assert!(
                    (a - b).abs() <= 1e-5 * (1.0 + a.abs()),
                    "{what}: {p0:?} vs {p1:?}"
                );
            }
            for (a, b) in v0.iter().flatten().zip(v1.iter().flatten()) {
                assert!(
                    (a - b).abs() <= 1e-3 * (1.0 + a.abs()),
                    "{what}: {v0:?} vs {v1:?}"
                );
            }
        }
    }
    no_gl_error(&ctx);
}
