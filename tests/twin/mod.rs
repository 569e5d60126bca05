//! The harness that checks every force and every collider of the integration pass
//! (glsl/sim/integrate.frag, glsl/sim/forces.glsl, glsl/sim/colliders.glsl) on the GPU against its
//! CPU twin, `texflow::sim::reference::Reference` (tests/forces.rs, tests/colliders.rs,
//! tests/integration_twin.rs).
//!
//! Each test builds a scene with only the feature under test (an initial emitter, so the particles
//! are permanent unless the test is about life), overwrites the state of its 8x8 particles with
//! `set_state` (positions chosen to be far from, near, hitting and caught inside a collider, some
//! slower than `slow_speed`), and runs steps on both sides in two ways:
//!
//! - **lockstep**: before every GPU step the state is read back and the reference steps that same
//!   state; the GPU's new state must match the reference's to within [`TOL_STEP`]. This checks the
//!   twin operation by operation without letting rounding accumulate, and works for colliders
//!   where a bounce amplifies small differences.
//! - **free run**: the reference steps its own state from the initial one and the two trajectories
//!   are compared after every step, with a tolerance that grows with the number of steps (forces
//!   only: see below for colliders).
//!
//! # Tolerances
//!
//! Both sides evaluate the same `f32` formulas in the same order. They differ only where GLSL lets
//! the driver differ from IEEE single precision: division (`a / b` may be `a * (1 / b)`, 2.5 ulp),
//! `normalize` and `length` (reciprocal square roots), fused multiply-adds, and `mix`. One step is
//! some 10 to 40 dependent operations (the collision branches the most: two distances, a
//! response, a push-out, an advance, `keep_outside`), each off by at most a few ulp of the
//! *largest* magnitude it involves (a plane distance `n . x - c` is off by ulps of `|x|`, not of
//! the small distance). Hence the comparison: per component,
//! `|gpu - cpu| <= tol * max(1, |cpu|)`, `|cpu|` the largest component of that vector, the floor
//! of 1 because the scenes are laid out in metres and metres per second with values of order 1.
//! With `eps = 2^-24 = 6e-8`, 40 operations at up to 4 ulp each give `160 eps ~ 1e-5`:
//! [`TOL_STEP`]. The distance field's normal is a difference quotient of two interpolated
//! distances over one cell, which divides their rounding by the cell size: its scenes get
//! [`TOL_SDF`]. Life is a single subtraction, correctly rounded on both sides: it must match
//! exactly, and so must the `+inf` of the dead. (Measured on llvmpipe: the worst lockstep error
//! is 7 % of [`TOL_STEP`], about 11 eps; most steps match to the bit.)
//!
//! A free run adds each step's rounding to an error that the dynamics carry on. The allowance
//! after `n` steps is [`TOL_STEP`] times the larger of `n` (explicit integrators: velocity errors
//! reach the position through `dt < 1`) or `n^2 / 2` (Verlet, whose velocity is a difference of
//! two positions), and of the amplification of rounding by the dynamics, measured on the
//! reference itself (see [`free_run`]): near an attractor's centre or a vortex's axis, where the
//! direction of the force turns on a rounding error, a trajectory is not reproducible beyond its
//! first steps, and only the lockstep checks it.
//!
//! A branch on a value within rounding of its threshold (a particle that ends a step exactly on a
//! surface, a speed equal to `slow_speed`) can go either way on either side. The lockstep accepts
//! such a step only if the reference, started a few ulps away from the GPU's input, reproduces
//! the GPU's output ([`explained_by_a_branch`]), and at most 1 % of the particle steps of a run.
//! Colliders are checked in lockstep only: after such a branch a free run differs by a bounce.
//!
//! `tolerance_is_not_vacuous` shows that the comparison rejects a reference that is wrong by less
//! than any plausible bug (a result perturbed by three tolerances, a resilience of 0.79 instead of
//! 0.8, gravity 1 % off, the other integrator).

#![allow(dead_code)]

use crate::common::scene::Rng;
use glam::Vec3;
use texflow::gl::Context;
use texflow::scene::{self, SceneFile};
use texflow::sim::reference::{Events, Reference};
use texflow::sim::ParticleSim;

/// Particles per test: the 8x8 state texture.
pub const N: usize = 64;

/// `2^-24`, half an ulp of 1 in `f32`.
pub const EPS: f32 = 1.0 / (1u32 << 24) as f32;

/// One step, relative to `max(1, |value|)` (see the module documentation).
pub const TOL_STEP: f32 = 160.0 * EPS;

/// One step of a distance-field scene. After tests/fields.rs, an interpolated distance is off by
/// up to `K eps ((n - 1) J + 3 M)` (`K = 8` ulp per operation, `n - 1 = 31` cells, the largest
/// jump between nodes `J = h = 3 / 31`, the largest distance `M ~ 2.6`): `~ 90 eps`. The normal
/// divides differences of two of them by `2 h`, so each component is off by `~ 90 eps / h ~ 900
/// eps`, and a response `v - (1 + e) (v . n) n` carries that relative error into the velocity:
/// `~ 6` [`TOL_STEP`]; 16 leaves a margin of between two and three.
pub const TOL_SDF: f32 = 16.0 * TOL_STEP;

/// All integrators.
pub const ALL: [&str; 3] = ["euler", "uberflow", "verlet"];

// ---------------------------------------------------------------------------------------------
// Scenes and particles
// ---------------------------------------------------------------------------------------------

/// One particle's initial state: position, velocity, `w` (remaining life, or 1 for a permanent
/// particle), type and total life (the static texture's y and z).
#[derive(Debug, Clone, Copy)]
pub struct P {
    pub x: Vec3,
    pub v: Vec3,
    pub life: f32,
    pub ty: usize,
    pub total: f32,
}

pub fn p(x: Vec3, v: Vec3) -> P {
    P {
        x,
        v,
        life: 1.0,
        ty: 0,
        total: 0.0,
    }
}

/// Initial emitters (one type each) with these masses; `life` adds `life = [1, 1]` (the `LIFE`
/// pass).
pub fn emitters(masses: &[f32], life: bool) -> String {
    let mut s = String::new();
    for m in masses {
        s += &format!(
            "[[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
             speed = [0.0, 0.0]\nmass = {m:?}\n"
        );
        if life {
            s += "life = [1.0, 1.0]\n";
        }
    }
    s
}

pub fn scene(integrator: &str, dt: f32, emitters: &str, body: &str) -> SceneFile {
    let src = format!(
        "name = \"forces_colliders\"\nintegrator = \"{integrator}\"\n[particles]\nsize = [8, 8]\n\
         [time]\ndt = {dt:?}\n{emitters}{body}"
    );
    crate::common::scene::parse("forces_colliders", &src)
}

/// Fills the 64 texels: the given particles, then particles parked far from everything at rest.
pub fn pad(mut ps: Vec<P>) -> Vec<P> {
    assert!(ps.len() <= N, "{} particles for {N} texels", ps.len());
    while ps.len() < N {
        let k = ps.len() as f32;
        ps.push(p(Vec3::new(40.0 + k, 30.0, -20.0), Vec3::ZERO));
    }
    ps
}

/// `count` particles at random in a box, types alternating over `types`.
pub fn scattered(seed: u64, count: usize, half: f32, speed: f32, types: usize) -> Vec<P> {
    let mut rng = Rng(seed);
    (0..count)
        .map(|i| P {
            ty: i % types,
            ..p(rng.vec(-half, half), rng.vec(-speed, speed))
        })
        .collect()
}

/// Eight kinds of particle around a surface point `s` with outward unit normal `n`, for a time
/// step `dt` and a slow speed of 0.5 m/s: far and leaving; hitting during the first step, fast
/// and oblique or head on; hitting slower than `slow_speed`; caught inside, moving in or out;
/// hitting a few steps later; sliding along the surface.
pub fn around(s: Vec3, n: Vec3, dt: f32) -> [P; 8] {
    let t = n.any_orthonormal_vector();
    let fast = 4.0;
    [
        p(s + n, 0.5 * t + 0.2 * n),
        p(s + 0.3 * fast * dt * n, -fast * n + 0.5 * fast * t),
        p(s + 0.5 * fast * dt * n, -fast * n),
        p(s + 0.002 * n, -0.15 * n + 0.05 * t),
        p(s - 0.03 * n, -n + 0.3 * t),
        p(s - 0.03 * n, 0.5 * n + 0.5 * t),
        p(s + 3.5 * dt * n, -n + 0.2 * t),
        p(s + 0.0213 * n, 2.0 * t - 0.1 * n),
    ]
}

/// The eight kinds of [`around`] at each of eight surface points, types alternating over two.
pub fn around_all(surface: &[(Vec3, Vec3)], dt: f32) -> Vec<P> {
    assert_eq!(surface.len(), 8);
    surface
        .iter()
        .flat_map(|&(s, n)| around(s, n.normalize(), dt))
        .enumerate()
        .map(|(i, q)| P { ty: i % 2, ..q })
        .collect()
}

/// A simulation of `scene` with `particles` (padded to 64) as its state.
pub fn start(ctx: &Context, scene: &SceneFile, particles: &[P]) -> ParticleSim {
    let ps = pad(particles.to_vec());
    let mut sim = ParticleSim::new(ctx, scene, 7).unwrap();
    let pos: Vec<f32> = ps
        .iter()
        .flat_map(|q| q.x.extend(q.life).to_array())
        .collect();
    let vel: Vec<f32> = ps.iter().flat_map(|q| q.v.extend(0.0).to_array()).collect();
    let st: Vec<f32> = ps
        .iter()
        .flat_map(|q| [0.0, q.ty as f32, q.total, 0.5])
        .collect();
    sim.set_state(&pos, &vel, &st).unwrap();
    sim
}

// ---------------------------------------------------------------------------------------------
// Comparison
// ---------------------------------------------------------------------------------------------

/// The GPU state: positions, `w`, and velocities (explicit) or previous positions (Verlet).
pub struct State {
    pub x: Vec<Vec3>,
    pub w: Vec<f32>,
    pub other: Vec<Vec3>,
}

pub fn read(sim: &ParticleSim) -> State {
    let pos = sim.read_positions().unwrap();
    let other = match sim.previous() {
        Some(t) => t.read_f32().unwrap(),
        None => sim.read_velocities().unwrap(),
    };
    let v3 = |c: &[f32]| Vec3::new(c[0], c[1], c[2]);
    State {
        x: pos.chunks(4).map(v3).collect(),
        w: pos.chunks(4).map(|c| c[3]).collect(),
        other: other.chunks(4).map(v3).collect(),
    }
}

/// `|gpu - cpu| <= tol * max(1, |cpu|_inf)` per component; non-finite values must be identical.
/// Returns the largest ratio of error to allowance (at most 1).
pub fn close(what: &str, gpu: Vec3, cpu: Vec3, tol: f32) -> Result<f32, String> {
    let scale = cpu
        .to_array()
        .iter()
        .filter(|c| c.is_finite())
        .fold(1.0f32, |m, c| m.max(c.abs()));
    let mut worst = 0.0f32;
    for k in 0..3 {
        let (g, c) = (gpu[k], cpu[k]);
        if !c.is_finite() || !g.is_finite() {
            if g.to_bits() != c.to_bits() {
                return Err(format!("{what}: GPU {gpu} vs CPU {cpu}"));
            }
            continue;
        }
        let ratio = (g - c).abs() / (tol * scale);
        // Both finite and the scale at least 1: the ratio is a number.
        if ratio > 1.0 {
            return Err(format!(
                "{what}: GPU {gpu} vs CPU {cpu}: component {k} off by {:e}, {ratio:.1} times \
                 the tolerance {:e}",
                (g - c).abs(),
                tol * scale
            ));
        }
        worst = worst.max(ratio);
    }
    Ok(worst)
}

/// What a run saw: the largest error as a fraction of its tolerance, and the reference's
/// branches summed over particles and steps.
#[derive(Debug)]
pub struct Summary {
    pub worst: f32,
    pub events: Events,
    /// Lockstep: particle steps where GPU and reference took different branches on a value
    /// within rounding of the threshold (see [`explained_by_a_branch`]).
    pub branches: Vec<String>,
    /// Lockstep: the least signed distance of a GPU position to the colliders after any step
    /// (`+inf` without colliders; negative: a particle left inside).
    pub deepest: f32,
    /// Free run: the largest allowance beyond the linear accumulation of rounding that the
    /// dynamics' own amplification called for (1: none).
    pub amplification: f32,
}

impl Default for Summary {
    fn default() -> Self {
        Summary {
            worst: 0.0,
            events: Events::default(),
            branches: Vec::new(),
            deepest: f32::INFINITY,
            amplification: 1.0,
        }
    }
}

impl Summary {
    /// Branches decided by rounding must be rare, or the placements test nothing.
    pub fn few_branches(&self, steps: usize) {
        assert!(
            self.branches.len() * 100 <= steps * N,
            "{} of {} particle steps differ by a branch: {:#?}",
            self.branches.len(),
            steps * N,
            self.branches
        );
    }
}

/// The reference's step of particle `i` of `before`: (position, w, velocity or `None`, events).
pub fn cpu_step(
    r: &Reference,
    x: Vec3,
    other: Vec3,
    w: f32,
    ty: usize,
) -> (Vec3, f32, Vec3, Events) {
    if r.integrator() == scene::Integrator::Verlet {
        let (xn, l, ev) = r.step_verlet_events(x, other, w, ty);
        (xn, l, x, ev)
    } else {
        let (xn, vn, l, ev) = r.step_explicit_events(x, other, w, ty);
        (xn, l, vn, ev)
    }
}

pub fn check_particle(
    what: &str,
    i: usize,
    gpu: &State,
    (x, w, other): (Vec3, f32, Vec3),
    tol: f32,
) -> Result<f32, String> {
    if gpu.w[i].to_bits() != w.to_bits() {
        return Err(format!(
            "{what}, particle {i}: life GPU {} vs CPU {w}",
            gpu.w[i]
        ));
    }
    let a = close(&format!("{what}, particle {i}, position"), gpu.x[i], x, tol)?;
    let b = close(
        &format!("{what}, particle {i}, velocity"),
        gpu.other[i],
        other,
        tol,
    )?;
    Ok(a.max(b))
}

/// Whether a GPU step that the reference does not reproduce is a branch taken on a value within
/// rounding of its threshold (a particle ending its step exactly on a surface, a speed equal to
/// `slow_speed`): the reference, started from inputs a few ulps away from the GPU's, reproduces
/// the GPU's result. Rounding decides such a branch on either side; a wrong formula is not
/// explained this way, since a few ulps of input move a continuous result by a few ulps only.
pub fn explained_by_a_branch(
    r: &Reference,
    (x, other, w, ty): (Vec3, Vec3, f32, usize),
    gpu: &State,
    i: usize,
    tol: f32,
) -> bool {
    let mut rng = Rng(i as u64 * 7919 + 1);
    let mut nudge = |v: Vec3| {
        let ulp = 2.0 * EPS * v.abs().max_element().max(1.0);
        v + Vec3::new(
            (rng.range(-4.0, 4.0)).round(),
            (rng.range(-4.0, 4.0)).round(),
            (rng.range(-4.0, 4.0)).round(),
        ) * ulp
    };
    (0..256).any(|_| {
        let (x1, o1) = (nudge(x), nudge(other));
        let (xn, wn, on, _) = cpu_step(r, x1, o1, w, ty);
        check_particle("nudged", i, gpu, (xn, wn, on), tol).is_ok()
    })
}

/// Lockstep: every GPU step against the reference's step of the GPU's previous state.
pub fn lockstep(
    sim: &mut ParticleSim,
    r: &Reference,
    ps: &[P],
    steps: usize,
    tol: f32,
) -> Result<Summary, String> {
    let ps = pad(ps.to_vec());
    let mut sum = Summary::default();
    let mut before = read(sim);
    for step in 1..=steps {
        sim.step().unwrap();
        let after = read(sim);
        for (i, q) in ps.iter().enumerate() {
            if after.x[i].is_finite() {
                sum.deepest = sum.deepest.min(r.distance_to_colliders(after.x[i]));
            }
            let (x, w, other, ev) = cpu_step(r, before.x[i], before.other[i], before.w[i], q.ty);
            sum.events += ev;
            match check_particle(&format!("lockstep {step}"), i, &after, (x, w, other), tol) {
                Ok(worst) => sum.worst = sum.worst.max(worst),
                Err(e) => {
                    let input = (before.x[i], before.other[i], before.w[i], q.ty);
                    if !explained_by_a_branch(r, input, &after, i, tol) {
                        return Err(e);
                    }
                    sum.branches.push(e);
                }
            }
        }
        before = after;
    }
    Ok(sum)
}

/// `v` plus a random vector of up to `tol * max(1, |v|)` per component (`v` if not finite).
pub fn jitter(rng: &mut Rng, v: Vec3, tol: f32) -> Vec3 {
    if !v.is_finite() {
        return v;
    }
    v + rng.vec(-1.0, 1.0) * tol * v.abs().max_element().max(1.0)
}

/// The largest component of `|a - b|` in units of `tol * max(1, |b|)` (0 if not finite).
pub fn spread(a: Vec3, b: Vec3, tol: f32) -> f32 {
    if !(a.is_finite() && b.is_finite()) {
        return 0.0;
    }
    (a - b).abs().max_element() / (tol * b.abs().max_element().max(1.0))
}

/// Shadow trajectories per particle in a free run.
pub const SHADOWS: usize = 3;

/// Free run: the reference's own trajectory from the initial state against the GPU's, after
/// every step.
///
/// The allowance after `n` steps is `tol` times the larger of
/// - the accumulation of one step's rounding per step: `n` for the explicit integrators and
///   `n^2 / 2` for Verlet (a position error is also a velocity error there), and
/// - twice the amplification of rounding by the dynamics themselves, measured on the reference:
///   [`SHADOWS`] copies of the particle's trajectory are pushed by a random `tol` after every
///   step, and the furthest of them from the unperturbed trajectory is how far rounding alone
///   can carry that particle (near a strong attractor two trajectories that start a rounding
///   error apart separate faster than linearly).
pub fn free_run(
    sim: &mut ParticleSim,
    r: &Reference,
    ps: &[P],
    steps: usize,
    tol: f32,
) -> Result<Summary, String> {
    let ps = pad(ps.to_vec());
    let verlet = r.integrator() == scene::Integrator::Verlet;
    let mut sum = Summary::default();
    // Verlet: the GPU's second-order start against the reference's.
    let gpu = read(sim);
    let mut cpu: Vec<(Vec3, f32, Vec3)> = ps
        .iter()
        .map(|q| {
            let other = if verlet && q.life > 0.0 {
                r.verlet_start(q.x, q.v, q.ty)
            } else if verlet {
                q.x
            } else {
                q.v
            };
            (q.x, q.life, other)
        })
        .collect();
    for (i, c) in cpu.iter().enumerate() {
        sum.worst = sum.worst.max(check_particle("start", i, &gpu, *c, tol)?);
    }
    let mut shadows: Vec<[(Vec3, f32, Vec3); SHADOWS]> =
        cpu.iter().map(|c| [*c; SHADOWS]).collect();
    let mut rng = Rng(99);
    for step in 1..=steps {
        sim.step().unwrap();
        let gpu = read(sim);
        let n = step as f32;
        let linear = if verlet { (n * n / 2.0).max(n) } else { n };
        for (i, q) in ps.iter().enumerate() {
            let (x, w, other) = cpu[i];
            let (xn, wn, on, ev) = cpu_step(r, x, other, w, q.ty);
            sum.events += ev;
            cpu[i] = (xn, wn, on);
            let mut amplified = 0.0f32;
            for sh in shadows[i].iter_mut() {
                let (x, _, o, _) = cpu_step(r, sh.0, sh.2, sh.1, q.ty);
                *sh = (jitter(&mut rng, x, tol), wn, jitter(&mut rng, o, tol));
                amplified = amplified
                    .max(spread(sh.0, xn, tol))
                    .max(spread(sh.2, on, tol));
            }
            let growth = linear.max(2.0 * amplified);
            sum.amplification = sum.amplification.max(growth / linear);
            let worst = check_particle(&format!("free run {step}"), i, &gpu, cpu[i], tol * growth)?;
            sum.worst = sum.worst.max(worst);
        }
    }
    Ok(sum)
}

/// Runs `particles` through `scene` in lockstep and in a free run of `steps` steps each and
/// returns the lockstep's summary (the branches the reference took).
pub fn both(ctx: &Context, scene: &SceneFile, ps: &[P], steps: usize, tol: f32) -> Summary {
    let r = Reference::new(scene).unwrap();
    let label = format!(
        "{} ({:?})",
        std::thread::current().name().unwrap_or("?"),
        scene.integrator
    );
    let mut sim = start(ctx, scene, ps);
    let lock = lockstep(&mut sim, &r, ps, steps, tol).unwrap_or_else(|e| panic!("{label}: {e}"));
    let mut sim = start(ctx, scene, ps);
    let free = free_run(&mut sim, &r, ps, steps, tol).unwrap_or_else(|e| panic!("{label}: {e}"));
    eprintln!(
        "{label}: worst error {:.3} of the tolerance in lockstep, {:.3} free (allowance widened \
         {:.1} times for the dynamics); {} branch(es) decided by rounding; {:?}",
        lock.worst,
        free.worst,
        free.amplification,
        lock.branches.len(),
        lock.events
    );
    lock.few_branches(steps);
    lock
}

/// Only the lockstep (for colliders: a free run can take a different branch once a particle
/// comes within rounding of a surface, and then differs by the size of the bounce).
pub fn locked(ctx: &Context, scene: &SceneFile, ps: &[P], steps: usize, tol: f32) -> Summary {
    let r = Reference::new(scene).unwrap();
    let label = format!(
        "{} ({:?})",
        std::thread::current().name().unwrap_or("?"),
        scene.integrator
    );
    let mut sim = start(ctx, scene, ps);
    let lock = lockstep(&mut sim, &r, ps, steps, tol).unwrap_or_else(|e| panic!("{label}: {e}"));
    eprintln!(
        "{label}: worst error {:.3} of the tolerance in lockstep; deepest {:e}; {} branch(es) \
         decided by rounding: {:?}; {:?}",
        lock.worst,
        lock.deepest,
        lock.branches.len(),
        lock.branches,
        lock.events
    );
    lock.few_branches(steps);
    lock
}

// ---------------------------------------------------------------------------------------------
// Colliders
// ---------------------------------------------------------------------------------------------

/// Collider scenes: dt, slow speed, steps, and the variants without and with gravity (the second
/// makes particles land again and again, slide and rest).
pub const COLLIDER_DT: f32 = 0.02;

pub const COLLIDER_STEPS: usize = 40;

pub const GRAVITY: &str = "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n";
