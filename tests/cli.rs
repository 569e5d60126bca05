//! The command line through the built binary: frames written and decodable, and every bad input
//! refused with exit code 2, its message, and nothing written.

mod common;

use common::cli::{file_names, stderr, texflow};

use std::path::Path;
use std::process::Command;

#[test]
fn render_writes_decodable_frames_of_the_requested_size() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a/b");
    let o = texflow(&[
        "render",
        "fire",
        "--frames",
        "5",
        "--every",
        "2",
        "--particles",
        "48x40",
        "--resolution",
        "80x60",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        file_names(&out),
        ["frame_00000.png", "frame_00002.png", "frame_00004.png"]
    );
    for name in file_names(&out) {
        let img = image::open(out.join(&name)).expect("decodable PNG");
        assert_eq!((img.width(), img.height()), (80, 60), "{name}");
    }
    // --quiet prints nothing.
    assert!(o.stderr.is_empty(), "{}", stderr(&o));
}

#[test]
fn default_scene_is_fire_and_default_out_is_frames() {
    let dir = tempfile::tempdir().unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args([
            "render",
            "--frames",
            "2",
            "--particles",
            "16",
            "--resolution",
            "32",
        ])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        file_names(&dir.path().join("frames")),
        ["frame_00000.png", "frame_00001.png"]
    );
    assert!(stderr(&o).contains("wrote 2 frame(s)"), "{}", stderr(&o));
}

/// Runs a bad command with `--out` pointing at a fresh folder: exit 2, the message, no folder.
fn refused(args: &[&str], message: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let mut all = args.to_vec();
    all.extend(["--out", out.to_str().unwrap(), "--quiet"]);
    let o = texflow(&all);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    assert!(
        stderr(&o).contains(message),
        "{args:?}: expected `{message}` in: {}",
        stderr(&o)
    );
    assert!(!out.exists(), "{args:?} created the output folder");
}

#[test]
fn bad_input_is_refused_with_exit_code_2() {
    refused(
        &["render", "smok"],
        "unknown scene `smok`: the built-in scenes are fire, fire-points, snow",
    );
    refused(&["render", "--particles", "0x5"], "empty");
    refused(&["render", "--particles", "abc"], "not a size");
    refused(&["render", "--resolution", "12x"], "not a size");
    refused(
        &["render", "--particles", "100000x4"],
        "GL_MAX_TEXTURE_SIZE",
    );
    refused(&["render", "--frames", "0"], "0 is not allowed");
    refused(
        &["render", "--frames", "-1"],
        "--frames <N>': -1 is not allowed",
    );
    refused(
        &["render", "--every", "0"],
        "--every <K>': 0 is not allowed",
    );
    refused(&["render", "--dt", "-0.01"], "time step");
    refused(&["render", "--dt", "nan"], "time step");
    refused(
        &["render", "--dt", "-inf"],
        "--dt <SECONDS>': -inf is not allowed",
    );
    refused(&["render", "--substeps", "0"], "substeps");
    refused(
        &["render", "--device", "99"],
        "EGL device 99 does not exist",
    );
    refused(&["render", "--no-such-option"], "unexpected argument");
}

#[test]
fn unwritable_output_paths_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("file");
    std::fs::write(&file, b"x").unwrap();
    for (out, message) in [
        (file.clone(), "exists and is not a folder"),
        (file.join("sub"), "is a file"),
        // Nobody, root included, can create files in /proc.
        (
            Path::new("/proc/texflow-frames").to_path_buf(),
            "cannot be written",
        ),
    ] {
        let o = texflow(&[
            "render",
            "--frames",
            "1",
            "--quiet",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains(message), "{}", stderr(&o));
    }
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}

#[test]
fn info_lists_the_devices_and_their_limits() {
    let o = texflow(&["info"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = String::from_utf8_lossy(&o.stdout);
    for field in [
        "device 0",
        "renderer",
        "max texture size",
        "max draw buffers",
        "vertex texture units",
        "RGBA32F colour buffer",
    ] {
        assert!(text.contains(field), "missing {field} in:\n{text}");
    }
    let o = texflow(&["info", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    envelope(&v, "texflow.info/1");
    let d = &v["devices"][0];
    assert!(d["limits"]["max_texture_size"].as_u64().unwrap() >= 1024);
    // The same vendor in text and JSON.
    let vendor = d["vendor"].as_str().unwrap();
    assert!(
        text.contains(&format!("({vendor}")),
        "{vendor} not in:\n{text}"
    );
}

#[test]
fn no_egl_device_says_what_to_install() {
    // glvnd with no vendor library behaves like a machine without an EGL driver.
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args(["info"])
        .env(
            "__EGL_VENDOR_LIBRARY_FILENAMES",
            "/nonexistent/egl_vendor.json",
        )
        .env_remove("__EGL_VENDOR_LIBRARY_DIRS")
        .output()
        .unwrap();
    assert_ne!(o.status.code(), Some(0));
    assert!(
        stderr(&o).contains("apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn bench_step_prints_json_records() {
    let o = texflow(&[
        "bench",
        "step",
        "fire",
        "--sizes",
        "16,24",
        "--repeats",
        "3",
        "--resolution",
        "32",
        "--json",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    envelope(&v, "texflow.bench.step/1");
    let records = v["records"].as_array().unwrap();
    assert_eq!(records.len(), 2);
    for (r, size) in records.iter().zip([16u64, 24]) {
        assert_eq!(r["size"].as_u64(), Some(size));
        assert_eq!(r["particles"].as_u64(), Some(size * size));
        for f in ["sim_ms", "sim_floor_ms", "render_ms", "render_floor_ms"] {
            assert!(r[f].as_f64().unwrap() >= 0.0, "{f}");
        }
    }
}

/// Every command's JSON is an object naming the version, the schema and the device.
fn envelope(v: &serde_json::Value, schema: &str) {
    assert_eq!(v["texflow_version"], env!("CARGO_PKG_VERSION"), "{v}");
    assert_eq!(v["schema"], schema, "{v}");
    assert!(v["device"]["renderer"].as_str().is_some(), "{v}");
    assert!(v["device"]["driver"].as_str().is_some(), "{v}");
    assert_eq!(v["device"]["clocks"], "unknown", "{v}");
}

#[test]
fn bench_step_keeps_the_old_scene_flag() {
    let o = texflow(&[
        "bench",
        "step",
        "--scene",
        "fire",
        "--sizes",
        "8",
        "--repeats",
        "1",
        "--resolution",
        "16",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("| 8 | 64 |"));
}

#[test]
fn bench_scene_times_every_phase_of_a_scene_file_against_its_floor() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("smoke.toml");
    let text = texflow(&["scene", "list", "smoke-unlit"]);
    assert!(text.status.success(), "{}", stderr(&text));
    std::fs::write(&file, &text.stdout).unwrap();
    let o = texflow(&[
        "bench",
        "scene",
        file.to_str().unwrap(),
        "--sizes",
        "16",
        "--repeats",
        "2",
        "--warmup",
        "2",
        "--resolution",
        "32x32",
        "--json",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
    envelope(&v, "texflow.bench.scene/1");
    let r = &v["records"][0];
    assert_eq!(r["size"], 16);
    assert_eq!(r["resolution"], serde_json::json!([32, 32]));
    let phases: Vec<&str> = r["phases"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["phase"].as_str().unwrap())
        .collect();
    // smoke is alpha-blended: its plan sorts before drawing.
    for want in ["sort keys", "sort network", "gather", "render"] {
        assert!(
            phases.iter().any(|p| p.starts_with(want)),
            "{want} in {phases:?}"
        );
    }
    let o = texflow(&["bench", "scene", "no-such-scene", "--sizes", "16"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

#[test]
fn dropped_births_are_predicted_warned_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("full.toml");
    // Fountain at 32x32: 12,000 births/s × 3 s of life want 36,000 slots of 1,024.
    let src = texflow::scene::builtin_source("fountain")
        .unwrap()
        .replace("size = [256, 256]", "size = [32, 32]");
    assert!(src.contains("size = [32, 32]"), "the fountain's size line");
    std::fs::write(&scene, src).unwrap();
    let check = texflow(&["scene", "check", scene.to_str().unwrap()]);
    assert!(check.status.success(), "{}", stderr(&check));
    let text = String::from_utf8_lossy(&check.stdout);
    assert!(text.contains("births per second will be dropped"), "{text}");
    let out = dir.path().join("out");
    let o = texflow(&[
        "render",
        scene.to_str().unwrap(),
        "--frames",
        "30",
        "--every",
        "29",
        "--resolution",
        "32",
        "--json",
        "--stats",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let err = stderr(&o);
    assert_eq!(
        err.matches("warning: frame").count(),
        1,
        "warned once: {err}"
    );
    assert!(err.contains("is full"), "{err}");
    // With --json, stdout is the JSON document alone; the --stats paragraph is on stderr.
    let stdout = String::from_utf8_lossy(&o.stdout);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["schema"], "texflow.render/1");
    let dropped = v["records"]["dropped_births"].as_u64().unwrap();
    assert!(dropped > 0, "{v}");
    assert!(err.contains(&format!("{dropped} births dropped")), "{err}");
    assert_eq!(v["records"]["frames"], 30);
    assert_eq!(v["records"]["written"], 2);
    // --stats: the paragraph with each phase's median.
    let para = &err;
    for part in [
        "median simulate",
        "sort",
        "draw and read back",
        "fps",
        "M particles/s",
    ] {
        assert!(para.contains(part), "{para}");
    }
    // A state that fits drops nothing and says nothing.
    let o = texflow(&[
        "render",
        "fountain",
        "--frames",
        "3",
        "--resolution",
        "32",
        "--json",
        "--quiet",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["records"]["dropped_births"], 0);
}

#[test]
fn help_names_every_built_in_scene_and_the_scenes_defaults() {
    for cmd in ["render", "view"] {
        let o = texflow(&[cmd, "--help"]);
        assert!(o.status.success());
        let help = String::from_utf8_lossy(&o.stdout).replace("\n", " ");
        for name in texflow::scene::BUILTIN {
            assert!(
                help.contains(name),
                "`{cmd} --help` leaves out the scene {name}"
            );
        }
        if cmd == "render" {
            assert!(help.contains("<WxH>"), "{help}");
            assert!(help.contains("[default: the scene's time.dt]"), "{help}");
        }
    }
}
