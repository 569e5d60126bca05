//! Weakly compressible SPH (`[fluid]`) as scenes run it: the dam-break surge front against
//! Martin & Moyce (1952) at two resolutions (ignored: half a minute to minutes on llvmpipe), `render --json`'s
//! per-frame density error and energy, and `[fluid]`'s refusals at their line.

mod common;

use common::fluid::{tank, twin_scene_source};
use common::scene::{parse, scene_error};
use common::{context, no_gl_error};
use texflow::report::fluid::MARTIN_MOYCE;
use texflow::scene;
use texflow::sim::{ParticleSim, Simulation};

/// The dam break of Martin & Moyce: a slab of n × 2n × 2 particles (a = 2¼ in, Δx = a / n,
/// h = 1.3 Δx) against the left wall of a tank 5a long and 2 Δx deep, started hydrostatic; the
/// floor and the wall behind the column no-slip (`wall = "no_slip"`), the slab's faces free-slip
/// (symmetry planes: the experiment is two-dimensional). The front (the foremost particle plus
/// half a spacing) at each of Martin & Moyce's times, printed against their Table 2; returns the
/// largest |Z / Z_MM − 1|.
fn dam_break(n: u32) -> f64 {
    let a = 0.05715f32;
    let dx = a / n as f32;
    let fluid = format!(
        "speed_of_sound = 15.0\nviscosity = 0.05\nspacing = {dx}\nsmoothing = {}\n\
         initial = \"hydrostatic\"",
        1.3 * dx
    );
    let block = ([a / 2.0, a, dx], [a, 2.0 * a, 2.0 * dx]);
    let side = 2 * n.max(16);
    let dt = 9e-5 * 16.0 / n as f32;
    let mut src = tank([side, side], [5.0 * a, 2.0 * dx], block, dt, &fluid);
    for normal in ["[0.0, 1.0, 0.0]", "[1.0, 0.0, 0.0]"] {
        let k = format!("normal = {normal}\nresilience = 0.0");
        assert!(src.contains(&k), "{k}");
        src = src.replace(&k, &format!("{k}\nwall = \"no_slip\""));
    }
    let s = parse("dam", &src);
    let ctx = context();
    let mut sim = ParticleSim::new(&ctx, &s, 1).expect("dam scene");
    let scale = (2.0 * 9.81 / a as f64).sqrt();
    let mut worst = 0.0f64;
    for (t_ref, z_ref) in MARTIN_MOYCE {
        while sim.time() * scale < t_ref {
            sim.step().unwrap();
        }
        let (x, _) = sim.read_state().unwrap();
        let front = (0..x.len() / 4)
            .filter(|&i| x[i * 4 + 3] > 0.0)
            .map(|i| x[i * 4] as f64)
            .fold(0.0, f64::max)
            + dx as f64 / 2.0;
        let z = front / a as f64;
        let err = z / z_ref - 1.0;
        eprintln!(
            "Δx = a/{n}: T {:.3} (Martin & Moyce {t_ref}): Z {z:.3} against {z_ref}, {:+.1} %",
            sim.time() * scale,
            100.0 * err
        );
        worst = worst.max(err.abs());
    }
    eprintln!("Δx = a/{n}: largest deviation {:.1} %", 100.0 * worst);
    assert_eq!(sim.truncated_searches().unwrap(), 0);
    no_gl_error(&ctx);
    worst
}

/// At Δx = a/16 the front is within 10 % of Martin & Moyce's at each of their times up to T = 3
/// (measured: at most +8.2 %, at T = 1.19; docs/numerics.md). Half a minute on llvmpipe:
/// `cargo test --release --test fluid_scenes dam_break -- --ignored --nocapture` prints the table.
#[test]
#[ignore]
fn dam_break_front_follows_martin_and_moyce() {
    let worst = dam_break(16);
    assert!(worst <= 0.10, "largest deviation {worst}");
}

/// At Δx = a/32 the front leads more early on (+12.9 % at T = 1.19): the artificial viscosity,
/// which carries the no-slip walls' shear and smooths the toe, falls with h. Asserted within
/// 15 %, the bound docs/numerics.md states for the model. Two to three minutes on llvmpipe.
#[test]
#[ignore]
fn dam_break_front_at_twice_the_resolution() {
    let worst = dam_break(32);
    assert!(worst <= 0.15, "largest deviation {worst}");
}

/// The refusals' tank: the twin's column with `fluid` keys and time step `dt`.
fn base(dt: f32, fluid: &str) -> String {
    common::fluid::twin_tank(dt, fluid)
}

/// The 1-based line of `src` that starts with `key`.
fn line_of(src: &str, key: &str) -> usize {
    1 + src.lines().position(|l| l.starts_with(key)).expect(key)
}

/// Each scene is refused at the line of its key, with a message that says `says`.
fn assert_refused(cases: impl IntoIterator<Item = (String, &'static str, &'static str)>) {
    for (src, key, says) in cases {
        let (line, _, message) = scene_error(scene::parse("bad.toml", &src));
        assert_eq!(line, line_of(&src, key), "{message}\n{src}");
        assert!(message.contains(says), "{message}");
    }
}

/// `[fluid]`'s refusals name the key, its line and column, and the fix.
#[test]
fn bad_fluid_scenes_are_refused_at_their_key() {
    let ok = "speed_of_sound = 10.0\nspacing = 0.02";
    let no_slip_floor = |src: String| {
        let k = "normal = [0.0, 1.0, 0.0]\nresilience = 0.0";
        src.replace(k, &format!("{k}\nwall = \"no_slip\""))
    };
    let cases: [(String, &str, &str); 7] = [
        (
            no_slip_floor(base(5e-4, &format!("{ok}\nwall_correction = false"))),
            "wall = ",
            "wall_correction = true",
        ),
        (
            base(5e-4, &format!("{ok}\ninitial = \"hydrostatic\""))
                .replace("[0.0, -9.81, 0.0]", "[-9.81, 0.0, 0.0]"),
            "initial",
            "gravity along −y",
        ),
        (base(0.01, ok), "dt = ", "CFL"),
        (
            base(5e-4, &format!("{ok}\nsmoothing = 0.05")),
            "smoothing",
            "spacing",
        ),
        (
            base(5e-4, "speed_of_sound = 10.0\nspacing = 0.02\ngamma = 9.0"),
            "gamma",
            "[1, 7]",
        ),
        (
            base(5e-4, ok)
                + "[collisions]\nradius = 0.01\nbounds = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]]\n",
            "[collisions]",
            "remove [collisions]",
        ),
        (
            base(5e-4, ok).replace("shape = \"box\"", "shape = \"point\""),
            "shape",
            "box",
        ),
    ];
    assert_refused(cases);
    let (_, _, m) = scene_error(scene::parse(
        "bad.toml",
        &base(5e-4, &format!("{ok}\nviscosity = 10.0")),
    ));
    assert!(m.contains("viscous"), "{m}");
    // A no-slip wall past the 31 planes whose bits the shader takes.
    let far = "[[colliders.plane]]\npoint = [0.0, 0.0, 0.0]\nnormal = [0.0, 1.0, 0.0]\n";
    let src = base(5e-4, ok) + &far.repeat(27) + far + "wall = \"no_slip\"\n";
    let (line, _, m) = scene_error(scene::parse("bad.toml", &src));
    assert_eq!(line, line_of(&src, "wall = "), "{m}");
    assert!(m.contains("first 31 planes"), "{m}");
}

/// `fluid.cell` outside its three values, and a lattice of cells of h past 2^24 cells, are
/// refused at their key (the latter naming the coarser cell).
#[test]
fn bad_fluid_cells_are_refused_at_their_key() {
    let ok = "speed_of_sound = 10.0\nspacing = 0.02";
    assert_refused([
        (
            base(5e-4, &format!("{ok}\ncell = \"3h\"")),
            "cell",
            "expected one of `auto`, `h`, `2h`",
        ),
        (
            // 30 m × 1 m × 30 m in cells of h = 2 cm: 112 million cells, past 2^24.
            base(5e-4, &format!("{ok}\ncell = \"h\"")).replace(
                "bounds = [[0.0, 0.0, 0.0], [0.24, 1.0, 0.12]]",
                "bounds = [[0.0, 0.0, 0.0], [30.0, 1.0, 30.0]]",
            ),
            "bounds",
            "or cell = \"2h\"",
        ),
    ]);
}

/// `render --json` lists per written frame the fluid's density error and energy: every live
/// particle counted, the errors ordered, and the energy (kinetic + gravitational) lower at the
/// end than at the start (viscosity and the inelastic walls take it; the compression's own
/// energy is small at this speed of sound).
#[test]
fn render_json_reports_density_error_and_energy_per_frame() {
    let tmp = tempfile::tempdir().unwrap();
    let scene = tmp.path().join("fluid.toml");
    let src = twin_scene_source().replace("dt = 0.0005", "dt = 0.0005\nsubsteps = 40");
    std::fs::write(&scene, src).unwrap();
    let out = tmp.path().join("f");
    let o = common::cli::texflow(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "8",
        "--every",
        "7",
        "--resolution",
        "32",
        "--json",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", common::cli::stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let frames = v["records"]["fluid"]
        .as_array()
        .expect("a fluid array")
        .clone();
    assert_eq!(frames.len(), 2, "frames 0 and 7: {v}");
    let energy =
        |f: &serde_json::Value| f["kinetic"].as_f64().unwrap() + f["potential"].as_f64().unwrap();
    for f in &frames {
        assert_eq!(f["live"], 216, "{f}");
        let (max, mean) = (
            f["max_density_error"].as_f64().unwrap(),
            f["mean_density_error"].as_f64().unwrap(),
        );
        assert!(max >= mean && mean > 0.0 && max < 1.0, "{f}");
        assert!(f["max_compression"].as_f64().unwrap() < 0.1, "{f}");
    }
    assert_eq!(frames[1]["frame"], 7);
    assert!(
        frames[0]["kinetic"].as_f64().unwrap() > 0.0,
        "the column falls: {:?}",
        frames[0]
    );
    assert!(energy(&frames[1]) < energy(&frames[0]), "{frames:?}");
}
