//! Spinning spheres (UberFlow §4.5) against closed forms: a frictional collision between
//! particles conserves the total angular momentum about any point, Σ (x − p) × m v + I ω with
//! I = 2/5 m r², and loses no energy; a ball on an incline with Coulomb friction slips until
//! ω r = v, then rolls with the acceleration 5/7 g sin θ; sprites with `rotate = "spin"` turn by
//! the angle the simulation integrated.

mod common;

use common::{context, no_gl_error};
use glam::Vec3;
use texflow::render::ParticleStyle;
use texflow::scene;
use texflow::sim::ParticleSim;

const RADIUS: f32 = 0.05;
const MASS: f32 = 2.0;

/// A particle's position and velocity, as `common::set_particles` takes them.
type Particle = ([f32; 3], [f32; 3]);

fn spin_scene(size: [u32; 2], detection: &str, extra: &str) -> scene::SceneFile {
    let src = format!(
        r#"
name = "spin-test"
integrator = "uberflow"
[particles]
size = [{}, {}]
mass = {MASS}
[time]
dt = 0.01
[[emitters.initial]]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
[collisions]
radius = {RADIUS}
bounds = [[-2.0, -2.0, -2.0], [2.0, 2.0, 2.0]]
detection = "{detection}"
restitution = 0.9
spin = true
friction = 0.4
{extra}
"#,
        size[0], size[1]
    );
    scene::parse("test", &src).unwrap_or_else(|e| panic!("{e}\n{src}"))
}

/// The live particles' (position, velocity, angular velocity), read back.
fn state(sim: &ParticleSim) -> Vec<(Vec3, Vec3, Vec3)> {
    let x = sim.read_positions().unwrap();
    let v = sim.read_velocities().unwrap();
    let w = sim.read_spins().unwrap();
    let at = |a: &[f32], i: usize| Vec3::new(a[4 * i], a[4 * i + 1], a[4 * i + 2]);
    (0..x.len() / 4)
        .filter(|&i| x[4 * i + 3] > 0.0 && x[4 * i].is_finite())
        .map(|i| (at(&x, i), at(&v, i), at(&w, i)))
        .collect()
}

/// Σ (x − p) × m v + I ω, in f64.
fn angular_momentum(s: &[(Vec3, Vec3, Vec3)], p: Vec3) -> glam::DVec3 {
    let inertia = 0.4 * MASS as f64 * (RADIUS as f64).powi(2);
    s.iter()
        .map(|(x, v, w)| {
            (x.as_dvec3() - p.as_dvec3()).cross(v.as_dvec3()) * MASS as f64 + w.as_dvec3() * inertia
        })
        .sum()
}

/// Translational plus rotational kinetic energy.
fn energy(s: &[(Vec3, Vec3, Vec3)]) -> f64 {
    let inertia = 0.4 * MASS as f64 * (RADIUS as f64).powi(2);
    s.iter()
        .map(|(_, v, w)| {
            0.5 * MASS as f64 * v.as_dvec3().length_squared()
                + 0.5 * inertia * w.as_dvec3().length_squared()
        })
        .sum()
}

/// Three off-centre pairs, far apart from each other, each with spins of its own: every pair
/// collides once within the run.
fn pairs() -> (Vec<Particle>, Vec<[f32; 3]>) {
    let particles = vec![
        ([-0.3, 0.03, 0.0], [2.0, 0.0, 0.0]),
        ([0.1, -0.02, 0.01], [-1.0, 0.1, 0.3]),
        ([-0.5, 1.0, 1.0], [1.5, 0.2, -0.1]),
        ([-0.2, 1.06, 0.97], [0.0, 0.0, 0.0]),
        ([0.8, -1.0, -1.0], [0.0, 1.2, 0.0]),
        ([0.83, -0.7, -1.02], [0.1, -1.0, 0.0]),
    ];
    let spins = vec![
        [0.0, 0.0, 30.0],
        [5.0, -10.0, 0.0],
        [0.0, 0.0, 0.0],
        [-20.0, 4.0, 8.0],
        [0.0, 40.0, -15.0],
        [3.0, 0.0, 0.0],
    ];
    (particles, spins)
}

fn set_spins(sim: &mut ParticleSim, spins: &[[f32; 3]]) {
    let n = (sim.size().x * sim.size().y) as usize;
    let mut w = vec![0.0; n * 4];
    for (i, s) in spins.iter().enumerate() {
        w[4 * i..4 * i + 3].copy_from_slice(s);
    }
    sim.set_spins(&w).unwrap();
}

/// Frictional, off-centre collisions between spinning spheres (no colliders, no forces), in
/// both detection modes: the total angular momentum about a point away from the origin is
/// conserved to 1e-5 relative, linear momentum too, the spins changed (friction acted), and
/// the kinetic energy (translation and rotation) did not grow.
#[test]
fn frictional_collisions_conserve_angular_momentum() {
    let ctx = context();
    let p = Vec3::new(0.7, -0.4, 0.25);
    for detection in ["uberflow", "exact"] {
        let mut sim = ParticleSim::new(&ctx, &spin_scene([4, 4], detection, ""), 3).unwrap();
        let (particles, spins) = pairs();
        common::set_particles(&mut sim, &particles, |i, n| (i as f32 + 0.5) / n as f32);
        set_spins(&mut sim, &spins);
        let before = state(&sim);
        let (l0, e0) = (angular_momentum(&before, p), energy(&before));
        let m0: Vec3 = before.iter().map(|s| s.1).sum();
        for _ in 0..40 {
            sim.step().unwrap();
        }
        let after = state(&sim);
        assert_eq!(after.len(), before.len());
        let (l1, e1) = (angular_momentum(&after, p), energy(&after));
        let m1: Vec3 = after.iter().map(|s| s.1).sum();
        let err = (l1 - l0).length() / l0.length();
        println!(
            "{detection}: L0 {l0:.6?} L1 {l1:.6?} relative error {err:.3e}; energy {e0:.5} -> \
             {e1:.5}"
        );
        assert!(
            err < 1e-5,
            "{detection}: angular momentum {l0:?} -> {l1:?} ({err:e})"
        );
        assert!(
            (m1 - m0).length() < 1e-4 * m0.length(),
            "{detection}: momentum {m0} -> {m1}"
        );
        assert!(e1 <= e0 * (1.0 + 1e-5), "{detection}: energy {e0} -> {e1}");
        // Every particle's spin changed (each pair collided, with friction): no spin after is
        // any spin before. (The collision sort reorders the state, so compare with all.)
        for a in &after {
            let nearest = before
                .iter()
                .map(|b| (a.2 - b.2).length())
                .fold(f32::MAX, f32::min);
            assert!(
                nearest > 0.5,
                "{detection}: spin {} is one from the start",
                a.2
            );
        }
        // Nothing left overlapping.
        for i in 0..after.len() {
            for j in i + 1..after.len() {
                let d = after[i].0.distance(after[j].0);
                assert!(d >= 2.0 * RADIUS * 0.999, "{detection}: {i} {j} at {d}");
            }
        }
    }
    no_gl_error(&ctx);
}

/// Balls on a plane inclined by θ = 20° with Coulomb friction μ = 0.3 (resilience 0), started
/// at rest, sliding, with top spin and with back spin. The closed form: while the contact slips
/// at u = v − ω r, friction μ g cos θ opposes it, so dv/dt = g sin θ ∓ μ g cos θ and
/// d(ω r)/dt = ±5/2 μ g cos θ, until u = 0; from then on (μ ≥ 2/7 tan θ) the ball rolls,
/// ω = v / r, with dv/dt = 5/7 g sin θ. After 1 s every ball rolls: ω r = v within 1e-4, the
/// speed matches the closed form within 1e-3, and the acceleration over the last 0.3 s matches
/// 5/7 g sin θ within 1e-3; the spin texture's angle is Σ ω_z dt. (Each step's friction impulse is the closed form's over dt: the
/// normal impulse per step is g cos θ dt, so llvmpipe agrees to about 3e-7.)
#[test]
fn balls_on_an_incline_roll_without_slipping() {
    let ctx = context();
    let theta = 20f32.to_radians();
    let (g, mu, dt) = (9.81f32, 0.3f32, 0.01f32);
    let n = Vec3::new(-theta.sin(), theta.cos(), 0.0);
    // Down the slope, in the plane z = const.
    let down = Vec3::new(-theta.cos(), -theta.sin(), 0.0);
    let extra = format!(
        r#"
[[forces.gravity]]
acceleration = [0.0, {}, 0.0]
[[colliders.plane]]
point = [0.0, 0.0, 0.0]
normal = [{}, {}, 0.0]
friction = {mu}
resilience = 0.0
"#,
        -g, n.x, n.y
    );
    let s = spin_scene([2, 2], "uberflow", &extra);
    let mut sim = ParticleSim::new(&ctx, &s, 5).unwrap();
    // Speed down the slope, and ω r (positive: turning as rolling down the slope turns).
    let starts = [(0.0f32, 0.0f32), (2.0, 0.0), (0.0, 1.5), (1.0, -1.0)];
    // The axis a ball rolling down the slope turns about: with the contact at −r n, rolling
    // means v + ω × (−r n) = 0, so ω = (v / r) (n × down).
    let axis = n.cross(down);
    let particles: Vec<_> = starts
        .iter()
        .enumerate()
        .map(|(i, &(v0, _))| {
            let x = n * 1e-4 + Vec3::new(0.0, 0.0, i as f32 - 1.5);
            (x.to_array(), (down * v0).to_array())
        })
        .collect();
    common::set_particles(&mut sim, &particles, |i, n| (i as f32 + 0.5) / n as f32);
    let spins: Vec<[f32; 3]> = starts
        .iter()
        .map(|&(_, wr)| (axis * wr / RADIUS).to_array())
        .collect();
    set_spins(&mut sim, &spins);
    // The collision sort keeps the balls in texel order: z, the slowest axis of the cell key,
    // grows with the index, and every ball is in a cell of its own within the bounds.
    let speeds = |sim: &ParticleSim| -> Vec<(f32, f32)> {
        state(sim)
            .iter()
            .map(|(_, v, w)| (v.dot(down), w.dot(axis) * RADIUS))
            .collect()
    };
    let steps = 100;
    let mut history = Vec::new();
    for _ in 0..steps {
        sim.step().unwrap();
        history.push(speeds(&sim));
    }
    // The sprite angle: each step adds its new ω_z dt (the axis is +z here), kept in (−π, π].
    assert!((axis - Vec3::Z).length() < 1e-6);
    let angles: Vec<f32> = sim.read_spins().unwrap().chunks(4).map(|w| w[3]).collect();
    for (i, angle) in angles.iter().take(starts.len()).enumerate() {
        let turned: f64 = history.iter().map(|h| (h[i].1 / RADIUS * dt) as f64).sum();
        let expected = (turned + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        println!("ball {i}: angle {angle:.5} rad, Σ ω_z dt = {turned:.4} ≡ {expected:.5}");
        assert!(
            (*angle as f64 - expected).abs() < 1e-3,
            "ball {i}: angle {angle}"
        );
    }
    check_rolling(&starts, &history, Incline { theta, g, mu, dt });
    no_gl_error(&ctx);
}

/// The incline of [`balls_on_an_incline_roll_without_slipping`].
struct Incline {
    theta: f32,
    g: f32,
    mu: f32,
    dt: f32,
}

/// Each ball against the closed form (the slip phase, then rolling): ω r = v, the speed, and
/// the acceleration over the last 0.3 s. `history` holds (v, ω r) per step and ball.
fn check_rolling(starts: &[(f32, f32)], history: &[Vec<(f32, f32)>], incline: Incline) {
    let Incline { theta, g, mu, dt } = incline;
    let steps = history.len();
    let t = steps as f32 * dt;
    let rolling_a = 5.0 / 7.0 * g * theta.sin();
    for (i, &(v0, wr0)) in starts.iter().enumerate() {
        // Closed form: the slip phase, then rolling.
        let u0 = v0 - wr0;
        let (a_slip, t_roll) = if u0.abs() < 1e-6 {
            (rolling_a, 0.0)
        } else {
            let f = u0.signum() * mu * g * theta.cos();
            let du = g * theta.sin() - 3.5 * f;
            assert!(du * u0 < 0.0, "ball {i} must stop slipping");
            (g * theta.sin() - f, -u0 / du)
        };
        let expected = v0 + a_slip * t_roll + rolling_a * (t - t_roll);
        let (v, wr) = history[steps - 1][i];
        let late = history[steps - 31][i].0;
        let a = (v - late) / (30.0 * dt);
        println!(
            "ball {i}: rolls from t = {t_roll:.3} s; v = {v:.5} m/s (closed form {expected:.5}), \
             ω r = {wr:.5} (ω r / v − 1 = {:.2e}); a = {a:.5} m/s² (5/7 g sin θ = {rolling_a:.5})",
            wr / v - 1.0
        );
        assert!(
            (wr / v - 1.0).abs() < 1e-4,
            "ball {i}: ω r = {wr} against v = {v}"
        );
        assert!(
            (v / expected - 1.0).abs() < 1e-3,
            "ball {i}: v = {v} against {expected}"
        );
        assert!(
            (a / rolling_a - 1.0).abs() < 1e-3,
            "ball {i}: a = {a} against {rolling_a}"
        );
    }
}

/// Draws one snowflake sprite (tile 1, random number 0.1, permanent, born at 0) at the origin
/// at time `time`, turned by `style.rotate`; the spin texture's angle is `angle`.
fn sprite(ctx: &texflow::gl::Context, style: &ParticleStyle, angle: f32, time: f32) -> Vec<u8> {
    use texflow::gl::{Texture, TextureDesc, TextureFormat};
    use texflow::render::{Camera, FrameState, FrameTarget, ParticleRenderer};
    const S: u32 = 2;
    let make = |label, data: [[f32; 4]; 4]| {
        let t = Texture::new(
            ctx,
            TextureDesc {
                width: S,
                height: S,
                format: TextureFormat::Rgba32F,
                label,
            },
        )
        .unwrap();
        t.upload_f32(data.as_flattened()).unwrap();
        t
    };
    let dead = [f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0];
    let pos = make("position", [[0.0, 0.0, 0.0, 1.0], dead, dead, dead]);
    let stat = make(
        "statics",
        [[0.0, 0.0, 0.0, 0.1], [0.0; 4], [0.0; 4], [0.0; 4]],
    );
    let spin = make(
        "spin",
        [[0.0, 0.0, 3.0, angle], [0.0; 4], [0.0; 4], [0.0; 4]],
    );
    let target = FrameTarget::new(ctx, 48, 48).unwrap();
    let r = ParticleRenderer::new(ctx, style.clone(), S, S).unwrap();
    r.clear(&target);
    let camera = Camera {
        distance: 4.0,
        elevation: 0.0,
        ..Camera::default()
    };
    let frame = FrameState {
        positions: &pos,
        statics: &stat,
        motion: None,
        time,
        spins: Some(&spin),
        count: 1,
        user: &[],
    };
    r.draw_frame(&target, &frame, &camera).unwrap();
    target.read_rgb().unwrap().into_raw()
}

/// `render.rotate = "spin"` turns a sprite by the spin texture's angle: a quarter turn there
/// draws the same pixels as a quarter turn from the type's rotation speed (90°/s for 1 s,
/// `rotate = "age"`), and differs from no turn; the age does not turn it.
#[test]
fn sprites_turn_by_the_spin_angle() {
    use texflow::scene::{DrawMode, Rotate};
    let ctx = context();
    let style = |rotate, speed: f32| {
        let mut s = ParticleStyle {
            mode: DrawMode::Sprites,
            point_size: 40.0,
            rotate,
            ..ParticleStyle::default()
        };
        s.types[0].tile = 1;
        s.types[0].spin = [speed, speed];
        s.keyframes = vec![texflow::scene::Keyframe {
            age: 0.0,
            rgba: [1.0; 4],
        }];
        s
    };
    let quarter = std::f32::consts::FRAC_PI_2;
    let by_spin = sprite(&ctx, &style(Rotate::Spin, 0.0), quarter, 1.0);
    let by_age = sprite(&ctx, &style(Rotate::Age, 90.0), 0.0, 1.0);
    let unturned = sprite(&ctx, &style(Rotate::Spin, 0.0), 0.0, 1.0);
    let later = sprite(&ctx, &style(Rotate::Spin, 90.0), quarter, 5.0);
    let differ = |a: &[u8], b: &[u8]| a.iter().zip(b).filter(|(x, y)| x.abs_diff(**y) > 8).count();
    assert!(unturned.iter().any(|&c| c > 0), "the sprite is drawn");
    assert!(
        differ(&by_spin, &by_age) == 0,
        "{} channels differ",
        differ(&by_spin, &by_age)
    );
    assert!(
        differ(&by_spin, &unturned) > 20,
        "a quarter turn changes the snowflake"
    );
    assert_eq!(by_spin, later, "the age and rotation speed do not turn it");
    no_gl_error(&ctx);
}

/// `--dump-state` writes every state texture of a spinning scene, row i the same particle in
/// each: `spins_NNNNN.npy` (ω, angle) and `statics_NNNNN.npy` beside the positions and
/// velocities, which an outside script can check (examples/spin/rolling.py). Here the same
/// check: the built-in `spin`'s balls on its planes (centre on the plane, the colliders'
/// convention, the contact r below) roll, |ω × r n| = |v|, for most of them.
#[test]
fn dumps_hold_the_spins_and_the_balls_on_the_planes_roll() {
    let dir = tempfile::tempdir().unwrap();
    let dumps = dir.path().join("d");
    let o = common::cli::texflow(&[
        "render",
        "spin",
        "--frames",
        "240",
        "--resolution",
        "32",
        "--quiet",
        "--out",
        common::cli::s(&dir.path().join("f")),
        "--dump-state",
        common::cli::s(&dumps),
        "--dump-every",
        "20",
    ]);
    assert!(o.status.success(), "{}", common::cli::stderr(&o));
    let read = |what: &str, frame: u32| -> Vec<Vec3> {
        let path = dumps.join(format!("{what}_{frame:05}.npy"));
        let (shape, v) = texflow::npy::read_f32_shaped(&path).unwrap();
        assert_eq!(shape, [16, 4], "{what}");
        v.chunks(4).map(Vec3::from_slice).collect()
    };
    let s = scene::load("spin").unwrap();
    let r = s.collisions.as_ref().unwrap().radius;
    let (mut rolling, mut touching) = (0, 0);
    for frame in (0..240).step_by(20) {
        let (x, v, w) = (
            read("positions", frame),
            read("velocities", frame),
            read("spins", frame),
        );
        assert!(read("statics", frame).iter().all(|st| st.y == 0.0));
        for i in 0..16 {
            for plane in &s.colliders.plane {
                let n = Vec3::from(plane.normal).normalize();
                let gap = (x[i] - Vec3::from(plane.point)).dot(n);
                let along = v[i] - v[i].dot(n) * n;
                if gap.abs() > 0.1 * r || along.length() < 0.05 {
                    continue;
                }
                touching += 1;
                let ratio = w[i].cross(r * n).length() / along.length();
                rolling += usize::from((ratio - 1.0).abs() < 0.05);
            }
        }
    }
    assert!(touching >= 50, "{touching} ball-frames on a plane");
    assert!(
        rolling * 10 >= touching * 7,
        "{rolling} of {touching} ball-frames on a plane roll"
    );
}
