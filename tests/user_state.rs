//! User state (`[[state]]`, src/sim/particles/user_state.rs): textures of the user's own,
//! updated by a pass each after the integration, against CPU twins of their updates; the value at
//! birth under every kind of emission; custom forces reading a state by name; the dump; scene
//! errors at their line and column, GLSL errors at the user's file and line.

mod common;

use common::context;
use texflow::scene::{self, SceneFile};
use texflow::sim::ParticleSim;

const SIZE: [u32; 2] = [16, 8];

/// A scene of `SIZE` with `emitter` (a whole `[[emitters.*]]` table) and `body`.
fn scene_with(emitter: &str, body: &str) -> SceneFile {
    let src = format!(
        "name = \"user-state\"\nintegrator = \"euler\"\n[particles]\nsize = {SIZE:?}\n\
         [time]\ndt = 0.05\n{emitter}\n{body}"
    );
    scene::parse("user_state.toml", &src).expect("a valid scene")
}

/// Permanent particles at rest, spread over a box.
const INITIAL: &str = "[[emitters.initial]]\nshape = \"box\"\ncenter = [0.0, 0.0, 0.0]\n\
                       size = [2.0, 2.0, 2.0]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n";

fn texel(a: &[f32], i: usize) -> [f32; 4] {
    [a[4 * i], a[4 * i + 1], a[4 * i + 2], a[4 * i + 3]]
}

#[test]
fn updates_follow_their_cpu_twin() {
    let ctx = context();
    // x: a clock (T += dt); y: exponential decay by forward Euler, T' = T (1 - k dt), k = 0.5;
    // z: the particle's index at birth; w: another state's previous value (the clock, one step
    // late: every update reads the previous step's values).
    let body = "[[state]]\nname = \"clock\"\ninit = \"vec4(0.0, 1.0, float(index), 0.0)\"\n\
                update = \"vec4(clock.x + dt, clock.y * (1.0 - 0.5 * dt), clock.z, lag.x)\"\n\
                [[state]]\nname = \"lag\"\ninit = \"vec4(0.0)\"\nupdate = \"clock\"\n";
    let s = scene_with(INITIAL, body);
    let mut sim = ParticleSim::new(&ctx, &s, 3).unwrap();
    let steps = 40;
    for _ in 0..steps {
        sim.step().unwrap();
    }
    let got = sim.read_user_state("clock").unwrap();
    let lag = sim.read_user_state("lag").unwrap();
    // The twin, in f32 as the shader computes it: the clock after each step, and the decay.
    let dt = 0.05f32;
    let mut clocks = vec![0.0f32];
    let mut decay = 1.0f32;
    for _ in 0..steps {
        clocks.push(clocks[clocks.len() - 1] + dt);
        decay *= 1.0 - 0.5 * dt;
    }
    let clock = clocks[steps];
    for i in 0..(SIZE[0] * SIZE[1]) as usize {
        let [c, d, idx, w] = texel(&got, i);
        assert_eq!(c, clock, "texel {i}: the clock");
        assert!((d - decay).abs() <= 1e-6, "texel {i}: decay {d} != {decay}");
        assert_eq!(idx, i as f32, "texel {i}: the index at birth");
        // lag is the clock one step late; clock.w is lag.x one step late again.
        assert_eq!(texel(&lag, i)[0], clocks[steps - 1], "texel {i}: lag");
        assert_eq!(w, clocks[steps - 2], "texel {i}: clock.w");
    }
    // The closed form of the decay agrees to first order (the Euler twin is the exact reference).
    let exact = (-0.5f32 * dt * steps as f32).exp();
    assert!((decay - exact).abs() < 0.01, "{decay} vs e^(-kt) = {exact}");
    common::no_gl_error(&ctx);
}
