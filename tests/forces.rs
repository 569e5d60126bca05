//! Every force of the integration pass (glsl/sim/integrate.frag, glsl/sim/forces.glsl) and life
//! on the GPU against its CPU twin, `texflow::sim::reference::Reference`, in lockstep and in a
//! free run (the harness and its tolerances: tests/twin/mod.rs); the papers' forms of the wind
//! and the vortex, a mass per particle, and user forces.

mod common;
mod twin;

use common::scene::Rng;
use common::{context, no_gl_error};
use glam::Vec3;
use texflow::gl::Context;
use texflow::scene::SceneFile;
use texflow::sim::reference::Reference;
use texflow::sim::ParticleSim;
use twin::*;

// ---------------------------------------------------------------------------------------------
// Forces
// ---------------------------------------------------------------------------------------------

#[test]
fn gravity() {
    let ctx = context();
    // Two types of different mass: gravity is an acceleration, the same for both.
    let body = "[[forces.gravity]]\nacceleration = [0.5, -9.81, 0.25]\n\
                [[forces.gravity]]\nacceleration = [0.0, -0.19, 0.0]\n";
    for integrator in ALL {
        let s = scene(integrator, 1.0 / 60.0, &emitters(&[1.0, 3.0], false), body);
        both(&ctx, &s, &scattered(1, N, 2.0, 3.0, 2), 50, TOL_STEP);
    }
    no_gl_error(&ctx);
}

#[test]
fn damping() {
    let ctx = context();
    // Two entries sum to one rate; a negative rate un-damps.
    for (rates, seed) in [([0.8f32, -0.3], 2), ([-0.4, 0.0], 3)] {
        let body = format!(
            "[[forces.damping]]\nrate = {:?}\n[[forces.damping]]\nrate = {:?}\n",
            rates[0], rates[1]
        );
        for integrator in ALL {
            let s = scene(integrator, 0.02, &emitters(&[1.0, 2.0], false), &body);
            both(&ctx, &s, &scattered(seed, N, 2.0, 4.0, 2), 50, TOL_STEP);
        }
    }
    no_gl_error(&ctx);
}

#[test]
fn wind() {
    let ctx = context();
    let body = "[[forces.wind]]\nvelocity = [1.0, 0.2, -0.5]\nturbulence = 0.8\nresolution = 9\n\
                bounds = [[-1.0, -0.5, -1.5], [1.5, 2.0, 1.0]]\ndrag = 2.5\n";
    // Inside the bounds and outside (where the field is clamped).
    let mut ps = scattered(4, 48, 1.0, 1.0, 2);
    ps.extend(scattered(5, 16, 3.0, 1.0, 2));
    for integrator in ALL {
        let s = scene(integrator, 0.02, &emitters(&[1.0, 0.5], false), body);
        both(&ctx, &s, &ps, 50, TOL_STEP);
    }
    no_gl_error(&ctx);
}

/// Particles at the centre `c` (no force), inside the softening radius, between, and beyond the
/// maximum distance, in every direction.
fn around_point(c: Vec3, radii: &[f32], seed: u64) -> Vec<P> {
    let mut rng = Rng(seed);
    let mut ps = vec![p(c, Vec3::new(0.1, 0.0, 0.0))];
    for (i, r) in radii.iter().cycle().take(N - 1).enumerate() {
        let dir = rng.vec(-1.0, 1.0).normalize();
        ps.push(P {
            ty: i % 2,
            ..p(c + r * dir, rng.vec(-0.5, 0.5))
        });
    }
    ps
}

#[test]
fn attractor_inverse_square() {
    let ctx = context();
    // An attractor with a wide softening and no maximum distance, and a repulsor with the
    // default softening (0.05) and a maximum distance of 1.5.
    let body = "[[forces.attractor]]\nposition = [0.3, -0.2, 0.1]\nstrength = 2.0\n\
                softening = 0.2\n\
                [[forces.attractor]]\nposition = [-0.5, 0.4, 0.0]\nstrength = -1.0\n\
                max_distance = 1.5\n";
    let mut ps = around_point(Vec3::new(0.3, -0.2, 0.1), &[0.1, 0.3, 0.8, 2.5], 6);
    ps.truncate(32);
    ps.extend(around_point(Vec3::new(-0.5, 0.4, 0.0), &[0.03, 0.4, 1.2, 1.8], 7).drain(..32));
    for integrator in ALL {
        let s = scene(integrator, 0.01, &emitters(&[1.0, 2.0], false), body);
        both(&ctx, &s, &ps, 50, TOL_STEP);
    }
    no_gl_error(&ctx);
}

#[test]
fn attractor_constant() {
    let ctx = context();
    let body = "[[forces.attractor]]\nposition = [0.2, 0.1, -0.3]\nstrength = 1.5\n\
                falloff = \"constant\"\nmax_distance = 1.0\n\
                [[forces.attractor]]\nposition = [-0.4, 0.0, 0.5]\nstrength = -0.7\n\
                falloff = \"constant\"\n";
    let mut ps = around_point(Vec3::new(0.2, 0.1, -0.3), &[0.05, 0.5, 0.9, 1.3, 3.0], 8);
    ps.truncate(40);
    ps.extend(around_point(Vec3::new(-0.4, 0.0, 0.5), &[0.2, 2.0], 9).drain(..24));
    for integrator in ALL {
        let s = scene(integrator, 0.02, &emitters(&[1.0, 0.25], false), body);
        both(&ctx, &s, &ps, 50, TOL_STEP);
    }
    no_gl_error(&ctx);
}

#[test]
fn vortex() {
    let ctx = context();
    // A tilted axis given unnormalised, and a counter-rotating one along z.
    let body = "[[forces.vortex]]\npoint = [0.2, 0.0, -0.1]\naxis = [1.0, 2.0, 0.5]\n\
                strength = 1.2\n\
                [[forces.vortex]]\npoint = [0.2, 0.0, -0.1]\naxis = [0.0, 0.0, 3.0]\n\
                strength = -0.5\n";
    let mut ps = scattered(10, 40, 1.5, 0.5, 2);
    // Exactly on the z axis (no force from it), inside the core radius 0.1 and just outside.
    ps.push(p(Vec3::new(0.2, 0.0, 5.0), Vec3::ZERO));
    let mut rng = Rng(11);
    for i in 0..23 {
        let r = [0.05, 0.09, 0.12, 0.3][i % 4];
        let a = rng.range(0.0, std::f32::consts::TAU);
        ps.push(P {
            ty: i % 2,
            ..p(
                Vec3::new(0.2 + r * a.cos(), r * a.sin(), rng.range(-1.0, 1.0)),
                rng.vec(-0.2, 0.2),
            )
        });
    }
    for integrator in ALL {
        let s = scene(integrator, 0.01, &emitters(&[1.0, 2.0], false), body);
        both(&ctx, &s, &ps, 50, TOL_STEP);
    }
    no_gl_error(&ctx);
}

#[test]
fn inverse_mass_per_type() {
    let ctx = context();
    // Four types (the most a scene has) with different masses, under an attractor and a vortex
    // (forces, divided by the mass) and gravity (an acceleration, not divided).
    let body = "[[forces.gravity]]\nacceleration = [0.0, -2.0, 0.0]\n\
                [[forces.attractor]]\nposition = [0.0, 0.0, 0.0]\nstrength = 1.0\n\
                softening = 0.3\n\
                [[forces.vortex]]\npoint = [0.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\n\
                strength = 2.0\n";
    let ps = scattered(12, N, 1.5, 0.5, 4);
    let masses = [0.5, 1.0, 2.0, 4.0];
    for integrator in ALL {
        let s = scene(integrator, 0.02, &emitters(&masses, false), body);
        both(&ctx, &s, &ps, 50, TOL_STEP);
        // The same particle feels the force in inverse proportion to its type's mass.
        let r = Reference::new(&s).unwrap();
        let (x, v) = (Vec3::new(1.0, 0.5, 0.0), Vec3::ZERO);
        let g = Vec3::new(0.0, -2.0, 0.0);
        let f0 = (r.acceleration(x, v, 0) - g) * masses[0];
        for (ty, m) in masses.iter().enumerate() {
            let f = (r.acceleration(x, v, ty) - g) * m;
            assert!(
                (f - f0).length() < 1e-5 * f0.length(),
                "type {ty}: {f} vs {f0}"
            );
        }
    }
    no_gl_error(&ctx);
}

// ---------------------------------------------------------------------------------------------
// Life
// ---------------------------------------------------------------------------------------------

#[test]
fn life_counts_down_and_the_dead_go_to_infinity() {
    let ctx = context();
    let dt = 0.05f32;
    let body = "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n";
    let mut rng = Rng(13);
    let lives = [1.0, 0.05, dt + 1e-6, 0.12, 0.5, 0.0, -1.0, 2.0 * dt];
    let ps: Vec<P> = (0..N)
        .map(|i| {
            let life = lives[i % lives.len()];
            let x = if life > 0.0 {
                rng.vec(-1.0, 1.0)
            } else {
                Vec3::INFINITY
            };
            P {
                life,
                total: 1.0,
                ..p(x, rng.vec(-1.0, 1.0))
            }
        })
        .collect();
    for integrator in ALL {
        let s = scene(integrator, dt, &emitters(&[1.0], true), body);
        let r = Reference::new(&s).unwrap();
        assert!(r.has_life());
        let sum = both(&ctx, &s, &ps, 20, TOL_STEP);
        assert!(sum.events.dead);
        // After 20 steps (1 s) every particle is dead: at infinity.
        let mut sim = start(&ctx, &s, &ps);
        for _ in 0..20 {
            sim.step().unwrap();
        }
        let st = read(&sim);
        for i in 0..N {
            assert_eq!(st.x[i], Vec3::INFINITY, "{integrator}: particle {i}");
            assert!(st.w[i] <= 0.0);
        }
    }
    no_gl_error(&ctx);
}

// ---------------------------------------------------------------------------------------------
// The papers' forms of the wind and the vortex, and a mass per particle
// ---------------------------------------------------------------------------------------------

/// A steady wind (no turbulence): the flow field is `w` everywhere.
fn steady_wind(form: &str, drag: &str) -> String {
    format!(
        "[[forces.wind]]\nform = \"{form}\"\nvelocity = [1.0, 0.0, 0.5]\nturbulence = 0.0\n\
         resolution = 4\nbounds = [[-5.0, -5.0, -5.0], [5.0, 5.0, 5.0]]\n{drag}"
    )
}

/// One Euler step of a particle at rest at the origin of type `ty`: its new velocity.
fn one_euler_step(ctx: &Context, s: &SceneFile, ty: usize) -> Vec3 {
    let mut sim = start(
        ctx,
        s,
        &[P {
            ty,
            ..p(Vec3::ZERO, Vec3::ZERO)
        }],
    );
    sim.step().unwrap();
    let v = sim.read_velocities().unwrap();
    Vec3::new(v[0], v[1], v[2])
}

/// Latta eq. 1-2 divide the drag by the mass; the default drag (an acceleration) does not;
/// UberFlow eq. 1 adds the wind velocity itself. Closed forms after one Euler step from rest:
/// `Δv = k w dt`, `Δv = c w dt / m`, `Δv = w`. Then every integrator against the twin.
#[test]
fn wind_forms_as_the_papers_write_them() {
    let ctx = context();
    let (w, dt) = (Vec3::new(1.0, 0.0, 0.5), 0.02);
    let masses = [1.0, 5.0];
    let forms = [
        ("drag", "drag = 2.0\n", [2.0 * dt, 2.0 * dt]),
        ("latta", "drag = 2.0\n", [2.0 * dt, 2.0 * dt / 5.0]),
        ("uberflow", "", [1.0, 1.0]),
    ];
    for (form, drag, factor) in forms {
        let body = steady_wind(form, drag);
        let s = scene("euler", dt, &emitters(&masses, false), &body);
        for (ty, f) in factor.iter().enumerate() {
            let v = one_euler_step(&ctx, &s, ty);
            assert!(
                (v - *f * w).length() <= 1e-5,
                "{form}, mass {}: Δv {v}, closed form {}",
                masses[ty],
                *f * w
            );
        }
        let ps = scattered(21, N, 1.0, 1.0, 2);
        for integrator in ALL {
            let s = scene(integrator, dt, &emitters(&masses, false), &body);
            locked(&ctx, &s, &ps, 20, TOL_STEP);
        }
    }
    no_gl_error(&ctx);
}

/// Latta §3.4.2: a vortex accelerates a particle towards its closest point on the line, with an
/// attractor's falloff. From rest at distance r from the y axis (inverse square, softening s):
/// `Δv = S d / (r^2 + s^2)^(3/2) dt / m`, d pointing at the axis; a particle moving across it
/// orbits. Then every integrator against the twin.
#[test]
fn latta_vortex_pulls_towards_the_line() {
    let ctx = context();
    let dt = 0.01;
    let body = "[[forces.vortex]]\nform = \"latta\"\npoint = [0.0, 0.0, 0.0]\n\
                axis = [0.0, 1.0, 0.0]\nstrength = 0.5\nsoftening = 0.1\n";
    let s = scene("euler", dt, &emitters(&[2.0], false), body);
    let x = Vec3::new(0.6, 0.3, -0.8);
    let mut sim = start(&ctx, &s, &[p(x, Vec3::ZERO)]);
    sim.step().unwrap();
    let v = sim.read_velocities().unwrap();
    let v = Vec3::new(v[0], v[1], v[2]);
    let d = Vec3::new(-0.6, 0.0, 0.8);
    let q: f32 = 1.0 + 0.01;
    let want = 0.5 * d / (q * q.sqrt()) * dt / 2.0;
    assert!((v - want).length() <= 1e-6, "Δv {v}, closed form {want}");
    let mut ps = scattered(22, 48, 1.0, 0.5, 1);
    // On the axis (no force) and beyond a max distance in the constant-falloff variant.
    ps.push(p(Vec3::new(0.0, 0.4, 0.0), Vec3::ZERO));
    ps.extend(scattered(23, 15, 3.0, 0.5, 1));
    for (variant, extra) in [
        ("inverse square", ""),
        ("constant", "falloff = \"constant\"\nmax_distance = 1.5\n"),
    ] {
        let body = format!("{body}{extra}");
        for integrator in ALL {
            let s = scene(integrator, dt, &emitters(&[2.0], false), &body);
            eprintln!("vortex {variant}, {integrator}");
            locked(&ctx, &s, &ps, 30, TOL_STEP);
        }
    }
    no_gl_error(&ctx);
}

/// Latta §3.3: a mass per particle. With `mass_range = [1, 5]` a particle whose static texel
/// holds r has mass `1 + 4 fract(4096 r)`; under Latta's drag from rest its first Euler step is
/// `Δv = c w dt / m`. Sixteen particles with r chosen so that fract(4096 r) is 0, 1/4, 1/2, 3/4:
/// masses 1, 2, 3, 4, each four times; GPU, twin and closed form agree.
#[test]
fn mass_range_gives_each_particle_its_mass() {
    let ctx = context();
    let dt = 0.02;
    let em = "[[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
              speed = [0.0, 0.0]\nmass_range = [1.0, 5.0]\n";
    let s = scene("euler", dt, em, &steady_wind("latta", "drag = 2.0\n"));
    let n = 16;
    let rs: Vec<f32> = (0..n).map(|i| (4 * i + i % 4) as f32 / 16384.0).collect();
    let ps = pad(vec![p(Vec3::ZERO, Vec3::ZERO); n]);
    let mut sim = ParticleSim::new(&ctx, &s, 7).unwrap();
    let pos: Vec<f32> = ps.iter().flat_map(|q| q.x.extend(1.0).to_array()).collect();
    let vel = vec![0.0; N * 4];
    let st: Vec<f32> = (0..N)
        .flat_map(|i| [0.0, 0.0, 0.0, rs.get(i).copied().unwrap_or(0.5)])
        .collect();
    sim.set_state(&pos, &vel, &st).unwrap();
    sim.step().unwrap();
    let v = sim.read_velocities().unwrap();
    let mut r = Reference::new(&s).unwrap();
    let w = Vec3::new(1.0, 0.0, 0.5);
    for (i, rv) in rs.iter().enumerate() {
        let m = 1.0 + 4.0 * (i % 4) as f32 / 4.0;
        let gpu = Vec3::new(v[4 * i], v[4 * i + 1], v[4 * i + 2]);
        let want = 2.0 * w * dt / m;
        r.set_static_random(*rv);
        assert!((1.0 / r.particle_inv_mass(0, *rv) - m).abs() < 1e-6);
        let (_, cpu, _) = r.step_explicit(Vec3::ZERO, Vec3::ZERO, 1.0, 0);
        assert!(
            (gpu - want).length() <= 1e-6 && (gpu - cpu).length() <= 1e-6,
            "particle {i} (r = {rv}, mass {m}): GPU {gpu}, twin {cpu}, closed form {want}"
        );
    }
    no_gl_error(&ctx);
}

// ---------------------------------------------------------------------------------------------
// User forces
// ---------------------------------------------------------------------------------------------

/// A fresh directory for this test's GLSL files.
fn glsl_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("texflow-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Two `[[forces.custom]]` files, paths relative to the scene's directory: a constant force
/// `(0, 3 (type + 1), 0)` N and a force `(age, 0, 0)` N that grows with the particle's age.
/// With mass 2 and Euler from rest, after n steps (age t_k = k dt at step k):
/// `v_y = n dt 3 (type + 1) / 2` and `v_x = dt^2 n (n - 1) / 2 / 2`.
#[test]
fn custom_forces_match_the_closed_form() {
    let ctx = context();
    let dir = glsl_dir("custom");
    std::fs::write(
        dir.join("lift.glsl"),
        "// A constant force per type.\nvec3 force(vec3 x, vec3 v, float age, int type) {\n    \
         return vec3(0.0, 3.0, 0.0) * float(type + 1);\n}\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("push.glsl"),
        "vec3 force(vec3 x, vec3 v, float age, int type) {\n    return vec3(age, 0.0, 0.0);\n}\n",
    )
    .unwrap();
    let body = "[[forces.custom]]\nglsl = \"lift.glsl\"\n[[forces.custom]]\nglsl = \"push.glsl\"\n";
    let mut s = scene("euler", 0.0625, &emitters(&[2.0, 2.0], false), body);
    s.resolve_custom_paths(&dir);
    assert!(s.forces.custom[0].glsl.starts_with(dir.to_str().unwrap()));
    let mut sim = start(
        &ctx,
        &s,
        &[
            p(Vec3::ZERO, Vec3::ZERO),
            P {
                ty: 1,
                ..p(Vec3::ONE, Vec3::ZERO)
            },
        ],
    );
    let (n, dt) = (16.0f32, 0.0625f32);
    for _ in 0..16 {
        sim.step().unwrap();
    }
    let v = sim.read_velocities().unwrap();
    for ty in 0..2 {
        let got = Vec3::new(v[4 * ty], v[4 * ty + 1], v[4 * ty + 2]);
        let want = Vec3::new(
            dt * dt * n * (n - 1.0) / 4.0,
            n * dt * 1.5 * (ty as f32 + 1.0),
            0.0,
        );
        assert!(
            (got - want).length() <= 1e-5,
            "type {ty}: v {got}, closed form {want}"
        );
    }
    no_gl_error(&ctx);
}

/// A custom force that does not compile: the error names the user's file and line, and says
/// what the file must define.
#[test]
fn broken_custom_force_names_its_file_and_line() {
    let ctx = context();
    let dir = glsl_dir("broken");
    std::fs::write(
        dir.join("broken.glsl"),
        "vec3 force(vec3 x, vec3 v, float age, int type) {\n    \
         return no_such_variable;\n}\n",
    )
    .unwrap();
    let mut s = scene(
        "euler",
        0.02,
        &emitters(&[1.0], false),
        "[[forces.custom]]\nglsl = \"broken.glsl\"\n",
    );
    s.resolve_custom_paths(&dir);
    let e = ParticleSim::new(&ctx, &s, 1).unwrap_err().to_string();
    eprintln!("{e}");
    let file = dir.join("broken.glsl");
    assert!(
        e.contains(&format!("{}:2", file.display())) && e.contains("vec3 force("),
        "{e}"
    );
    assert!(
        !e.contains("glsl/"),
        "a user's file is not under glsl/: {e}"
    );
    // A missing file is an input error naming it.
    let mut s = scene(
        "euler",
        0.02,
        &emitters(&[1.0], false),
        "[[forces.custom]]\nglsl = \"missing.glsl\"\n",
    );
    s.resolve_custom_paths(&dir);
    let e = ParticleSim::new(&ctx, &s, 1).unwrap_err().to_string();
    assert!(
        e.contains("missing.glsl") && e.contains("relative to the scene file"),
        "{e}"
    );
    no_gl_error(&ctx);
}
