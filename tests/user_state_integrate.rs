//! User states updated inside the integration pass (`[[state]]` with `pass = "integrate"`,
//! src/sim/particles/user_state_mrt.rs): the same scene with `pass = "own"` gives the same
//! state, both against a CPU twin of the expression fed with the position and velocity read back
//! after every step; births under the allocator; the pass list; the refusals.

mod common;

use common::{context, no_gl_error};
use texflow::scene::{self, SceneFile, StatePassKind};
use texflow::sim::{particle_live, ParticleSim};

const SIZE: [u32; 2] = [16, 8];
const DT: f32 = 0.02;

/// Particles thrown up in a box under gravity and damping (velocities change every step), with
/// `emitter` and `state`.
fn scene_with(emitter: &str, state: &str) -> SceneFile {
    let src = format!(
        "name = \"integrate-state\"\nintegrator = \"euler\"\n[particles]\nsize = {SIZE:?}\n\
         [time]\ndt = {DT}\n{emitter}\n[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n\
         [[forces.damping]]\nrate = 0.5\n{state}"
    );
    scene::parse("integrate_state.toml", &src).expect("a valid scene")
}

const INITIAL: &str = "[[emitters.initial]]\nshape = \"box\"\ncenter = [0.0, 0.0, 0.0]\n\
                       size = [2.0, 2.0, 2.0]\ndirection = [0.0, 1.0, 0.0]\n\
                       speed = [1.0, 3.0]\n";

/// x: the path length Σ |v| dt; y: Σ x.y dt; z: the index; w: the other state's previous x.
const STATES: &str = "[[state]]\nname = \"path\"\ninit = \"vec4(0.0, 0.0, float(index), 0.0)\"\n\
                      update = \"vec4(path.x + dt * length(v), path.y + dt * x.y, path.z, \
                      lag.x)\"\n[[state]]\nname = \"lag\"\ninit = \"vec4(0.0)\"\n\
                      update = \"path\"\n";

fn texel(a: &[f32], i: usize) -> [f32; 4] {
    [a[4 * i], a[4 * i + 1], a[4 * i + 2], a[4 * i + 3]]
}

/// Runs `s` with the states' `pass` set to `pass` for `steps` steps; returns the states and,
/// stepped along, the twin of `path` and `lag` from the positions and velocities read back.
fn run(
    s: &SceneFile,
    pass: [StatePassKind; 2],
    steps: usize,
) -> (Vec<f32>, Vec<f32>, Vec<[f32; 4]>) {
    let ctx = context();
    let mut s = s.clone();
    s.state[0].pass = pass[0];
    s.state[1].pass = pass[1];
    let mut sim = ParticleSim::new(&ctx, &s, 11).unwrap();
    let n = (SIZE[0] * SIZE[1]) as usize;
    let mut twin: Vec<[f32; 4]> = (0..n).map(|i| [0.0, 0.0, i as f32, 0.0]).collect();
    let mut lag = vec![[0.0f32; 4]; n];
    for _ in 0..steps {
        sim.step().unwrap();
        let (x, v) = (
            sim.read_positions().unwrap(),
            sim.read_velocities().unwrap(),
        );
        for i in 0..n {
            let (x, v) = (texel(&x, i), texel(&v, i));
            let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            let old = twin[i];
            twin[i] = [old[0] + DT * speed, old[1] + DT * x[1], old[2], lag[i][0]];
            lag[i] = old;
        }
    }
    let got = sim.read_user_state("path").unwrap();
    let got_lag = sim.read_user_state("lag").unwrap();
    no_gl_error(&ctx);
    (got, got_lag, twin)
}

#[test]
fn the_integration_pass_gives_what_the_own_pass_gives() {
    let s = scene_with(INITIAL, STATES);
    let steps = 25;
    let (own, own_lag, twin) = run(&s, [StatePassKind::Own; 2], steps);
    let mixed = [StatePassKind::Integrate, StatePassKind::Own];
    for pass in [[StatePassKind::Integrate; 2], mixed] {
        let (got, lag, _) = run(&s, pass, steps);
        assert_eq!(got, own, "{pass:?}: path");
        assert_eq!(lag, own_lag, "{pass:?}: lag");
    }
    for (i, want) in twin.iter().enumerate() {
        let got = texel(&own, i);
        for k in 0..4 {
            assert!(
                (got[k] - want[k]).abs() <= 1e-5 * want[k].abs().max(1.0),
                "texel {i}: {got:?} against the twin's {want:?}"
            );
        }
    }
    // The velocities changed (gravity, damping): a state of the last step's velocity would not
    // match.
    assert!(twin.iter().any(|t| t[0] > 0.5), "{:?}", twin[0]);
}

/// Births, deaths and live rows under the min-heap allocator, and half-float velocities: the
/// state taken at birth and updated after, the same in both modes.
#[test]
fn births_and_half_velocities_match_the_own_pass() {
    let ctx = context();
    let allocator = "[[emitters.allocator]]\nallocator = \"min_heap\"\nrate = 150.0\n\
                     life = [0.3, 0.6]\nshape = \"point\"\ncenter = [0.0, 0.0, 0.0]\n\
                     direction = [0.0, 1.0, 0.0]\nspeed = [0.5, 1.0]\n";
    let born = "[[state]]\nname = \"born\"\ninit = \"vec4(time - age, random, 0.0, 0.0)\"\n\
                update = \"born + vec4(0.0, 0.0, 1.0, length(v) * dt)\"\n";
    for (emitter, half) in [(allocator, false), (INITIAL, true)] {
        let mut s = scene_with(emitter, born);
        if half {
            s.particles.velocity_format = scene::VelocityFormat::Rgba16f;
        }
        let mut out = Vec::new();
        for pass in [StatePassKind::Own, StatePassKind::Integrate] {
            s.state[0].pass = pass;
            let mut sim = ParticleSim::new(&ctx, &s, 5).unwrap();
            for _ in 0..40 {
                sim.step().unwrap();
            }
            let p = sim.read_positions().unwrap();
            let live = (0..p.len() / 4).filter(|&i| particle_live(texel(&p, i)));
            assert!(live.count() > 10);
            out.push(sim.read_user_state("born").unwrap());
        }
        for (i, (a, b)) in out[0].iter().zip(&out[1]).enumerate() {
            assert!(
                (a - b).abs() <= 1e-6 * a.abs().max(1.0),
                "half {half}: value {i}: own {a}, integrate {b}"
            );
        }
    }
    no_gl_error(&ctx);
}

#[test]
fn the_pass_list_shows_the_update_inside_the_integration() {
    let mut s = scene_with(INITIAL, STATES);
    s.state[0].pass = StatePassKind::Integrate;
    let passes = texflow::sim::particles::Features::of(&s).step_passes();
    let names: Vec<&str> = passes.iter().map(|p| p.name.as_str()).collect();
    assert!(
        names
            .iter()
            .any(|n| n.starts_with("integrate:") && n.contains("user state(s) path")),
        "{names:?}"
    );
    assert!(
        !names.iter().any(|n| n.starts_with("state path (")),
        "{names:?}"
    );
    assert!(
        names.iter().any(|n| n.starts_with("state lag (")),
        "{names:?}"
    );
}

#[test]
fn integration_states_are_refused_where_the_pass_cannot_write_them() {
    let base = format!(
        "name = \"bad\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 8]\n{INITIAL}\n\
         [[state]]\nname = \"a\"\ninit = \"vec4(0.0)\"\npass = \"integrate\"\n\
         [[state]]\nname = \"b\"\ninit = \"vec4(0.0)\"\npass = \"integrate\"\n\
         [[state]]\nname = \"c\"\ninit = \"vec4(0.0)\"\npass = \"integrate\"\n"
    );
    let line = |src: &str, nth: usize| {
        (src.lines().enumerate())
            .filter(|(_, l)| l.starts_with("pass = "))
            .nth(nth)
            .unwrap()
            .0
            + 1
    };
    // Three more targets after position and velocity: the third is one too many.
    let e = scene::parse("bad.toml", &base).unwrap_err().to_string();
    assert!(
        e.contains(&format!("bad.toml:{}:", line(&base, 2)))
            && e.contains("GL_MAX_DRAW_BUFFERS")
            && e.contains("pass = \"own\""),
        "{e}"
    );
    let two = base.replacen("pass = \"integrate\"\n", "", 1);
    scene::parse("ok.toml", &two).expect("two states fit");
    for (from, to) in [
        ("integrator = \"euler\"", "integrator = \"verlet\""),
        (
            "integrator = \"euler\"",
            "integrator = \"euler\"\npasses = \"separate\"",
        ),
    ] {
        let bad = two.replacen(from, to, 1);
        let e = scene::parse("bad.toml", &bad).unwrap_err().to_string();
        assert!(
            e.contains(&format!("bad.toml:{}:", line(&bad, 0))) && e.contains("pass = \"own\""),
            "{to}: {e}"
        );
    }
}

/// A name the GLSL does not know in an update of the integration pass names the state and
/// where its expressions are, as in its own pass.
#[test]
fn an_unknown_name_in_an_integrated_update_names_the_state() {
    let ctx = context();
    let src = format!(
        "name = \"bad\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 8]\n{INITIAL}\n\
         [[state]]\nname = \"path\"\ninit = \"vec4(0.0)\"\nupdate = \"path + heat\"\n\
         pass = \"integrate\"\n"
    );
    let line = src.lines().position(|l| l.starts_with("update =")).unwrap() + 1;
    let s = scene::parse("bad.toml", &src).unwrap();
    let e = ParticleSim::new(&ctx, &s, 1).unwrap_err().to_string();
    assert!(
        e.contains("user state `path`")
            && e.contains("heat")
            && e.contains(&format!("state.path.update is at bad.toml:{line}:")),
        "{e}"
    );
}
