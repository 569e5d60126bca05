//! Scene files through the binary: render by name or file, `scene check`, `scene passes`,
//! `--dump-state`, and malformed files refused with file, line, column and exit code 2.

mod common;

use common::cli::texflow;

use std::process::Output;

fn text(o: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

#[test]
fn scene_check_accepts_good_files_and_locates_errors() {
    let o = texflow(&["scene", "check", "tests/scenes/good.toml"]);
    assert!(o.status.success(), "{}", text(&o));
    for name in texflow::scene::BUILTIN {
        let o = texflow(&["scene", "check", name]);
        assert!(o.status.success(), "{name}: {}", text(&o));
    }
    let o = texflow(&["scene", "check", "tests/scenes/bad_friction.toml"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let t = text(&o);
    assert!(
        t.contains("tests/scenes/bad_friction.toml:") && t.contains("friction"),
        "{t}"
    );
    let o = texflow(&["scene", "check", "no/such/scene.toml"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let o = texflow(&["scene", "check", "smok"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(text(&o).contains("snow"), "{}", text(&o));
}

#[test]
fn scene_passes_prints_the_plan() {
    let o = texflow(&["scene", "passes", "smoke-unlit"]);
    assert!(o.status.success(), "{}", text(&o));
    let t = text(&o);
    assert!(t.contains("sort: oddeven") && t.contains("emit"), "{t}");
    let o = texflow(&["scene", "passes", "fire", "--json"]);
    let all: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(all["schema"], "texflow.scene.passes/1");
    assert!(all["texflow_version"].is_string());
    let v = &all["records"];
    assert_eq!(v["scene"], "fire");
    assert!(v["per_frame"].as_array().unwrap().len() == 1);
    // The list is the engine's: the fire's soft sprites are drawn (not "points"), a
    // user force is compiled into the integration pass and a user pair force into the
    // neighbour pass, because they run.
    let line = v["per_frame"][0].as_str().unwrap();
    assert!(
        line.contains("soft round sprites") && line.contains("fire's age ramp"),
        "{line}"
    );
    let o = texflow(&["scene", "passes", "fire-points"]);
    assert!(text(&o).contains("render points"), "{}", text(&o));
    let o = texflow(&["scene", "passes", "examples/boids/boids.toml"]);
    let t = text(&o);
    assert!(
        t.contains("user force examples/boids/cruise.glsl") && t.contains("1 user pair force"),
        "{t}"
    );
}

/// `render --engine cpu` draws UberFlow's E5 engine through the same frame loop; a scene it
/// does not cover is refused naming what it lacks, with nothing written.
#[test]
fn render_draws_the_cpu_engine_too() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cpu");
    let args = |engine: &str, out: &std::path::Path| {
        texflow(&[
            "render",
            "e3",
            "--engine",
            engine,
            "--particles",
            "64",
            "--resolution",
            "96x64",
            "--frames",
            "40",
            "--every",
            "39",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    let o = args("cpu", &out);
    assert!(o.status.success(), "{}", text(&o));
    let cpu = image::open(out.join("frame_00039.png")).unwrap().to_rgb8();
    let gpu_out = dir.path().join("gpu");
    assert!(args("gpu", &gpu_out).status.success());
    let gpu = image::open(gpu_out.join("frame_00039.png"))
        .unwrap()
        .to_rgb8();
    // The same particles, sorted and drawn by each engine: the frames are close (the CPU's
    // floats round differently), and both draw something.
    let lit = |img: &image::RgbImage| img.pixels().filter(|p| p.0 != [0, 0, 0]).count();
    assert!(
        lit(&cpu) > 20 && lit(&gpu) > 20,
        "{} {}",
        lit(&cpu),
        lit(&gpu)
    );
    let differ = cpu.pixels().zip(gpu.pixels()).filter(|(a, b)| {
        a.0.iter()
            .zip(b.0)
            .any(|(x, y)| (*x as i32 - y as i32).abs() > 8)
    });
    assert!(
        differ.count() * 50 <= (96 * 64),
        "the CPU and GPU frames differ in over 2 %"
    );
    let refused = dir.path().join("smoke-unlit");
    let o = texflow(&[
        "render",
        "smoke-unlit",
        "--engine",
        "cpu",
        "--frames",
        "1",
        "--quiet",
        "--out",
        refused.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("CPU engine"), "{}", text(&o));
    assert!(!refused.exists(), "nothing written for a refused run");
}

#[test]
fn render_from_a_file_with_state_dumps() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("s.toml");
    std::fs::write(
        &scene,
        texflow::scene::builtin_source("fountain")
            .unwrap()
            .replace("name = \"fountain\"", "name = \"mine\""),
    )
    .unwrap();
    let out = dir.path().join("frames");
    let dump = dir.path().join("dump");
    let o = texflow(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "6",
        "--particles",
        "64x64",
        "--resolution",
        "64x64",
        "--dump-state",
        dump.to_str().unwrap(),
        "--dump-every",
        "5",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", text(&o));
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), 6);
    let mut names: Vec<String> = std::fs::read_dir(&dump)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "positions_00000.npy",
            "positions_00005.npy",
            "statics_00000.npy",
            "statics_00005.npy",
            "velocities_00000.npy",
            "velocities_00005.npy"
        ]
    );
    // The statics of the same particles: born at most 0.1 s ago, of type 0.
    let (sshape, st) = texflow::npy::read_f32_shaped(&dump.join("statics_00005.npy")).unwrap();
    assert_eq!(sshape, [1200, 4]);
    assert!(st
        .chunks(4)
        .all(|s| (0.0..0.1).contains(&s[0]) && s[1] == 0.0));
    let (shape, pos) = texflow::npy::read_f32_shaped(&dump.join("positions_00005.npy")).unwrap();
    let (vshape, vel) = texflow::npy::read_f32_shaped(&dump.join("velocities_00005.npy")).unwrap();
    assert_eq!(shape, vshape);
    assert_eq!(shape[1], 4);
    // 12000 births per second, dt 1/120, 2 substeps, 6 frames: 1200 particles, all alive.
    assert_eq!(shape[0], 1200);
    assert!(pos.chunks(4).all(|p| p[3] > 0.0 && p[1] > -1e-3));
    // Launched upwards at 5.5-6.5 m/s, at most 0.1 s ago: still rising fast.
    assert!(vel.chunks(4).all(|v| v[1] > 3.5), "{:?}", &vel[..8]);
}

#[test]
fn malformed_scene_files_exit_2_with_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("bad.toml");
    std::fs::write(
        &scene,
        "name = \"x\"\n[particles]\nsize = [8, 8]\n[time]\ndt = -0.5\n",
    )
    .unwrap();
    let out = dir.path().join("frames");
    let o = texflow(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("bad.toml:5:6"), "{}", text(&o));
    assert!(!out.exists(), "nothing written for a bad scene");
    // Overrides are checked like the file's own values.
    let o = texflow(&[
        "render",
        "snow",
        "--dt",
        "-1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(!out.exists());
}

#[test]
fn sizes_over_the_device_limit_are_located_in_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("big.toml");
    std::fs::write(
        &scene,
        "name = \"big\"\n[particles]\nsize = [4, 70000]\n[[emitters.initial]]\n\
         direction = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n",
    )
    .unwrap();
    for args in [
        vec!["scene", "check", scene.to_str().unwrap()],
        vec![
            "render",
            scene.to_str().unwrap(),
            "--out",
            dir.path().join("f").to_str().unwrap(),
        ],
    ] {
        let o = texflow(&args);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        let t = text(&o);
        assert!(t.contains("big.toml:3:8") && t.contains("limit"), "{t}");
    }
    assert!(!dir.path().join("f").exists());
}

#[test]
fn collide_stats_prints_the_promised_fields() {
    let o = texflow(&[
        "collide-stats",
        "collide",
        "--steps",
        "150",
        "--particles",
        "32x32",
        "--k",
        "4",
        "--no-staggered",
        "--json",
        "-q",
    ]);
    assert!(o.status.success(), "{}", text(&o));
    let all: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(all["schema"], "texflow.collide-stats/1");
    assert!(all["device"]["renderer"].is_string(), "{all}");
    let v = &all["records"];
    for f in ["pairs_true", "found", "missed", "false_pairs", "gpu_ms"] {
        assert!(v[f].is_number(), "{f} missing: {v}");
    }
    assert_eq!(v["k"], 4);
    assert_eq!(v["staggered"], false);
    let n = |f: &str| v[f].as_u64().unwrap();
    assert_eq!(n("false_pairs"), 0);
    assert_eq!(n("missed") + n("found") - n("false_pairs"), n("pairs_true"));
    // A scene without collisions is refused.
    let o = texflow(&["collide-stats", "fire"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}
