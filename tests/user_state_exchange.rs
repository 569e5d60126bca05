//! User states in the collision stage (`[[state]]` with `[collisions]`, src/sim/collide/carry.rs):
//! the states follow their particles through the cell sorts, and `pair` exchanges a state with
//! the neighbours the exact search finds, against a CPU twin of one step and the conservation of
//! a symmetric exchange.

mod common;

use common::context;
use texflow::scene::{self, SceneFile};
use texflow::sim::ParticleSim;

/// Particles on a lattice of `SPACING` (jittered by up to `JITTER` per axis), at rest: closer
/// than `REACH` along the axes, farther on the diagonals, never in contact (2 × 0.11 m).
const SPACING: f32 = 0.25;
const JITTER: f32 = 0.01;
const REACH: f32 = 0.3;
const K: f32 = 0.2;

/// The exchange scene: 16×16 texels, `[collisions]` with the exact detection, and a state with
/// `pair` (a diffusion of temperature.x weighted by 1 − r / REACH; .y the particle's id).
fn exchange_scene(extra: &str) -> SceneFile {
    scene::parse("exchange.toml", &exchange_source(extra)).expect("a valid scene")
}

/// The text of [`exchange_scene`].
fn exchange_source(extra: &str) -> String {
    format!(
        "name = \"exchange\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n\
         [time]\ndt = 0.05\n[[emitters.initial]]\nshape = \"box\"\ncenter = [0.0, 0.0, 0.0]\n\
         size = [1.0, 1.0, 1.0]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n\
         [collisions]\nradius = 0.11\ncell = {REACH}\ndetection = \"exact\"\n\
         bounds = [[-0.5, -0.5, -0.5], [2.5, 2.5, 1.5]]\n\
         [[state]]\nname = \"temperature\"\n\
         init = \"vec4(300.0 + 400.0 * random, float(index), 0.0, 0.0)\"\n\
         pair = \"vec4({K:?} * (other.temperature.x - temperature.x) * (1.0 - r / {REACH:?}), \
         0.0, 0.0, 0.0)\"\nradius = {REACH}\n{extra}"
    )
}

/// 240 particles (8 × 6 × 5) on the jittered lattice; the last 16 texels dead.
fn lattice() -> Vec<([f32; 3], [f32; 3])> {
    let mut out = Vec::new();
    let mut h = 12345u32;
    let mut jitter = || {
        h = h.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
        ((h >> 8) as f32 / (1u32 << 24) as f32 * 2.0 - 1.0) * JITTER
    };
    for z in 0..5 {
        for y in 0..6 {
            for x in 0..8 {
                let p = [x, y, z].map(|c| c as f32 * SPACING);
                out.push((
                    [p[0] + jitter(), p[1] + jitter(), p[2] + jitter()],
                    [0.0; 3],
                ));
            }
        }
    }
    out
}

fn texel(a: &[f32], i: usize) -> [f32; 4] {
    [a[4 * i], a[4 * i + 1], a[4 * i + 2], a[4 * i + 3]]
}

/// The simulation on the lattice after one step (so that every texel's value at birth is set
/// and the particles are in cell order).
fn settled(ctx: &texflow::gl::Context, s: &SceneFile) -> ParticleSim {
    let mut sim = ParticleSim::new(ctx, s, 7).unwrap();
    common::set_particles(&mut sim, &lattice(), |i, n| (i as f32 + 0.5) / n as f32);
    sim.step().unwrap();
    sim
}

#[test]
fn one_exchange_step_follows_its_cpu_twin() {
    let ctx = context();
    let s = exchange_scene("");
    let mut sim = settled(&ctx, &s);
    let pos = sim.read_positions().unwrap();
    let before = sim.read_user_state("temperature").unwrap();
    sim.step().unwrap();
    let after = sim.read_user_state("temperature").unwrap();
    let pos_after = sim.read_positions().unwrap();
    let n = 256;
    // The twin, in f32: T_i + Σ_j k (T_j − T_i) (1 − r / R) over the live j closer than R.
    let live: Vec<usize> = (0..n).filter(|&i| pos[4 * i + 3] > 0.0).collect();
    assert_eq!(live.len(), 240);
    let mut want = std::collections::HashMap::new();
    let mut paired = 0;
    for &i in &live {
        let (pi, ti) = (texel(&pos, i), texel(&before, i));
        let (mut sum, mut scale) = (0.0f32, ti[0].abs());
        for &j in &live {
            let pj = texel(&pos, j);
            let r = ((pj[0] - pi[0]).powi(2) + (pj[1] - pi[1]).powi(2) + (pj[2] - pi[2]).powi(2))
                .sqrt();
            if j != i && r < REACH {
                let term = K * (texel(&before, j)[0] - ti[0]) * (1.0 - r / REACH);
                sum += term;
                scale += term.abs();
                paired += 1;
            }
        }
        want.insert(ti[1] as u32, (ti[0] + sum, scale, pi));
    }
    // Every particle has its axis neighbours: the search found pairs to sum.
    assert!(
        paired >= 2 * (7 * 6 * 5 + 8 * 5 * 5 + 8 * 6 * 4),
        "{paired} pairs"
    );
    let mut seen = 0;
    for i in 0..n {
        let (p, t) = (texel(&pos_after, i), texel(&after, i));
        if p[3] <= 0.0 {
            continue;
        }
        let (w, scale, at) = want[&(t[1] as u32)];
        // The state followed its particle through the sort: the same place.
        assert_eq!([p[0], p[1], p[2]], [at[0], at[1], at[2]], "texel {i}");
        // float32 rounding of a sum in another order, and of the distance.
        assert!(
            (t[0] - w).abs() <= 4e-6 * scale,
            "particle {}: {} != twin {w}",
            t[1],
            t[0]
        );
        seen += 1;
    }
    assert_eq!(seen, 240);
    common::no_gl_error(&ctx);
}

#[test]
fn a_symmetric_exchange_conserves_the_total() {
    let ctx = context();
    let s = exchange_scene("");
    let mut sim = settled(&ctx, &s);
    let total_spread = |sim: &ParticleSim| {
        let (p, t) = (
            sim.read_positions().unwrap(),
            sim.read_user_state("temperature").unwrap(),
        );
        let v: Vec<f64> = (0..256)
            .filter(|&i| p[4 * i + 3] > 0.0)
            .map(|i| t[4 * i] as f64)
            .collect();
        let lo = v.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        (v.iter().sum::<f64>(), hi - lo)
    };
    let (total0, spread0) = total_spread(&sim);
    for _ in 0..30 {
        sim.step().unwrap();
    }
    let (total, spread) = total_spread(&sim);
    // Each pair's terms are exact opposites; only the f32 sums round.
    assert!(
        (total - total0).abs() <= 1e-5 * total0,
        "total {total} != {total0}"
    );
    // And the exchange did diffuse the temperature.
    assert!(spread < 0.5 * spread0, "spread {spread0} -> {spread}");
    common::no_gl_error(&ctx);
}

/// A pile falling onto the ground with `collisions` (keys of the table), and a state holding
/// the particle's static random number, its index at birth and its height at birth.
fn pile(collisions: &str) -> SceneFile {
    let src = format!(
        "name = \"carry\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n\
         [time]\ndt = 0.02\n[[emitters.initial]]\nshape = \"box\"\ncenter = [0.0, 0.4, 0.0]\n\
         size = [0.5, 0.5, 0.5]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n\
         [[forces.gravity]]\nacceleration = [0.0, -9.8, 0.0]\n\
         [[colliders.plane]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\n\
         [collisions]\nradius = 0.03\nbounds = [[-1.0, -0.1, -1.0], [1.0, 1.5, 1.0]]\n\
         {collisions}\n[[state]]\nname = \"tag\"\n\
         init = \"vec4(random, float(index), x.y, 0.0)\"\n"
    );
    scene::parse("carry.toml", &src).expect("a valid scene")
}

#[test]
fn states_follow_their_particles_through_the_sorts() {
    let ctx = context();
    for collisions in [
        "detection = \"exact\"\niterations = 2",
        "staggered = true",
        "detection = \"uberflow\"",
    ] {
        let s = pile(collisions);
        let mut sim = ParticleSim::new(&ctx, &s, 5).unwrap();
        for _ in 0..40 {
            sim.step().unwrap();
        }
        let tag = sim.read_user_state("tag").unwrap();
        let statics = sim.statics().read_f32().unwrap();
        let pos = sim.read_positions().unwrap();
        let (mut moved, mut fell) = (0, 0);
        for i in 0..256 {
            let t = texel(&tag, i);
            // The static texel is carried by the stage itself: the state must sit beside it.
            assert_eq!(t[0], statics[4 * i + 3], "{collisions}: texel {i}");
            moved += (t[1] != i as f32) as usize;
            fell += (pos[4 * i + 1] < t[2] - 0.1) as usize;
        }
        // The sorts did reorder the particles: the check above could fail.
        assert!(
            moved > 128,
            "{collisions}: only {moved} texels changed particle"
        );
        assert!(
            fell > 128,
            "{collisions}: only {fell} particles fell below their start"
        );
    }
    common::no_gl_error(&ctx);
}

#[test]
fn bad_exchanges_are_refused_at_their_line_and_column() {
    let src = exchange_source("");
    let line_of =
        |needle: &str, s: &str| s.lines().position(|l| l.starts_with(needle)).unwrap() + 1;
    for (from, to, key, want) in [
        (
            "radius = 0.3\n",
            "radius = 0.0\n",
            "radius = 0.0",
            "must be above 0",
        ),
        (
            "radius = 0.3\n",
            "radius = 0.5\n",
            "radius = 0.5",
            "at most the collision cell",
        ),
        ("radius = 0.3\n", "", "pair =", "pair needs radius"),
        (
            "detection = \"exact\"\n",
            "",
            "pair =",
            "exact collision detection",
        ),
        (
            "pair = \"vec4(",
            "pair = \"{ vec4(",
            "pair =",
            "one GLSL vec4 expression",
        ),
        (
            "name = \"temperature\"",
            "name = \"r\"",
            "name = \"r\"",
            "is taken",
        ),
    ] {
        let bad = src.replacen(from, to, 1);
        let e = scene::parse("bad.toml", &bad).unwrap_err().to_string();
        let at = format!("bad.toml:{}:", line_of(key, &bad));
        assert!(
            e.contains(&at) && e.contains(want),
            "{to:?}: {e} (want {at})"
        );
    }
    // Radius without pair.
    let bad = src.replacen("pair = ", "# pair = ", 1);
    let e = scene::parse("bad.toml", &bad).unwrap_err().to_string();
    assert!(e.contains("radius is the reach of `pair`"), "{e}");
}

#[test]
fn unknown_names_in_pair_name_the_key() {
    let ctx = context();
    let src = exchange_source("").replace("other.temperature.x", "other.heat.x");
    let line = src.lines().position(|l| l.starts_with("pair =")).unwrap() + 1;
    let s = scene::parse("exchange.toml", &src).unwrap();
    let e = match ParticleSim::new(&ctx, &s, 1) {
        Ok(_) => panic!("an unknown name compiled"),
        Err(e) => e.to_string(),
    };
    assert!(
        e.contains("user state `temperature`") && e.contains("heat"),
        "{e}"
    );
    assert!(
        e.contains(&format!(
            "state.temperature.pair is at exchange.toml:{line}:"
        )),
        "{e}"
    );
    // `scene check` compiles the exchange too.
    let e = texflow::sim::particles::check_user_states(&ctx, &s)
        .unwrap_err()
        .to_string();
    assert!(e.contains("heat"), "{e}");
}
