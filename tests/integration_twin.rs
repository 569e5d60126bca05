//! The integration pass against its CPU twin beyond single forces and colliders (those are in
//! tests/forces.rs and tests/colliders.rs; the harness and its tolerances in tests/twin/mod.rs):
//! the comparison itself (fp24 rounding, and `tolerance_is_not_vacuous`: it rejects a reference
//! that is wrong by less than any plausible bug), births dropped when the state texture is full,
//! fp24 scenes sorted with the paper's identifiers, and the thesis's integrators.

mod common;
mod twin;

use common::{context, no_gl_error};
use glam::Vec3;
use texflow::scene::{self};
use texflow::sim::reference::Reference;
use texflow::sim::ParticleSim;
use twin::*;

// ---------------------------------------------------------------------------------------------
// Precision and the comparison itself
// ---------------------------------------------------------------------------------------------

#[test]
fn fp24_rounding_of_the_written_state() {
    let ctx = context();
    // Each written value is rounded to a 16-bit mantissa. GPU and CPU values a few f32 ulps
    // apart can round to neighbouring fp24 values: one fp24 ulp, 2^-16 of the value.
    let tol = TOL_STEP + 1.0 / 65536.0;
    for integrator in ALL {
        let src = format!(
            "name = \"fp24\"\nintegrator = \"{integrator}\"\n[particles]\nsize = [8, 8]\n\
             precision = \"fp24\"\n[time]\ndt = 0.02\n{}{GRAVITY}\
             [[forces.damping]]\nrate = 0.3\n\
             [colliders]\n[[colliders.plane]]\npoint = [0.0, -1.0, 0.0]\n\
             normal = [0.0, 1.0, 0.0]\nresilience = 0.5\n",
            emitters(&[1.0], false)
        );
        let s = scene::parse("fp24", &src).unwrap();
        locked(&ctx, &s, &scattered(14, N, 0.9, 3.0, 1), 40, tol);
    }
    no_gl_error(&ctx);
}

#[test]
fn tolerance_is_not_vacuous() {
    let ctx = context();
    // The comparison itself: within the tolerance passes, three tolerances off fails.
    let x = Vec3::new(0.25, -3.0, 1.5);
    assert!(close("x", x * (1.0 + 0.5 * TOL_STEP), x, TOL_STEP).is_ok());
    assert!(close(
        "x",
        x + Vec3::new(0.0, 0.0, 3.0 * 3.0 * TOL_STEP),
        x,
        TOL_STEP
    )
    .is_err());
    assert!(close("x", Vec3::new(f32::INFINITY, 0.0, 0.0), x, TOL_STEP).is_err());
    assert!(close("x", Vec3::INFINITY, Vec3::INFINITY, TOL_STEP).is_ok());

    // A real run: a plane with gravity, the GPU against references that are slightly wrong.
    let plane = |resilience: f32, g: f32| {
        format!(
            "[colliders]\nslow_speed = 0.5\n[[colliders.plane]]\npoint = [0.1, -0.2, 0.3]\n\
             normal = [0.3, 1.0, -0.2]\nfriction = 0.4\nresilience = {resilience:?}\n\
             [[forces.gravity]]\nacceleration = [0.0, {g:?}, 0.0]\n"
        )
    };
    let n = Vec3::new(0.3, 1.0, -0.2).normalize();
    let surface: Vec<(Vec3, Vec3)> = (0..8)
        .map(|k| (Vec3::new(0.1 + 0.1 * k as f32, -0.2, 0.3), n))
        .collect();
    let ps = around_all(&surface, COLLIDER_DT);
    let em = emitters(&[1.0, 2.0], false);
    for integrator in ["euler", "verlet"] {
        let truth = scene(integrator, COLLIDER_DT, &em, &plane(0.8, -9.81));
        // The right reference passes...
        let mut sim = start(&ctx, &truth, &ps);
        let r = Reference::new(&truth).unwrap();
        lockstep(&mut sim, &r, &ps, 20, TOL_STEP).unwrap();
        // ... and each wrong one fails.
        let mut wrong = vec![
            (
                "resilience 0.79",
                scene(integrator, COLLIDER_DT, &em, &plane(0.79, -9.81)),
            ),
            (
                "gravity 1 % off",
                scene(integrator, COLLIDER_DT, &em, &plane(0.8, -9.71)),
            ),
        ];
        if integrator == "euler" {
            wrong.push((
                "uberflow for euler",
                scene("uberflow", COLLIDER_DT, &em, &plane(0.8, -9.81)),
            ));
        }
        for (what, s) in wrong {
            let r = Reference::new(&s).unwrap();
            let mut sim = start(&ctx, &truth, &ps);
            let res = lockstep(&mut sim, &r, &ps, 20, TOL_STEP);
            assert!(res.is_err(), "{integrator}: a reference with {what} passed");
            let mut sim = start(&ctx, &truth, &ps);
            let res = free_run(&mut sim, &r, &ps, 20, TOL_STEP);
            assert!(
                res.is_err(),
                "{integrator}: a reference with {what} passed a free run"
            );
        }
    }
    no_gl_error(&ctx);
}

// ---------------------------------------------------------------------------------------------
// Births dropped when the state texture is full
// ---------------------------------------------------------------------------------------------

/// 200 births per second of a 2 s life want 400 live particles in 16x16 = 256 texels. With
/// `dt = 0.05` each step owes exactly 10 births; the texture is full after 25.6 steps, and the
/// first index comes free (death at 2 s, reclaimed 3 steps late) after step 40. So after 40 steps
/// 400 births were asked for, 256 placed and 144 dropped; `capacity_check` predicts the overflow
/// and the texture that holds it.
#[test]
fn dropped_births_are_counted_and_predicted() {
    let ctx = context();
    let src = "name = \"full\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n\
               [time]\ndt = 0.05\n[[emitters.allocator]]\nrate = 200.0\nshape = \"point\"\n\
               direction = [0.0, 1.0, 0.0]\nspeed = [1.0, 1.0]\nlife = [2.0, 2.0]\n";
    let s = scene::parse("full", src).unwrap();
    let w = s.capacity_check().expect("400 live > 256 texels");
    assert_eq!((w.live, w.slots, w.side), (400.0, 256, 32));
    let mut sim = ParticleSim::new(&ctx, &s, 3).unwrap();
    for _ in 0..40 {
        sim.step().unwrap();
    }
    assert_eq!(sim.emitted(), (400, 144));
    assert_eq!(sim.dropped_births(), 144);
    let live = sim
        .read_positions()
        .unwrap()
        .chunks(4)
        .filter(|p| p[3] > 0.0)
        .count();
    assert_eq!(live, 256, "every texel holds a live particle");
    // The same rate in 32x32 drops nothing.
    let big = scene::parse("big", &src.replace("[16, 16]", "[32, 32]")).unwrap();
    assert_eq!(big.capacity_check(), None);
    let mut sim = ParticleSim::new(&ctx, &big, 3).unwrap();
    for _ in 0..40 {
        sim.step().unwrap();
    }
    assert_eq!(sim.dropped_births(), 0);
    no_gl_error(&ctx);
}

// ---------------------------------------------------------------------------------------------
// fp24 scenes sort with the paper's identifiers
// ---------------------------------------------------------------------------------------------

/// `smoke-unlit` at 16x16 in `precision = "fp24"`: its sort runs with UberFlow §4.3.1's identifier
/// table (24-bit floats cannot hold every index of a large texture exactly), and what it gathers
/// is still every live particle of the state, back to front from the eye, none lost or
/// duplicated: the identifiers were decoded to the right particles.
#[test]
fn fp24_scenes_sort_with_the_identifier_table() {
    let ctx = context();
    let src = scene::builtin_source("smoke-unlit")
        .unwrap()
        .replace("size = [64, 64]", "size = [16, 16]\nprecision = \"fp24\"")
        .replace("resolution = [512, 512]", "resolution = [64, 64]");
    let s = scene::parse("smoke-fp24", &src).unwrap();
    let mut engine = texflow::engine::ParticleEngine::new(&ctx, &s, 3).unwrap();
    for _ in 0..30 {
        engine.advance_frame().unwrap();
    }
    engine.draw().unwrap();
    let o = engine.sorter().expect("smoke sorts").options();
    assert!(o.id_table && o.precision.is_some(), "{o:?}");
    let eye = engine.camera().eye();
    let live = |p: &[f32]| p[3] > 0.0;
    let mut state: Vec<[u32; 3]> = engine
        .sim()
        .read_positions()
        .unwrap()
        .chunks(4)
        .filter(|p| live(p))
        .map(|p| [p[0].to_bits(), p[1].to_bits(), p[2].to_bits()])
        .collect();
    let sorted: Vec<Vec3> = engine
        .sorted()
        .unwrap()
        .texture(0)
        .read_f32()
        .unwrap()
        .chunks(4)
        .filter(|p| live(p))
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect();
    assert!(state.len() > 100, "{} live particles", state.len());
    let mut got: Vec<[u32; 3]> = sorted
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect();
    state.sort();
    got.sort();
    assert_eq!(
        got, state,
        "the sort gathered other particles than the state's"
    );
    // Back to front: distances do not increase, up to the keys' 16-bit mantissa.
    for w in sorted.windows(2) {
        let (a, b) = (w[0].distance(eye), w[1].distance(eye));
        assert!(b <= a * (1.0 + 1e-4), "{a} then {b}");
    }
    no_gl_error(&ctx);
}

// ---------------------------------------------------------------------------------------------
// The thesis's integrators (§2.1)
// ---------------------------------------------------------------------------------------------

/// Heun, RK4 and leapfrog (`glsl/sim/stages.glsl`) against the reference's `stages`, with
/// gravity, damping, a vortex, an attractor and a wind at once (every force the reference
/// models), so that each stage evaluates them at a state of its own (a wrong stage
/// weight or a stage evaluated at the wrong state is off by O(dt²), thousands of tolerances),
/// then with a sphere collider, whose response re-advances a stage-integrated step.
#[test]
fn thesis_integrators_match_the_reference() {
    let ctx = context();
    let body = "[[forces.gravity]]\nacceleration = [0.5, -9.81, 0.25]\n\
                [[forces.damping]]\nrate = 0.4\n\
                [[forces.vortex]]\npoint = [0.2, 0.0, -0.1]\naxis = [1.0, 2.0, 0.5]\n\
                strength = 1.2\n\
                [[forces.attractor]]\nposition = [0.0, 1.0, 0.0]\nstrength = 2.0\n\
                softening = 0.3\n\
                [[forces.wind]]\nvelocity = [1.0, 0.2, -0.5]\nturbulence = 0.8\n\
                resolution = 9\nbounds = [[-1.0, -0.5, -1.5], [1.5, 2.0, 1.0]]\ndrag = 2.5\n";
    let sphere = "[colliders]\nslow_speed = 0.5\n[[colliders.sphere]]\n\
                  center = [0.2, 0.1, -0.3]\nradius = 0.6\nfriction = 0.3\nresilience = 0.8\n";
    let dirs = [
        Vec3::X,
        -Vec3::X,
        Vec3::Y,
        -Vec3::Y,
        Vec3::Z,
        -Vec3::Z,
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(-1.0, 0.5, -2.0),
    ];
    let surface: Vec<(Vec3, Vec3)> = dirs
        .iter()
        .map(|d| {
            (
                Vec3::new(0.2, 0.1, -0.3) + 0.6 * d.normalize(),
                d.normalize(),
            )
        })
        .collect();
    for integrator in ["heun", "rk4", "leapfrog"] {
        let s = scene(integrator, 0.02, &emitters(&[1.0, 2.0], false), body);
        both(&ctx, &s, &scattered(7, N, 2.0, 3.0, 2), 50, TOL_STEP);
        let s = scene(
            integrator,
            COLLIDER_DT,
            &emitters(&[1.0, 2.0], false),
            &format!("{sphere}{GRAVITY}"),
        );
        let sum = locked(
            &ctx,
            &s,
            &around_all(&surface, COLLIDER_DT),
            COLLIDER_STEPS,
            TOL_STEP,
        );
        assert!(sum.events.hits > 0, "{integrator}: {:?}", sum.events);
        assert!(sum.deepest >= -TOL_STEP, "{integrator}: left inside");
    }
    no_gl_error(&ctx);
}
