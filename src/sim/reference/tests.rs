//! Unit tests of the twin.

use super::colliders::box_distance;
use super::*;
use crate::scene::parse;

const HEAD: &str = r#"
name = "reference"
[particles]
size = [2, 2]
[time]
dt = 0.125
[[emitters.initial]]
shape = "point"
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
"#;

fn scene(integrator: &str, rest: &str) -> Reference {
    let src = format!("integrator = \"{integrator}\"\n{HEAD}{rest}");
    Reference::new(&parse("test", &src).unwrap()).unwrap()
}

#[test]
fn reference_euler_and_uberflow_under_gravity_are_exact_on_dyadic_numbers() {
    // dt = 1/8 and g = -8: every product is exact, so the formulas give the exact values.
    let g = "[[forces.gravity]]\nacceleration = [0.0, -8.0, 0.0]\n";
    let x = Vec3::new(1.0, 2.0, 3.0);
    let v = Vec3::new(0.5, 1.0, 0.0);
    let (xe, ve, _) = scene("euler", g).step_explicit(x, v, 1.0, 0);
    assert_eq!(ve, Vec3::new(0.5, 0.0, 0.0));
    assert_eq!(xe, x + ve * 0.125);
    let (xu, vu, _) = scene("uberflow", g).step_explicit(x, v, 1.0, 0);
    assert_eq!(vu, ve);
    assert_eq!(xu, Vec3::new(1.0625, 2.0625, 3.0));
    // Verlet from its second-order start reproduces x + v dt + a dt^2 / 2.
    let r = scene("verlet", g);
    let xp = r.verlet_start(x, v, 0);
    let (xv, _) = r.step_verlet(x, xp, 1.0, 0);
    assert_eq!(xv, Vec3::new(1.0625, 2.0625, 3.0));
}

#[test]
fn reference_life_counts_down_and_kills() {
    let src = format!(
        "integrator = \"euler\"\n{}\nlife = [1.0, 1.0]\n",
        HEAD.trim_end()
    );
    let r = Reference::new(&parse("test", &src).unwrap()).unwrap();
    assert!(r.has_life());
    let (_, _, l) = r.step_explicit(Vec3::ZERO, Vec3::ZERO, 0.5, 0);
    assert_eq!(l, 0.375);
    let (x, v, l, ev) = r.step_explicit_events(Vec3::ZERO, Vec3::ONE, 0.125, 0);
    assert!(ev.dead && l == 0.0 && x == Vec3::INFINITY && v == Vec3::ZERO);
    let (_, _, l) = r.step_explicit(Vec3::ZERO, Vec3::ONE, -1.0, 0);
    assert_eq!(l, -1.0);
    // Permanent particles keep their w.
    let (_, _, l) = scene("euler", "").step_explicit(Vec3::ZERO, Vec3::ZERO, 1.0, 0);
    assert_eq!(l, 1.0);
}

#[test]
fn reference_plane_bounce_reflects_and_friction_spares_slow_particles() {
    let plane = "[colliders]\nslow_speed = 0.5\n[[colliders.plane]]\npoint = [0.0, 0.0, 0.0]\n\
                 normal = [0.0, 1.0, 0.0]\nfriction = 0.5\nresilience = 0.5\n";
    let r = scene("euler", plane);
    // Hits during the step: v = (1, -2, 0) -> (0.5, 1, 0), moved from x.
    let x = Vec3::new(0.0, 0.125, 0.0);
    let (xb, vb, _, ev) = r.step_explicit_events(x, Vec3::new(1.0, -2.0, 0.0), 1.0, 0);
    assert_eq!((ev.hits, ev.slow, ev.caught), (1, 0, 0));
    assert_eq!(vb, Vec3::new(0.5, 1.0, 0.0));
    assert_eq!(xb, x + vb * 0.125);
    // Slow: no friction.
    let (_, vb, _, ev) = r.step_explicit_events(
        Vec3::new(0.0, 0.01, 0.0),
        Vec3::new(0.25, -0.25, 0.0),
        1.0,
        0,
    );
    assert_eq!((ev.hits, ev.slow), (1, 1));
    assert_eq!(vb, Vec3::new(0.25, 0.125, 0.0));
    // Caught inside: pushed out to SKIN, velocity mirrored.
    let (xb, vb, _, ev) =
        r.step_explicit_events(Vec3::new(0.0, -0.5, 0.0), Vec3::new(0.0, -1.0, 0.0), 1.0, 0);
    assert_eq!(ev.caught, 1);
    assert_eq!(vb, Vec3::new(0.0, 1.0, 0.0));
    assert!((xb.y - (SKIN + 0.125)).abs() < 1e-6, "{xb}");
}

#[test]
fn reference_box_distance_picks_the_nearest_face_inside() {
    let (lo, hi) = (Vec3::ZERO, Vec3::new(2.0, 4.0, 6.0));
    assert_eq!(
        box_distance(lo, hi, Vec3::new(0.25, 2.0, 3.0)),
        (-0.25, -Vec3::X)
    );
    assert_eq!(
        box_distance(lo, hi, Vec3::new(1.0, 3.5, 3.0)),
        (-0.5, Vec3::Y)
    );
    let (d, n) = box_distance(lo, hi, Vec3::new(3.0, 5.0, 3.0));
    assert!(
        (d - 2f32.sqrt()).abs() < 1e-6
            && (n - Vec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-6
    );
}

#[test]
fn reference_rejects_what_it_does_not_model() {
    let src = format!(
        "integrator = \"euler\"\n{}",
        HEAD.replace("[particles]", "[particles]\nvelocity_format = \"rgba16f\"")
    );
    assert!(Reference::new(&parse("test", &src).unwrap()).is_err());
    let src = HEAD.replace(
        "[[emitters.initial]]",
        "[[emitters.timestamp]]\ncycle = 2.0\nlife = [1.0, 1.0]",
    );
    assert!(Reference::new(&parse("test", &src).unwrap()).is_err());
}
