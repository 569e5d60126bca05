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

/// A fresh directory for this test's files.
fn dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("texflow-ustate-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A state that remembers its birth: `x` = the time of birth (`time - age` at birth), `z` the
/// updates since. Checked against each live particle's age at the end under the allocator and
/// under time stamps, after particles died and were born again in the same texels.
#[test]
fn init_runs_at_every_birth() {
    let ctx = context();
    let body = "[[state]]\nname = \"born\"\ninit = \"vec4(time - age, float(index), 0.0, 0.0)\"\n\
                update = \"born + vec4(0.0, 0.0, 1.0, 0.0)\"\n";
    let spread = "shape = \"point\"\ncenter = [0.0, 0.0, 0.0]\ndirection = [0.0, 1.0, 0.0]\n\
                  speed = [0.5, 1.0]\n";
    // The min-heap allocator: passes cover the live rows only.
    let allocator = format!(
        "[[emitters.allocator]]\nallocator = \"min_heap\"\nrate = 150.0\nlife = [0.3, 0.6]\n{spread}"
    );
    let timestamp = format!("[[emitters.timestamp]]\ncycle = 0.5\nlife = [0.2, 0.4]\n{spread}");
    for (emitter, first_update) in [(allocator, 1.0f32), (timestamp, 0.0)] {
        let s = scene_with(&emitter, body);
        let mut sim = ParticleSim::new(&ctx, &s, 5).unwrap();
        for _ in 0..50 {
            sim.step().unwrap();
        }
        let (p, st) = (
            sim.read_positions().unwrap(),
            sim.statics().read_f32().unwrap(),
        );
        let born = sim.read_user_state("born").unwrap();
        let (dt, now) = (0.05f32, sim.time() as f32);
        let mut live = 0;
        for i in 0..(SIZE[0] * SIZE[1]) as usize {
            let (p, st, b) = (texel(&p, i), texel(&st, i), texel(&born, i));
            if !texflow::sim::particle_live(p) {
                continue;
            }
            live += 1;
            let age = st[2] - p[3];
            assert!(
                (b[0] - (now - age)).abs() < 1e-4,
                "texel {i}: born {b:?}, age {age}"
            );
            assert_eq!(b[1], i as f32);
            // Updates since birth: the steps lived after the birth step.
            let steps = age / dt - first_update;
            assert!(
                (b[2] - steps.floor()).abs() < 1.0 && b[2] <= steps + 1e-3,
                "texel {i}: {} updates, age {age} s",
                b[2]
            );
        }
        // 2.5 s of lives under 0.6 s: every texel alive now was born again at least once.
        assert!(live > 10, "{live} live particles");
    }
    common::no_gl_error(&ctx);
}

/// A custom force reads a state by name: a charge set at birth from the particle's random number
/// pushes it up or down, `v_y = n dt q / m` after n Euler steps from rest.
#[test]
fn custom_forces_read_states_by_name() {
    let ctx = context();
    let d = dir("force");
    std::fs::write(
        d.join("lift.glsl"),
        "vec3 force(vec3 x, vec3 v, float age, int type) {\n    \
         return vec3(0.0, charge.x, 0.0);\n}\n",
    )
    .unwrap();
    let src = format!(
        "name = \"charged\"\n[particles]\nsize = {SIZE:?}\n[time]\ndt = 0.05\n{INITIAL}\n\
         [[forces.custom]]\nglsl = \"lift.glsl\"\n[[state]]\nname = \"charge\"\n\
         init = \"vec4(random < 0.5 ? 2.0 : -1.0)\"\n"
    );
    std::fs::write(d.join("charged.toml"), src).unwrap();
    let s = scene::load(d.join("charged.toml").to_str().unwrap()).unwrap();
    let mut sim = ParticleSim::new(&ctx, &s, 2).unwrap();
    let n = 20;
    for _ in 0..n {
        sim.step().unwrap();
    }
    let v = sim.read_velocities().unwrap();
    let q = sim.read_user_state("charge").unwrap();
    let st = sim.statics().read_f32().unwrap();
    let mut signs = [0, 0];
    for i in 0..(SIZE[0] * SIZE[1]) as usize {
        let want_q = if texel(&st, i)[3] < 0.5 { 2.0 } else { -1.0 };
        assert_eq!(
            texel(&q, i),
            [want_q; 4],
            "texel {i}: the charge at birth, kept"
        );
        let want = n as f32 * 0.05 * want_q;
        assert!(
            (texel(&v, i)[1] - want).abs() < 1e-4,
            "texel {i}: v_y {:?}",
            texel(&v, i)
        );
        signs[(want_q > 0.0) as usize] += 1;
    }
    assert!(
        signs[0] > 0 && signs[1] > 0,
        "both charges occur: {signs:?}"
    );
    common::no_gl_error(&ctx);
}

/// Scene errors name the file, line and column of the offending key.
#[test]
fn bad_states_are_refused_at_their_line_and_column() {
    let head = format!("name = \"bad\"\n[particles]\nsize = {SIZE:?}\n{INITIAL}");
    let lines = head.lines().count();
    for (table, line, column, want) in [
        (
            "name = \"Temp\"\ninit = \"vec4(0.0)\"",
            1,
            8,
            "not a name GLSL can read",
        ),
        ("name = \"age\"\ninit = \"vec4(0.0)\"", 1, 8, "is taken"),
        ("name = \"exp\"\ninit = \"vec4(0.0)\"", 1, 8, "is taken"),
        (
            "name = \"t\"\ninit = \"vec4(0.0); discard\"",
            2,
            8,
            "one GLSL vec4 expression",
        ),
        (
            "name = \"t\"\ninit = \"0.0\"\nupdate = \"  \"",
            3,
            10,
            "update is empty",
        ),
        (
            "name = \"t\"\ninit = \"0.0\"\nformat = \"rgba8\"",
            3,
            10,
            "rgba8",
        ),
        (
            "name = \"t\"\ninit = \"0.0\"\npass = \"later\"",
            3,
            8,
            "integrate",
        ),
    ] {
        let src = format!("{head}[[state]]\n{table}\n");
        let e = scene::parse("bad.toml", &src).unwrap_err().to_string();
        let at = format!("bad.toml:{}:{column}", lines + 1 + line);
        assert!(
            e.contains(&at) && e.contains(want),
            "{table:?}: {e} (want {at})"
        );
    }
    // Twice the same name: the second one is refused.
    let twice =
        "[[state]]\nname = \"t\"\ninit = \"0.0\"\n[[state]]\nname = \"t\"\ninit = \"1.0\"\n";
    let e = scene::parse("bad.toml", &format!("{head}{twice}"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(&format!("bad.toml:{}:8", lines + 5)) && e.contains("named twice"),
        "{e}"
    );
    // The collision stage carries the states along its sorts (tests/user_state_exchange.rs).
    let collide = format!(
        "{head}[collisions]\nradius = 0.05\ncell = 0.1\nbounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\n[[state]]\nname = \"t\"\ninit = \"0.0\"\n"
    );
    scene::parse("ok.toml", &collide).expect("states with [collisions]");
}

/// GLSL that does not compile: the error names the helper file and line, or the state's key
/// and where it is in the scene file.
#[test]
fn glsl_errors_name_the_users_file_and_line() {
    let ctx = context();
    let d = dir("glsl");
    std::fs::write(
        d.join("heat.glsl"),
        "// Cooling.\nfloat cool(float t) {\n    return t * no_such_rate;\n}\n",
    )
    .unwrap();
    let scene_file = |body: &str| {
        let src = format!("name = \"glsl\"\n[particles]\nsize = {SIZE:?}\n{INITIAL}{body}");
        let path = d.join("glsl.toml");
        std::fs::write(&path, src).unwrap();
        scene::load(path.to_str().unwrap()).unwrap()
    };
    let s = scene_file(
        "[[state]]\nname = \"heat\"\nglsl = \"heat.glsl\"\ninit = \"1.0\"\n\
         update = \"cool(heat.x)\"\n",
    );
    let e = ParticleSim::new(&ctx, &s, 1).unwrap_err().to_string();
    let file = d.join("heat.glsl");
    assert!(e.contains(&format!("{}:3", file.display())), "{e}");
    assert!(!e.contains("glsl/sim"), "{e}");
    // An undeclared name in an expression: the state's key, and its place in the scene file.
    let s = scene_file("[[state]]\nname = \"heat\"\ninit = \"1.0\"\nupdate = \"heat * coolth\"\n");
    let e = ParticleSim::new(&ctx, &s, 1).unwrap_err().to_string();
    let lines = INITIAL.lines().count() + 3;
    let at = format!(
        "state.heat.update is at {}:{}:10",
        d.join("glsl.toml").display(),
        lines + 4
    );
    assert!(
        e.contains("user state `heat`") && e.contains("`coolth' undeclared"),
        "{e}"
    );
    assert!(e.contains(&at) && !e.contains("user-state:"), "{e}");
    // `scene check` compiles the passes too.
    let e = texflow::sim::particles::check_custom_forces(&ctx, &s).unwrap_err();
    assert!(e.to_string().contains(&at), "{e}");
    common::no_gl_error(&ctx);
}

/// `render.color` colours each particle by a state: the left half of a box of particles hot
/// (red), the right half cold (blue), seen from the front. The picture's left half holds red
/// pixels and no blue ones (away from the middle), its right half the reverse, and nothing is drawn white (the
/// keyframes' colour the expression replaces).
#[test]
fn renderer_colours_particles_by_a_state() {
    let ctx = context();
    let src = format!(
        "name = \"colour\"\n[particles]\nsize = [32, 32]\n{INITIAL}\
         [[state]]\nname = \"heat\"\ninit = \"x.x < 0.0 ? 1.0 : 0.0\"\n\
         [render]\nresolution = [64, 64]\npoint_size = 2.0\n\
         color = \"heat.x > 0.5 ? vec4(1.0, 0.0, 0.0, 1.0) : vec4(0.0, 0.0, 1.0, 1.0)\"\n\
         [render.camera]\ndistance = 5.0\nelevation = 0.0\n"
    );
    let s = scene::parse("colour.toml", &src).unwrap();
    let mut e = texflow::ParticleEngine::new(&ctx, &s, 4).unwrap();
    e.advance_frame().unwrap();
    let img = e.render().unwrap();
    let (w, h) = img.dimensions();
    let mut counts = [[0usize; 3]; 2]; // [left, right] × [red, blue, white]
    for (x, _, p) in img.enumerate_pixels() {
        // Points at x = 0 straddle the middle column: a band of 4 pixels is neither side.
        if x.abs_diff(w / 2) < 3 {
            continue;
        }
        let side = (x >= w / 2) as usize;
        let [r, g, b] = p.0;
        if r > 100 && b < 50 {
            counts[side][0] += 1;
        }
        if b > 100 && r < 50 {
            counts[side][1] += 1;
        }
        if r > 100 && g > 100 && b > 100 {
            counts[side][2] += 1;
        }
    }
    assert!(
        counts[0][0] > 20 && counts[1][1] > 20,
        "{counts:?} in {w}x{h}"
    );
    assert_eq!((counts[0][1], counts[1][0]), (0, 0), "{counts:?}");
    assert_eq!(counts[0][2] + counts[1][2], 0, "{counts:?}");
    // Under alpha blending the depth sort would leave the states behind: refused.
    let sorted = src.replace("[render]\n", "[render]\nblending = \"alpha\"\n");
    let e = scene::parse("colour.toml", &sorted)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("render.color cannot be used here") && e.contains("colour.toml:"),
        "{e}"
    );
    common::no_gl_error(&ctx);
}

/// `--dump-state` writes each state beside the positions, one row per live particle.
#[test]
fn dumps_hold_the_states() {
    let d = dir("dump");
    let src = format!(
        "name = \"dump\"\n[particles]\nsize = {SIZE:?}\n{INITIAL}\
         [[state]]\nname = \"tag\"\nformat = \"rgba16f\"\ninit = \"vec4(float(index), 0.5, 0.0, 1.0)\"\n"
    );
    std::fs::write(d.join("dump.toml"), src).unwrap();
    let out = d.join("dumps");
    let o = common::cli::texflow(&[
        "render",
        d.join("dump.toml").to_str().unwrap(),
        "--frames",
        "1",
        "--out",
        d.join("frames").to_str().unwrap(),
        "--dump-state",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", common::cli::stderr(&o));
    let (shape, tags) = texflow::npy::read_f32_shaped(&out.join("state_tag_00000.npy")).unwrap();
    let n = (SIZE[0] * SIZE[1]) as usize;
    assert_eq!(shape, vec![n, 4]);
    for i in 0..n {
        assert_eq!(texel(&tags, i), [i as f32, 0.5, 0.0, 1.0], "row {i}");
    }
}

/// A half-float state that grows past 65504 overflows (to infinity, or clamped to 65504 as
/// llvmpipe writes it): every live particle is counted by the GPU counter; the same growth in
/// rgba32f stays finite.
#[test]
fn half_float_overflow_is_counted() {
    use texflow::sim::nonfinite::NonFiniteCounter;
    let ctx = context();
    for (format, overflows) in [("rgba16f", true), ("rgba32f", false)] {
        let body = format!(
            "[[state]]\nname = \"grow\"\nformat = \"{format}\"\ninit = \"1.0\"\n\
             update = \"grow * 10.0\"\n"
        );
        let mut sim = ParticleSim::new(&ctx, &scene_with(INITIAL, &body), 1).unwrap();
        let counter = NonFiniteCounter::for_sim(&ctx, &sim).unwrap();
        for _ in 0..4 {
            sim.step().unwrap();
        }
        // 10^4: finite in both.
        assert_eq!(counter.count_sim(&sim).unwrap().non_finite, 0, "{format}");
        sim.step().unwrap();
        let c = counter.count_sim(&sim).unwrap();
        let n = (SIZE[0] * SIZE[1]) as u64;
        assert_eq!(c.live, n);
        assert_eq!(
            c.non_finite,
            if overflows { n } else { 0 },
            "{format}: {c:?}"
        );
        assert_eq!(c.non_finite_position, 0);
        // Infinity, or the largest half where the driver clamps (llvmpipe).
        let g = sim.read_user_state("grow").unwrap();
        let want = if overflows { 65504.0 } else { 1e5 };
        assert!(
            g[0] >= want && (overflows || g[0] == want),
            "{format}: {}",
            g[0]
        );
    }
    common::no_gl_error(&ctx);
}

/// The expressions' `x` and `v` are this step's integrated state under every kind of update:
/// one MRT pass, separate passes, Verlet (whose velocity is implied by two positions).
#[test]
fn states_read_the_integrated_position_and_velocity() {
    let ctx = context();
    let body = "[[forces.gravity]]\nacceleration = [0.3, -9.81, 0.0]\n[[state]]\nname = \"seen\"\n\
                init = \"vec4(v, x.y)\"\nupdate = \"vec4(v, x.y)\"\n";
    let moving = INITIAL.replace("speed = [0.0, 0.0]", "speed = [0.5, 1.5]");
    for head in [
        "integrator = \"euler\"",
        "passes = \"separate\"",
        "integrator = \"verlet\"",
    ] {
        let src = format!(
            "name = \"kinds\"\n{head}\n[particles]\nsize = {SIZE:?}\n[time]\ndt = 0.05\n{moving}{body}"
        );
        let s = scene::parse("kinds.toml", &src).unwrap();
        let mut sim = ParticleSim::new(&ctx, &s, 9).unwrap();
        for _ in 0..12 {
            sim.step().unwrap();
        }
        let (x, v) = (
            sim.read_positions().unwrap(),
            sim.read_velocities().unwrap(),
        );
        let seen = sim.read_user_state("seen").unwrap();
        for i in 0..(SIZE[0] * SIZE[1]) as usize {
            let (x, v, got) = (texel(&x, i), texel(&v, i), texel(&seen, i));
            let want = [v[0], v[1], v[2], x[1]];
            for k in 0..4 {
                assert!(
                    (got[k] - want[k]).abs() <= 1e-4 * want[k].abs().max(1.0),
                    "{head}, texel {i}: {got:?} != {want:?}"
                );
            }
        }
    }
    common::no_gl_error(&ctx);
}

/// `render.size`: a state scales one particle's point by 3, so it covers about 9 times the
/// pixels of the other; without the key both cover the same.
#[test]
fn renderer_sizes_particles_by_a_state() {
    let ctx = context();
    let src = "name = \"size\"\n[particles]\nsize = [4, 4]\n\
               [[emitters.initial]]\nshape = \"point\"\ncenter = [0.0, 0.0, 0.0]\n\
               direction = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n\
               [[state]]\nname = \"scale\"\ninit = \"index == 0 ? 1.0 : 3.0\"\n\
               [render]\nresolution = [64, 64]\npoint_size = 4.0\ncolor = \"vec4(1.0)\"\n\
               size = \"size * scale.x\"\n\
               [render.camera]\ndistance = 5.0\nelevation = 0.0\n";
    let lit = |src: &str| {
        let s = scene::parse("size.toml", src).unwrap();
        let mut e = texflow::ParticleEngine::new(&ctx, &s, 4).unwrap();
        // Two particles, left and right of the centre; the rest dead.
        let two = [([-1.0, 0.0, 0.0], [0.0; 3]), ([1.0, 0.0, 0.0], [0.0; 3])];
        common::set_particles(e.sim_mut(), &two, |_, _| 0.5);
        let img = e.render().unwrap();
        let w = img.width();
        let mut counts = [0usize; 2];
        for (x, _, p) in img.enumerate_pixels() {
            if p.0.iter().any(|&c| c > 20) {
                counts[(x >= w / 2) as usize] += 1;
            }
        }
        counts
    };
    let [small, big] = lit(src);
    assert!(
        small >= 4 && big >= 6 * small && big <= 10 * small,
        "{small} {big}"
    );
    let [a, b] = lit(&src.replace("size = \"size * scale.x\"\n", ""));
    assert_eq!(a, b, "without render.size");
    // Not where the renderer cannot read the states (the depth sort's gather).
    let sorted = src.replace("[render]\n", "[render]\nblending = \"alpha\"\n");
    let sorted = sorted.replace("color = \"vec4(1.0)\"\n", "");
    let e = scene::parse("size.toml", &sorted).unwrap_err().to_string();
    assert!(e.contains("render.size cannot be used here"), "{e}");
    common::no_gl_error(&ctx);
}
