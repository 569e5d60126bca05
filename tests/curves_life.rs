//! An emitter's `life` as a curve over time (`src/scene/curve.rs`): the lives of the particles
//! born at known times, read back from the static texture, against the curve's closed form;
//! bad life curves refused at their line and column.

mod common;

use common::{context, no_gl_error};
use texflow::scene;
use texflow::sim::ParticleSim;

const DT: f64 = 0.01;

fn smoothstep(u: f64) -> f64 {
    u * u * (3.0 - 2.0 * u)
}

/// Runs an allocator scene of 64×64 particles born at 300 per second with `life` for `steps`
/// steps; returns (birth time, total life, remaining life) of every live particle.
fn newborn_lives(life: &str, steps: u32) -> Vec<(f64, f64, f64)> {
    let ctx = context();
    let src = format!(
        "name = \"lives\"\n[particles]\nsize = [64, 64]\n[time]\ndt = {DT}\n\
         [[emitters.allocator]]\nrate = 300.0\ndirection = [0.0, 1.0, 0.0]\nspeed = 0.0\n\
         life = {life}\n"
    );
    let s = common::scene::parse("lives.toml", &src);
    assert!(scene::has_curves(&s));
    let mut sim = ParticleSim::new(&ctx, &s, 5).unwrap();
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let st = sim.statics().read_f32().unwrap();
    let p = sim.read_positions().unwrap();
    no_gl_error(&ctx);
    (0..64 * 64)
        .filter(|i| p[4 * i + 3] > 0.0)
        .map(|i| (st[4 * i] as f64, st[4 * i + 2] as f64, p[4 * i + 3] as f64))
        .collect()
}

/// One number per key (min = max): every newborn's life is the curve at its birth time, smooth
/// keys 1 → 2 s over 0.5 s plus 0.3 sin(2π t / 0.2); its remaining life is that less its age.
#[test]
fn lives_follow_a_smooth_periodic_curve_at_birth() {
    let lives = newborn_lives(
        "{ keys = [[0.0, 1.0], [0.5, 2.0]], interpolation = \"smooth\", \
         periodic = { amplitude = 0.3, period = 0.2 } }",
        60,
    );
    let now = 60.0 * DT;
    // The shortest life, 0.7 s, outlasts the run: every birth is still there.
    assert!(lives.len() >= 170, "{} live", lives.len());
    for (born, life, left) in lives {
        let want = 1.0
            + smoothstep((born / 0.5).min(1.0))
            + 0.3 * (std::f64::consts::TAU * born / 0.2).sin();
        assert!(
            (life - want).abs() <= 1e-5 * want,
            "born at {born}: life {life}, want {want}"
        );
        let age = now - born;
        assert!(
            left <= life && (left - (life - age)).abs() <= 2.0 * DT + 1e-4,
            "born at {born}: {left} s left of {life} s at age {age}"
        );
    }
}

/// A range [min, max] per key, linear from [1, 2] at 0 s to [3, 5] at 1 s: every newborn's life
/// lies in the range at its birth time, spread over it (the mean fraction of the way near 1/2).
#[test]
fn lives_lie_in_the_range_of_their_birth_time() {
    let lives = newborn_lives("{ keys = [[0.0, [1.0, 2.0]], [1.0, [3.0, 5.0]]] }", 90);
    assert!(lives.len() >= 260, "{} live", lives.len());
    let mut fractions = 0.0;
    for &(born, life, _) in &lives {
        let u = born.min(1.0);
        let (lo, hi) = (1.0 + 2.0 * u, 2.0 + 3.0 * u);
        assert!(
            life >= lo - 1e-5 && life <= hi + 1e-5,
            "born at {born}: life {life} outside [{lo}, {hi}]"
        );
        fractions += (life - lo) / (hi - lo);
    }
    let mean = fractions / lives.len() as f64;
    assert!((mean - 0.5).abs() < 0.06, "mean fraction {mean}");
}

/// `src`'s emitter of `kind` with `keys` fails at `line:column` with `words`.
fn refused(kind: &str, keys: &str, at: &str, words: &str) {
    let src = format!(
        "name = \"bad\"\n[particles]\nsize = [16, 16]\n[[emitters.{kind}]]\n\
         direction = [0.0, 1.0, 0.0]\nspeed = 1.0\n{keys}\n"
    );
    let e = scene::parse("bad.toml", &src).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("bad.toml:{at}: ")) && e.contains(words),
        "{e}\n{src}"
    );
}

/// Life curves out of order or range, and where a texel's life is drawn once, are refused.
#[test]
fn bad_life_curves_are_refused_at_their_line_and_column() {
    refused(
        "allocator",
        "rate = 10.0\nlife = { keys = [[0.0, [1.0, 2.0]], [1.0, [3.0, 2.5]]] }",
        "8:1",
        "0 < min <= max over the curve",
    );
    // 1 - 0.6 - 0.6 < 0: the shortest life may go below zero.
    refused(
        "allocator",
        "rate = 10.0\nlife = { keys = [[0.0, 1.0]], periodic = { amplitude = 0.6, period = 1.0 }, \
         noise = { amplitude = 0.6, frequency = 2.0 } }",
        "8:1",
        "0 < min <= max over the curve",
    );
    refused(
        "allocator",
        "rate = 10.0\nlife = { keys = [[0.0, [1.0, 2.0, 3.0]]] }",
        "8:18",
        "key 0 has 3 numbers",
    );
    refused(
        "allocator",
        "rate = 10.0\nlife = { keys = [[1.0, 2.0], [0.5, 3.0]] }",
        "8:30",
        "must ascend",
    );
    refused(
        "timestamp",
        "cycle = 4.0\nlife = { keys = [[0.0, 1.0], [1.0, 2.0]] }",
        "8:1",
        "timestamp emitter draws each texel's life once",
    );
    refused(
        "allocator",
        "rate = 10.0\nlife = { keys = [[0.0, 1.0], [1.0, 2e9]] }",
        "8:1",
        "life 2000000000 s is above",
    );
}
