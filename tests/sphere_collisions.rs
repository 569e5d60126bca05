//! Collisions between particles on the GPU against their analytic guarantees: momentum
//! conserved head-on, no NaN for coincident centres, no energy gained at rest, and detection
//! that reports only true pairs (docs/collisions.md).

mod common;

use common::scene::collide_scene;
use common::{context, no_gl_error};
use texflow::sim::ParticleSim;

/// Uploads particles (position, velocity) as type 0, permanent; the rest of the texture dead.
fn set(sim: &mut ParticleSim, particles: &[([f32; 3], [f32; 3])]) {
    common::set_particles(sim, particles, |_, _| 0.5);
}

/// Two spheres on a head-on course collide once: momentum conserved, kinetic energy too when
/// elastic, and they never pass through each other; for mass ratios 1, 10 and 100.
#[test]
fn head_on_spheres_conserve_momentum() {
    let ctx = context();
    for (ratio, e) in [
        (1.0f32, 1.0f32),
        (10.0, 1.0),
        (100.0, 1.0),
        (1.0, 0.5),
        (10.0, 0.0),
    ] {
        let s = collide_scene(
            [2, 1],
            &format!(
                "[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\nmass = {ratio}\n\
                 [collisions]\nradius = 0.1\nrestitution = {e}\nbounds = [[-2.0, -2.0, -2.0], [2.0, 2.0, 2.0]]"
            ),
        );
        let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
        // Particle 0: type 0 (mass 1) at x = -0.5 moving +x at 2 m/s; particle 1: type 1 (mass
        // `ratio`) at x = +0.5 moving -x at 1 m/s. Same y and z: a head-on course.
        let pos = vec![-0.5, 0.3, 0.2, 1.0, 0.5, 0.3, 0.2, 1.0];
        let vel = vec![2.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0];
        let st = vec![0.0, 0.0, 0.0, 0.25, 0.0, 1.0, 0.0, 0.75];
        sim.set_state(&pos, &vel, &st).unwrap();
        let m = [1.0f64, ratio as f64];
        let p0 = m[0] * 2.0 - m[1];
        let k0 = 0.5 * m[0] * 4.0 + 0.5 * m[1];
        let mut collisions = 0;
        let mut approaching = true;
        for _ in 0..100 {
            sim.step().unwrap();
            let x = sim.read_positions().unwrap();
            let v = sim.read_velocities().unwrap();
            let st = sim.statics().read_f32().unwrap();
            // The state is reordered every step: find each particle by its type.
            let (a, b) = if st[1] == 0.0 { (0, 1) } else { (1, 0) };
            let gap = (x[b * 4] - x[a * 4]) as f64;
            assert!(gap > 0.2 - 1e-4, "ratio {ratio}: passed through ({gap})");
            let (va, vb) = (v[a * 4] as f64, v[b * 4] as f64);
            let p = m[0] * va + m[1] * vb;
            assert!(
                (p - p0).abs() < 1e-5 * (1.0 + p0.abs()),
                "ratio {ratio}: momentum {p} vs {p0}"
            );
            let now = vb - va < 0.0;
            if approaching && !now {
                collisions += 1;
            }
            approaching = now;
            if e == 1.0 {
                let k = 0.5 * m[0] * va * va + 0.5 * m[1] * vb * vb;
                assert!(
                    (k - k0).abs() < 1e-5 * k0,
                    "ratio {ratio}: energy {k} vs {k0}"
                );
            }
            assert!(
                v[a * 4 + 1] == 0.0 && v[a * 4 + 2] == 0.0,
                "sideways velocity"
            );
        }
        assert_eq!(collisions, 1, "ratio {ratio} e {e}: one collision");
        no_gl_error(&ctx);
    }
}

/// Coincident centres take the fixed fallback normal: no NaN, momentum conserved.
#[test]
fn coincident_centres_give_no_nan() {
    let ctx = context();
    let s = collide_scene(
        [2, 1],
        "[collisions]\nradius = 0.1\nbounds = [[-2.0, -2.0, -2.0], [2.0, 2.0, 2.0]]",
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    let pos = vec![0.3, 0.3, 0.3, 1.0, 0.3, 0.3, 0.3, 1.0];
    let vel = vec![1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0];
    let st = vec![0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 0.75];
    sim.set_state(&pos, &vel, &st).unwrap();
    for _ in 0..10 {
        sim.step().unwrap();
        let x = sim.read_positions().unwrap();
        let v = sim.read_velocities().unwrap();
        assert!(x.iter().chain(&v).all(|f| f.is_finite()), "{x:?} {v:?}");
        let p: f32 = v[0] + v[4];
        assert!(p.abs() < 1e-5 && (v[1] + v[5]).abs() < 1e-5, "{v:?}");
    }
    no_gl_error(&ctx);
}

/// A dense box of particles at rest (touching and overlapping neighbours, no gravity) gains no
/// energy over 1,000 steps: the response only acts on approaching pairs.
#[test]
fn dense_box_at_rest_gains_no_energy() {
    let ctx = context();
    let s = collide_scene(
        [16, 16],
        "[collisions]\nradius = 0.05\nrestitution = 1.0\n\
         bounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]",
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    // 256 particles on a jittered lattice of spacing 0.09 < 2r: every neighbour overlaps; tiny
    // random velocities (1 mm/s) so that some pairs approach.
    let mut rng = texflow::sim::emit::Rng::new(1, 2, 3);
    let mut starts = Vec::new();
    for i in 0..256usize {
        let (x, y, z) = (i % 8, (i / 8) % 8, i / 64);
        let mut p = [x as f32 * 0.09, y as f32 * 0.09, z as f32 * 0.09];
        let mut v = [0.0; 3];
        for k in 0..3 {
            p[k] += (rng.uniform() - 0.5) * 0.01 - 0.3;
            v[k] = (rng.uniform() - 0.5) * 2e-3;
        }
        starts.push((p, v));
    }
    set(&mut sim, &starts);
    let energy = |sim: &ParticleSim| -> f64 {
        let v = sim.read_velocities().unwrap();
        v.chunks(4)
            .map(|c| 0.5 * (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) as f64)
            .sum()
    };
    let e0 = energy(&sim);
    let mut max_e = e0;
    for step in 0..1000 {
        sim.step().unwrap();
        if step % 50 == 49 {
            max_e = max_e.max(energy(&sim));
        }
    }
    let drift = (max_e - e0) / e0;
    eprintln!("dense box: kinetic energy {e0:.3e} J at rest, at most {max_e:.3e} J over 1000 steps (relative {drift:+.2e})");
    // Elastic exchanges keep pair energies; a pair that is not mutual (its partner chose a closer
    // one on the other lattice) can change the total a little. No growth beyond 1%.
    assert!(drift < 0.01, "energy grew by {drift}");
    no_gl_error(&ctx);
}

fn random_stats(staggered: bool, seed: u32) -> texflow::report::collide_stats::CollisionStats {
    let ctx = context();
    let s = collide_scene(
        [32, 32],
        &format!(
            "[collisions]\nradius = 0.03\nstaggered = {staggered}\n\
             bounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]"
        ),
    );
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    let mut rng = texflow::sim::emit::Rng::new(seed, 0, 11);
    let starts: Vec<([f32; 3], [f32; 3])> = (0..1024)
        .map(|_| {
            let p = [rng.uniform(), rng.uniform(), rng.uniform()];
            let v = [
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
                rng.uniform() - 0.5,
            ];
            (p, v)
        })
        .collect();
    set(&mut sim, &starts);
    sim.step().unwrap();
    let stats = texflow::report::collide_stats::Snapshot::read(sim.collisions().unwrap())
        .unwrap()
        .stats();
    no_gl_error(&ctx);
    stats
}

/// On random configurations every pair the GPU reports really overlaps, and the staggered
/// lattice misses no more than the single one.
#[test]
fn detection_reports_only_true_pairs_and_staggering_helps() {
    for seed in [1, 2, 3] {
        let single = random_stats(false, seed);
        let both = random_stats(true, seed);
        for s in [&single, &both] {
            assert_eq!(s.false_pairs, 0, "{s:?}");
            assert!(s.pairs_true > 50, "{s:?}");
            assert_eq!(s.missed, s.pairs_true - (s.found - s.false_pairs), "{s:?}");
        }
        assert_eq!(single.pairs_true, both.pairs_true);
        assert!(
            both.missed <= single.missed,
            "single {single:?}\nstaggered {both:?}"
        );
        eprintln!(
            "seed {seed}: {} true pairs; missed {} with one lattice, {} with the staggered one",
            single.pairs_true, single.missed, both.missed
        );
    }
}
