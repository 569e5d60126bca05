//! Forces per emitter (`[[emitters.<kind>.forces.*]]`): they act on that emitter's particles
//! only (a particle's type is its emitter's place), beside the scene's `[[forces.*]]`, which act
//! on all. Checked on the GPU against the closed form of Latta's Euler step and against a CPU
//! recurrence of the same step.

mod common;

use common::{context, no_gl_error};
use texflow::scene::{self, SceneFile};
use texflow::sim::ParticleSim;

const DT: f32 = 0.01;
const STEPS: usize = 50;

/// Two initial emitters of permanent particles (types 0 and 1 alternate over the texels), 16x16,
/// Latta's Euler, with `forces` (scene and emitter tables) appended after each emitter.
fn scene(first: &str, second: &str, global: &str) -> SceneFile {
    let emitter = "[[emitters.initial]]\nshape = \"sphere\"\nradius = 0.5\n\
                   direction = [0.3, 1.0, 0.2]\ncone_degrees = 60.0\nspeed = [0.5, 2.0]\n";
    let src = format!(
        "name = \"emitter forces\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n\
         [time]\ndt = {DT:?}\n{emitter}{first}{emitter}{second}{global}"
    );
    scene::parse("emitter forces", &src).unwrap_or_else(|e| panic!("{e}\n{src}"))
}

/// Positions, velocities (xyz) and types of every particle.
fn state(sim: &ParticleSim) -> (Vec<[f32; 3]>, Vec<[f32; 3]>, Vec<usize>) {
    let xyz = |v: Vec<f32>| v.chunks(4).map(|c| [c[0], c[1], c[2]]).collect::<Vec<_>>();
    let types = sim.statics().read_f32().unwrap();
    (
        xyz(sim.read_positions().unwrap()),
        xyz(sim.read_velocities().unwrap()),
        types.chunks(4).map(|c| c[1] as usize).collect(),
    )
}

fn close(got: [f32; 3], want: [f32; 3], tol: f32) -> bool {
    (0..3).all(|k| (got[k] - want[k]).abs() <= tol * want[k].abs().max(1.0))
}

/// Gravity on emitter 0 only: its particles follow Latta's Euler fall in closed form,
/// x_n = x_0 + n dt v_0 + g dt² n(n+1)/2; emitter 1's move in straight lines, x_0 + n dt v_0.
#[test]
fn gravity_on_one_emitter_leaves_the_other_in_straight_lines() {
    let ctx = context();
    let g = [0.0f32, -9.81, 0.0];
    let s = scene(
        &format!("[[emitters.initial.forces.gravity]]\nacceleration = {g:?}\n"),
        "",
        "",
    );
    let mut sim = ParticleSim::new(&ctx, &s, 7).unwrap();
    let (x0, v0, types) = state(&sim);
    for _ in 0..STEPS {
        sim.step().unwrap();
    }
    let (x, _, _) = state(&sim);
    let n = STEPS as f32;
    let (mut fell, mut straight) = (0, 0);
    for i in 0..x.len() {
        let fall = if types[i] == 0 {
            fell += 1;
            DT * DT * n * (n + 1.0) / 2.0
        } else {
            straight += 1;
            0.0
        };
        let want: [f32; 3] = std::array::from_fn(|k| x0[i][k] + n * DT * v0[i][k] + g[k] * fall);
        assert!(
            close(x[i], want, 1e-4),
            "particle {i} of type {}: at {:?}, closed form {want:?}",
            types[i],
            x[i]
        );
    }
    assert_eq!((fell, straight), (128, 128));
    no_gl_error(&ctx);
}

/// The scene's gravity on all, emitter 0's damping and attractor, emitter 1's spring: each
/// particle against a CPU recurrence of the Euler step with its own type's forces (a force
/// applied to the wrong type is off by metres, the tolerance is 1e-4).
#[test]
fn scene_and_emitter_forces_add_per_type() {
    let ctx = context();
    let s = scene(
        "[[emitters.initial.forces.damping]]\nrate = 2.0\n\
         [[emitters.initial.forces.attractor]]\nposition = [1.0, 0.0, 0.0]\nstrength = 0.5\n",
        "[[emitters.initial.forces.spring]]\nanchor = [0.0, 2.0, 0.0]\nstiffness = 20.0\n",
        "[[forces.gravity]]\nacceleration = [0.0, -3.0, 0.0]\n",
    );
    let plan = common::plan_of(&ctx, &s).to_string();
    assert!(plan.contains("forces per emitter"), "{plan}");
    let mut sim = ParticleSim::new(&ctx, &s, 7).unwrap();
    let (mut x, mut v, types) = state(&sim);
    for _ in 0..STEPS {
        sim.step().unwrap();
        for i in 0..x.len() {
            let (p, u) = (glam::Vec3::from(x[i]), glam::Vec3::from(v[i]));
            let mut a = glam::Vec3::new(0.0, -3.0, 0.0);
            let mut f = glam::Vec3::ZERO;
            if types[i] == 0 {
                a -= 2.0 * u;
                let d = glam::Vec3::X - p;
                let q = d.length_squared() + 0.05 * 0.05;
                f += 0.5 * d / (q * q.sqrt());
            } else {
                f -= 20.0 * (p - glam::Vec3::new(0.0, 2.0, 0.0));
            }
            let vn = u + (a + f) * DT;
            x[i] = (p + vn * DT).to_array();
            v[i] = vn.to_array();
        }
    }
    let (got, _, _) = state(&sim);
    for i in 0..x.len() {
        assert!(
            close(got[i], x[i], 1e-4),
            "particle {i} of type {}: at {:?}, recurrence {:?}",
            types[i],
            got[i],
            x[i]
        );
    }
    no_gl_error(&ctx);
}

/// The CPU engine and the CPU reference model the scene's forces only: they refuse a scene with
/// forces per emitter, naming the key.
#[test]
fn cpu_twins_refuse_forces_per_emitter() {
    let s = scene(
        "[[emitters.initial.forces.gravity]]\nacceleration = [0.0, -1.0, 0.0]\n",
        "",
        "",
    );
    let e = texflow::engine::CpuSim::new(&s, 1).unwrap_err().to_string();
    assert!(e.contains("forces per emitter"), "{e}");
    let e = texflow::sim::reference::Reference::new(&s)
        .unwrap_err()
        .to_string();
    assert!(e.contains("[[emitters.*.forces.*]]"), "{e}");
}

/// The example of docs/scenes.md parses and uses both knobs.
#[test]
fn the_example_scene_has_forces_per_emitter_and_an_age_sort() {
    let s = scene::load("examples/knobs/two-falls.toml").unwrap();
    assert_eq!(s.emitters.allocator[0].forces.gravity.len(), 1);
    assert!(s.emitters.allocator[1].forces == Default::default());
    assert_eq!(s.render.sort.key, scene::SortKey::YoungestOnTop);
    assert!(texflow::sim::particles::Features::of(&s).emitter_forces);
}
