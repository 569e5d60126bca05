//! Distance constraints (Latta §3.4.3): the GPU's Verlet step and relaxation passes against the
//! CPU twin (`sim::reference::constraints`), the constraint error falling with the relaxation passes,
//! pinned particles held, and hair roots following their orbiting sphere.

mod common;

use texflow::scene::SceneFile;
use texflow::sim::reference::constraints::Twin;
use texflow::sim::ParticleSim;

/// A 16×16 cloth pinned at two corners under gravity; `extra` adds keys or sections.
fn cloth(iterations: u32, extra: &str) -> SceneFile {
    let src = format!(
        "name = \"cloth test\"\nintegrator = \"verlet\"\n[particles]\nsize = [16, 16]\n\
         [time]\ndt = 0.008333334\n\
         [[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n\
         [constraints]\nkind = \"cloth\"\niterations = {iterations}\nspacing = 0.1\n\
         origin = [-0.75, 2.0, -0.75]\npinned = [[0, 0], [15, 0]]\n{extra}"
    );
    common::scene::parse("cloth test", &src)
}

/// 8 strands of 16 particles rooted on a sphere that orbits.
fn hair(iterations: u32) -> SceneFile {
    let src = format!(
        "name = \"hair test\"\nintegrator = \"verlet\"\n[particles]\nsize = [16, 8]\n\
         [time]\ndt = 0.008333334\n\
         [[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n\
         [constraints]\nkind = \"hair\"\niterations = {iterations}\nspacing = 0.05\n\
         root_sphere = 0\n\
         [[colliders.sphere]]\ncenter = [0.4, 1.2, 0.0]\nradius = 0.3\nfriction = 0.3\n\
         resilience = 0.0\norbit = {{ radius = 0.4, period = 1.0 }}\n"
    );
    common::scene::parse("hair test", &src)
}

/// Largest |GPU - CPU| over every coordinate after `steps` steps of both.
fn gpu_against_twin(scene: &SceneFile, steps: usize) -> (f32, Vec<f32>, Twin) {
    let ctx = common::context();
    let mut sim = ParticleSim::new(&ctx, scene, 1).unwrap();
    let mut twin = Twin::new(scene).unwrap();
    for _ in 0..steps {
        sim.step().unwrap();
        twin.step();
    }
    let gpu = sim.read_positions().unwrap();
    common::no_gl_error(&ctx);
    let cpu = twin.positions();
    let worst = gpu
        .iter()
        .zip(&cpu)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, f32::max);
    eprintln!(
        "{}: largest |GPU - CPU| {worst:e} m after {steps} steps",
        scene.name
    );
    (worst, gpu, twin)
}

#[test]
fn cloth_matches_the_cpu_twin() {
    // 20 steps of 8 passes: the sheet has swung 16 mm and stretched; both sides round in f32.
    let scene = cloth(8, "");
    let (worst, gpu, twin) = gpu_against_twin(&scene, 20);
    let moved = twin
        .positions()
        .chunks(4)
        .zip(twin.layout().rest.iter())
        .map(|(x, r)| (x[1] - r[1]).abs())
        .fold(0.0f32, f32::max);
    assert!(moved > 0.01, "the sheet barely moved ({moved} m)");
    assert!(worst < 5e-6, "GPU and CPU differ by {worst} m");
    assert!(
        twin.error().worst > 1e-4,
        "no constraint was ever stretched"
    );
    // Pinned corners sit exactly on their rest positions.
    for k in [0usize, 15] {
        let r = twin.layout().rest[k];
        assert_eq!(&gpu[4 * k..4 * k + 3], &r[..3], "pinned texel {k} moved");
    }
}

#[test]
fn cloth_on_a_sphere_matches_the_cpu_twin() {
    // The sheet falls onto a sphere with friction: the Verlet step's collider response and the
    // relaxation's projection both act.
    let sphere = "[[colliders.sphere]]\ncenter = [0.0, 1.75, 0.0]\nradius = 0.3\n\
                  friction = 0.5\nresilience = 0.0\n";
    let scene = cloth(4, sphere);
    let (worst, gpu, _) = gpu_against_twin(&scene, 30);
    let c = glam::Vec3::new(0.0, 1.75, 0.0);
    let touching = gpu
        .chunks(4)
        .filter(|x| (glam::Vec3::new(x[0], x[1], x[2]) - c).length() < 0.3 + 1e-3)
        .count();
    assert!(touching > 0, "no particle reached the sphere");
    assert!(
        gpu.chunks(4)
            .all(|x| (glam::Vec3::new(x[0], x[1], x[2]) - c).length() >= 0.3),
        "a particle is inside the sphere"
    );
    assert!(worst < 2e-5, "GPU and CPU differ by {worst} m");
}

#[test]
fn hair_roots_follow_their_orbiting_sphere_as_the_twin_does() {
    let scene = hair(4);
    let steps = 30;
    let (worst, gpu, _) = gpu_against_twin(&scene, steps);
    assert!(worst < 5e-5, "GPU and CPU differ by {worst} m");
    // Roots: rest position plus the sphere's displacement at t = steps dt (closed form).
    let layout = texflow::sim::constraints::Layout::of(&scene).unwrap();
    let t = steps as f64 * scene.time.dt as f64;
    let a = std::f64::consts::TAU * t;
    let offset = [0.4 * (a.cos() - 1.0), 0.0, 0.4 * a.sin()];
    for j in 0..8 {
        let k = 16 * j;
        for c in 0..3 {
            let want = layout.rest[k][c] + offset[c] as f32;
            assert!(
                (gpu[4 * k + c] - want).abs() < 1e-5,
                "root of strand {j}: {} against {want}",
                gpu[4 * k + c]
            );
        }
    }
}

#[test]
fn constraint_error_falls_with_iterations() {
    // The same 120 steps (1 s) with 1, 4 and 16 passes per step, on the GPU, the error measured after
    // every step and averaged: more passes, a smaller mean and worst relative error. The twin's
    // averages agree with each.
    let ctx = common::context();
    let mut last: Option<(f64, f64)> = None;
    let steps = 120;
    for n in [1, 4, 16] {
        let scene = cloth(n, "");
        let mut sim = ParticleSim::new(&ctx, &scene, 1).unwrap();
        let mut twin = Twin::new(&scene).unwrap();
        let layout = sim.constraint_layout().unwrap().clone();
        let (mut mean, mut worst, mut twin_mean) = (0.0, 0.0, 0.0);
        for _ in 0..steps {
            sim.step().unwrap();
            twin.step();
            let e = layout.error(&sim.read_positions().unwrap());
            mean += e.mean / steps as f64;
            worst += e.worst / steps as f64;
            twin_mean += twin.error().mean / steps as f64;
        }
        assert!(
            (mean - twin_mean).abs() < 1e-3 * twin_mean,
            "{n} passes: GPU mean {mean} against the twin's {twin_mean}"
        );
        if let Some((m, w)) = last {
            assert!(
                mean < 0.8 * m && worst < 0.8 * w,
                "{n} passes: mean {mean} worst {worst} after mean {m} worst {w}"
            );
        }
        last = Some((mean, worst));
    }
    common::no_gl_error(&ctx);
}
