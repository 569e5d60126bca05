//! Every collider kind under every collision mode (UberFlow's detection with and without the
//! staggered lattice, the exact detection): a block of particles falls onto the collider for
//! 50 steps, and afterwards no state is non-finite and no particle is inside the collider (by the
//! CPU's own geometry: the plane, sphere and box in closed form, the height field and the
//! distance field by their CPU samplers).
//!
//! The staggered detection once left a gathered texture on the unit the response read the height
//! field from, and the first frame turned NaN; every pass now names its textures.

mod common;

use common::{context, no_gl_error};
use glam::Vec3;
use texflow::scene;
use texflow::sim::nonfinite::NonFiniteCount;
use texflow::sim::{DistanceField, HeightField, ParticleSim};

const COLLIDERS: [(&str, &str); 5] = [
    (
        "plane",
        "[[colliders.plane]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]",
    ),
    (
        "sphere",
        "[[colliders.sphere]]\ncenter = [0.0, -0.2, 0.0]\nradius = 0.4",
    ),
    (
        "box",
        "[[colliders.box]]\nmin = [-0.5, -0.5, -0.5]\nmax = [0.5, 0.1, 0.5]",
    ),
    (
        "heightfield",
        "[[colliders.heightfield]]\nextent = [-2.0, -2.0, 2.0, 2.0]\nresolution = 32\n\
         base = -0.1\namplitude = 0.1\nfrequency = 2.0\nfriction = 0.2\nresilience = 0.5",
    ),
    (
        "sdf",
        "[[colliders.sdf]]\nbounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\nresolution = 16\n\
         spheres = [[0.0, -0.2, 0.0, 0.4]]",
    ),
];

const MODES: [(&str, &str); 3] = [
    ("uberflow", "staggered = false"),
    ("uberflow staggered", "staggered = true"),
    ("exact", "detection = \"exact\"\niterations = 2"),
];

fn scene(collider: &str, mode: &str) -> scene::SceneFile {
    let src = format!(
        r#"
name = "drop"
integrator = "euler"
[particles]
size = [16, 16]
[time]
dt = 0.01
[[emitters.initial]]
shape = "box"
center = [0.0, 0.35, 0.0]
size = [0.3, 0.2, 0.3]
direction = [0.0, -1.0, 0.0]
speed = [0.5, 1.0]
[[forces.gravity]]
acceleration = [0.0, -9.81, 0.0]
{collider}
[collisions]
radius = 0.03
cell = 0.06
bounds = [[-2.0, -1.0, -2.0], [2.0, 1.0, 2.0]]
{mode}
"#
    );
    common::scene::parse("test", &src)
}

/// How far inside the collider `p` is (positive: inside).
fn inside(kind: &str, s: &scene::SceneFile, p: Vec3) -> f32 {
    let c = &s.colliders;
    match kind {
        "plane" => -p.y,
        "sphere" => 0.4 - p.distance(Vec3::new(0.0, -0.2, 0.0)),
        "box" => {
            let d = (p - Vec3::new(0.0, -0.2, 0.0)).abs() - Vec3::new(0.5, 0.3, 0.5);
            -d.max_element()
        }
        "heightfield" => {
            let h = HeightField::new(&c.heightfield[0]).unwrap();
            h.sample(p.x, p.z).0 - p.y
        }
        "sdf" => -DistanceField::new(&c.sdf[0]).unwrap().sample(p),
        _ => unreachable!(),
    }
}

#[test]
fn every_collider_under_every_collision_mode_stays_finite_and_outside() {
    let ctx = context();
    for (kind, collider) in COLLIDERS {
        for (mode, settings) in MODES {
            let s = scene(collider, settings);
            let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
            for _ in 0..50 {
                sim.step().unwrap();
            }
            let x = sim.read_positions().unwrap();
            let v = sim.read_velocities().unwrap();
            let census = NonFiniteCount::of_slices(&x, &v);
            assert!(census.is_clean(), "{kind}, {mode}: {census:?}");
            assert_eq!(census.live, 256, "{kind}, {mode}: live particles");
            let deepest = x
                .chunks(4)
                .map(|p| inside(kind, &s, Vec3::new(p[0], p[1], p[2])))
                .fold(f32::MIN, f32::max);
            // The grid colliders are sampled (bilinear, trilinear) where the CPU sampler is too,
            // up to float rounding; a particle resting on a surface sits on it.
            assert!(
                deepest < 2e-3,
                "{kind}, {mode}: a particle is {deepest} m inside the collider"
            );
            // And they reached it: the closest particle is within 1 cm of the surface.
            assert!(
                deepest > -0.01,
                "{kind}, {mode}: never reached the collider"
            );
            eprintln!("{kind}, {mode}: deepest {deepest:+.2e} m");
            no_gl_error(&ctx);
        }
    }
}
