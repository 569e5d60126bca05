//! Bad input on the newer surfaces (`--video`, custom GLSL, OBJ meshes, `bench scene`, `--json`),
//! through the built binary: nothing an input names is replaced, no input or encoder hangs a
//! run, a refused run creates nothing, `scene check` refuses what `render` refuses, and the
//! messages name the option or the file, line and column (docs/reliability.md).

mod common;

use common::cli::{command, file_names, s, stderr};

use std::fs;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Runs texflow in `dir` (None: the test's folder) with `path` prefixed to PATH when given, and
/// fails the test instead of hanging if it has not ended after a minute.
fn run_in(dir: Option<&Path>, path: Option<&Path>, args: &[&str]) -> Output {
    let mut c = command();
    c.args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    if let Some(d) = dir {
        c.current_dir(d);
    }
    if let Some(p) = path {
        let old = std::env::var("PATH").unwrap_or_default();
        c.env("PATH", format!("{}:{old}", p.display()));
    }
    let child = c.spawn().expect("run texflow");
    // A hang guard, not a timing: the quick report runs take a minute or more on a busy
    // 2-core machine.
    finish(child, Duration::from_secs(600), args)
}

fn run(args: &[&str]) -> Output {
    run_in(None, None, args)
}

fn finish(mut child: Child, limit: Duration, args: &[&str]) -> Output {
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let o = child.wait_with_output().unwrap();
            panic!(
                "texflow {args:?} hung (killed after {limit:?}): {}",
                String::from_utf8_lossy(&o.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn mkfifo(p: &Path) {
    assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
}

/// A force of (0, 1, 0) N.
const LIFT: &str = "vec3 force(vec3 x, vec3 v, float age, int type) {\n    \
                    return vec3(0.0, 1.0, 0.0);\n}\n";

/// A tiny particle scene (16×16 state, 16×16 frame): particles at rest at the origin, no
/// gravity, then `extra` (custom forces, say).
fn scene_text(extra: &str) -> String {
    format!(
        "name = \"tiny\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
         dt = 0.02\n[[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
         speed = [0.0, 0.0]\nmass = 1.0\n{extra}[render]\nresolution = [16, 16]\n"
    )
}

/// Writes `scene.toml` with `extra` into `dir`, and returns its path.
fn scene_file(dir: &Path, extra: &str) -> PathBuf {
    let p = dir.join("scene.toml");
    fs::write(&p, scene_text(extra)).unwrap();
    p
}

fn custom(glsl: &str) -> String {
    format!("[[forces.custom]]\nglsl = \"{glsl}\"\n")
}

/// An executable `ffmpeg` in a new folder under `dir`, running `body` (sh).
fn fake_ffmpeg(dir: &Path, body: &str) -> PathBuf {
    let bin = dir.join("fakebin");
    fs::create_dir_all(&bin).unwrap();
    let p = bin.join("ffmpeg");
    fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
    fs::set_permissions(&p, fs::Permissions::from_mode(0o755)).unwrap();
    bin
}

// ---------------------------------------------------------------------------------------------
// Outputs against inputs, outputs and frame targets, before the GPU starts
// ---------------------------------------------------------------------------------------------

/// A `--video` that is an input of the run (a custom force's GLSL, a mesh, the scene file) is
/// refused and the input kept; so is a frame folder that would replace an input.
#[test]
fn an_output_that_is_an_input_is_refused_and_the_input_kept() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A GLSL file named like an animation.
    fs::write(d.join("force.png"), LIFT).unwrap();
    let sc = scene_file(d, &custom("force.png"));
    let out = d.join("frames");
    for video in [d.join("force.png"), d.join(".").join("force.png")] {
        let o = run(&[
            "render",
            s(&sc),
            "--frames",
            "1",
            "--video",
            s(&video),
            "--out",
            s(&out),
            "--quiet",
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains("--video") && stderr(&o).contains("GLSL"),
            "{}",
            stderr(&o)
        );
        assert_eq!(
            fs::read_to_string(d.join("force.png")).unwrap(),
            LIFT,
            "the input is kept"
        );
        assert!(!out.exists(), "a refused run creates no folder");
    }
    // A scene file named like an animation (a path, so it is read as a file).
    let gif = d.join("scene.gif");
    fs::write(&gif, scene_text("")).unwrap();
    let o = run(&["render", s(&gif), "--frames", "1", "--video", s(&gif)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("scene file"), "{}", stderr(&o));
    assert_eq!(fs::read_to_string(&gif).unwrap(), scene_text(""));
    // A mesh named like an animation.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
    fs::write(d.join("mesh.gif"), obj).unwrap();
    let sdf = "[[colliders.sdf]]\nmesh = \"mesh.gif\"\nresolution = 8\n\
               bounds = [[-1.0, -1.0, -1.0], [2.0, 2.0, 2.0]]\n";
    let sc2 = d.join("mesh_scene.toml");
    fs::write(&sc2, scene_text(sdf)).unwrap();
    let o = run(&[
        "render",
        s(&sc2),
        "--frames",
        "1",
        "--video",
        s(&d.join("mesh.gif")),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("mesh"), "{}", stderr(&o));
    assert_eq!(fs::read_to_string(d.join("mesh.gif")).unwrap(), obj);
    // A frame the run would write that is an input: frames/frame_00000.png is the GLSL.
    fs::create_dir_all(&out).unwrap();
    fs::write(out.join("frame_00000.png"), LIFT).unwrap();
    let sc3 = d.join("in_frames.toml");
    fs::write(&sc3, scene_text(&custom("frames/frame_00000.png"))).unwrap();
    let o = run(&["render", s(&sc3), "--frames", "1", "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--out"), "{}", stderr(&o));
    assert_eq!(
        fs::read_to_string(out.join("frame_00000.png")).unwrap(),
        LIFT
    );
}

/// `--video` equal to `--out` or `--dump-state` (a new path, with or without a trailing `/`),
/// and an APNG of more than 2^32 frames, are refused before anything is created.
#[test]
fn clashing_video_and_folders_are_refused_before_anything_is_created() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    let new = d.join("new.gif");
    let slash = format!("{}/", s(&new));
    for args in [
        vec!["--video", s(&new), "--out", s(&new)],
        vec!["--video", s(&new), "--out", &slash],
        vec!["--video", s(&new), "--dump-state", &slash],
    ] {
        let mut all = vec!["render", s(&sc), "--frames", "1", "--quiet"];
        all.extend(&args);
        let o = run(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("--video"), "{}", stderr(&o));
        assert_eq!(file_names(d), ["scene.toml"], "{args:?}: nothing created");
    }
    let out = d.join("out");
    let o = run(&[
        "render",
        s(&sc),
        "--frames",
        "5000000000",
        "--video",
        s(&d.join("a.png")),
        "--out",
        s(&out),
        "--dump-state",
        s(&d.join("dumps")),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("APNG"), "{}", stderr(&o));
    assert_eq!(file_names(d), ["scene.toml"], "nothing created");
}

/// A fifo, folder, device or socket at the name of a later frame or dump is refused before the
/// first frame is written.
#[test]
fn a_later_frame_target_in_the_way_is_refused_before_the_first_frame() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    let out = d.join("out");
    fs::create_dir(&out).unwrap();
    let fifo = out.join("frame_00002.png");
    mkfifo(&fifo);
    let o = run(&[
        "render",
        s(&sc),
        "--frames",
        "3",
        "--out",
        s(&out),
        "--quiet",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("frame_00002.png"), "{}", stderr(&o));
    assert_eq!(
        file_names(&out),
        ["frame_00002.png"],
        "frame 0 was not written"
    );
    // Not written with --every 2 at 3 frames? It is (frames 0 and 2); at --every 3 it is not.
    let o = run(&[
        "render",
        s(&sc),
        "--frames",
        "3",
        "--every",
        "3",
        "--out",
        s(&out),
        "--quiet",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    fs::remove_file(&fifo).unwrap();
    fs::remove_file(out.join("frame_00000.png")).unwrap();
    // A folder at a dump's name.
    let dumps = d.join("dumps");
    fs::create_dir_all(dumps.join("velocities_00001.npy")).unwrap();
    let o = run(&[
        "render",
        s(&sc),
        "--frames",
        "2",
        "--out",
        s(&out),
        "--dump-state",
        s(&dumps),
        "--quiet",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--dump-state"), "{}", stderr(&o));
    assert!(file_names(&out).is_empty(), "{:?}", file_names(&out));
    assert_eq!(file_names(&dumps), ["velocities_00001.npy"]);
}

/// A killed run's temporary files (`.NAME.XXXXXXXX.tmp` of the names texflow writes there) are
/// removed by the next run into that folder; other files are kept.
#[test]
fn stale_temporary_files_of_a_killed_run_are_removed_by_the_next_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    let out = d.join("out");
    fs::create_dir(&out).unwrap();
    let stale = [
        ".frame_00007.png.Ab3dE9gH.tmp",
        ".positions_00001.npy.x1Y2z3W4.tmp",
        ".frame_00000.png.Qw12Er.tmp",
    ];
    let kept = [
        ".notes.txt.Ab3dE9gH.tmp",
        ".frame_00007.png.Ab3dE9g.tmp",
        "frame_00007.png.Ab3dE9gH.tmp",
        ".frame_00007.png.Ab3dE9gH.bak",
    ];
    for n in stale.iter().chain(&kept) {
        fs::write(out.join(n), b"half a file").unwrap();
    }
    fs::write(d.join(".anim.gif.ZZZZ1111.tmp"), b"half").unwrap();
    fs::write(d.join(".other.gif.ZZZZ1111.tmp"), b"half").unwrap();
    let o = run(&[
        "render",
        s(&sc),
        "--frames",
        "1",
        "--out",
        s(&out),
        "--video",
        s(&d.join("anim.gif")),
        "--quiet",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let mut want: Vec<String> = kept.iter().map(|s| s.to_string()).collect();
    want.push("frame_00000.png".into());
    want.sort();
    assert_eq!(file_names(&out), want);
    assert!(!d.join(".anim.gif.ZZZZ1111.tmp").exists());
    assert!(d.join(".other.gif.ZZZZ1111.tmp").exists());
    // A real SIGKILL: an encoder that never reads holds the run with its temporary video open.
    let bin_dir = fake_ffmpeg(d, "exec sleep 10");
    let mut c = command();
    c.args(["render", s(&sc), "--frames", "2", "--resolution", "128"])
        .args(["--video", s(&d.join("k.mp4")), "--quiet"]);
    c.env(
        "PATH",
        format!("{}:{}", bin_dir.display(), std::env::var("PATH").unwrap()),
    );
    let mut child = c
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let temp = || file_names(d).into_iter().find(|n| n.starts_with(".k.mp4."));
    let start = Instant::now();
    while temp().is_none() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(20));
    }
    let t = temp().expect("the run's temporary video");
    assert_eq!(t.len(), ".k.mp4.".len() + 8 + ".tmp".len(), "{t}");
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(d.join(&t).exists(), "SIGKILL leaves it");
    // The next run into that folder, writing k.mp4 again, removes it (and fails on the fake
    // encoder, which writes nothing: no k.mp4 either).
    let bin_dir = fake_ffmpeg(d, "cat > /dev/null");
    let o = run_in(
        None,
        Some(&bin_dir),
        &[
            "render",
            s(&sc),
            "--frames",
            "1",
            "--video",
            s(&d.join("k.mp4")),
        ],
    );
    assert_ne!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(!d.join(&t).exists());
    assert!(!d.join("k.mp4").exists());
}

// ---------------------------------------------------------------------------------------------
// Encoders: killed on the first signal; a video only if one was written
// ---------------------------------------------------------------------------------------------

/// Starts a render of a video through the fake encoder `body`, waits for `ready` (a file the
/// fake writes) and sends `signal` once: the run ends with 128 + signal, no video, nothing
/// unfinished.
fn one_signal_ends_a_stuck_encoder(body: &str, signal: &str, code: i32) {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    let ready = d.join("ready");
    let bin_dir = fake_ffmpeg(d, &body.replace("READY", s(&ready)));
    let video = d.join("v.mp4");
    let mut c = command();
    // 256×256 RGB frames are 192 KiB: more than a pipe holds, so an encoder that does not read
    // blocks the first frame's write.
    c.args(["render", s(&sc), "--frames", "3", "--resolution", "256"])
        .args(["--video", s(&video), "--out", s(&d.join("f")), "--quiet"])
        .env(
            "PATH",
            format!("{}:{}", bin_dir.display(), std::env::var("PATH").unwrap()),
        )
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    let child = c.spawn().unwrap();
    let start = Instant::now();
    while !ready.exists() && start.elapsed() < Duration::from_secs(30) {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(ready.exists(), "the fake encoder started");
    // Let the run reach the write that the encoder blocks (the wait at the end is reached
    // already when the fake has read everything).
    std::thread::sleep(Duration::from_millis(1000));
    assert!(Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    let o = finish(child, Duration::from_secs(20), &[signal]);
    assert_eq!(
        o.status.code(),
        Some(code),
        "{body} {signal}: {}",
        stderr(&o)
    );
    assert!(!video.exists());
    let left: Vec<String> = file_names(d)
        .into_iter()
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
    for n in file_names(&d.join("f")) {
        assert!(!n.ends_with(".tmp"), "{n}");
    }
}

#[test]
fn one_signal_ends_a_render_whose_encoder_stopped_reading() {
    one_signal_ends_a_stuck_encoder(": > READY\nexec sleep 60", "-INT", 130);
    one_signal_ends_a_stuck_encoder(": > READY\nexec sleep 60", "-TERM", 143);
}

#[test]
fn one_signal_ends_a_render_whose_encoder_never_exits() {
    // Reads every frame, then never exits: the run waits for it at the end.
    one_signal_ends_a_stuck_encoder("cat > /dev/null\n: > READY\nexec sleep 60", "-HUP", 129);
}

/// An encoder that exits 0 without writing, or writes something that is not the container,
/// gives no video and no success.
#[test]
fn an_encoder_that_writes_nothing_gives_no_video() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    for (body, ext) in [
        ("cat > /dev/null\nexit 0", "mp4"),
        (
            "cat > /dev/null\nfor a; do last=$a; done\necho hello > \"$last\"",
            "mp4",
        ),
        (
            "cat > /dev/null\nfor a; do last=$a; done\necho hello > \"$last\"",
            "webm",
        ),
    ] {
        let bin_dir = fake_ffmpeg(d, body);
        let video = d.join(format!("v.{ext}"));
        let o = run_in(
            None,
            Some(&bin_dir),
            &["render", s(&sc), "--frames", "2", "--video", s(&video)],
        );
        assert_eq!(o.status.code(), Some(1), "{body}: {}", stderr(&o));
        assert!(stderr(&o).contains("encoder wrote"), "{}", stderr(&o));
        assert!(!video.exists(), "{body}");
        assert!(
            !file_names(d).iter().any(|n| n.ends_with(".tmp")),
            "{:?}",
            file_names(d)
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Inputs: regular files only, bounded
// ---------------------------------------------------------------------------------------------

/// A fifo or a device as the scene file, the GLSL or the mesh is refused at once by `scene
/// check`, `render` and `bench scene`, with its name and the reason.
#[test]
fn inputs_that_are_not_regular_files_are_refused_before_reading() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let fifo_scene = d.join("fifo.toml");
    mkfifo(&fifo_scene);
    mkfifo(&d.join("force.glsl"));
    mkfifo(&d.join("mesh.obj"));
    let glsl_scene = scene_file(d, &custom("force.glsl"));
    let mesh_scene = d.join("mesh.toml");
    let sdf = "[[colliders.sdf]]\nmesh = \"mesh.obj\"\nresolution = 8\n\
               bounds = [[-1.0, -1.0, -1.0], [2.0, 2.0, 2.0]]\n";
    fs::write(&mesh_scene, scene_text(sdf)).unwrap();
    let dev_glsl = d.join("dev.toml");
    fs::write(&dev_glsl, scene_text(&custom("/dev/zero"))).unwrap();
    for (scene, named, why) in [
        (fifo_scene.as_path(), "fifo.toml", "fifo"),
        (Path::new("/dev/zero"), "/dev/zero", "device"),
        (glsl_scene.as_path(), "force.glsl", "fifo"),
        (mesh_scene.as_path(), "mesh.obj", "fifo"),
        (dev_glsl.as_path(), "/dev/zero", "device"),
    ] {
        for cmd in [
            vec!["scene", "check", s(scene)],
            vec![
                "render",
                s(scene),
                "--frames",
                "1",
                "--out",
                s(&d.join("o")),
            ],
            vec![
                "bench",
                "scene",
                s(scene),
                "--sizes",
                "16",
                "--repeats",
                "1",
            ],
        ] {
            let o = run(&cmd);
            assert_eq!(o.status.code(), Some(2), "{cmd:?}: {}", stderr(&o));
            assert!(
                stderr(&o).contains(named) && stderr(&o).contains(why),
                "{cmd:?}: {}",
                stderr(&o)
            );
        }
    }
    assert!(!d.join("o").exists());
    // Too large: a scene file over 1 MiB.
    let big = d.join("big.toml");
    fs::write(
        &big,
        format!("{}#{}\n", scene_text(""), "x".repeat(1 << 20)),
    )
    .unwrap();
    let o = run(&["scene", "check", s(&big)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("over the limit"), "{}", stderr(&o));
}

// ---------------------------------------------------------------------------------------------
// Custom GLSL: one validation, the user's file and line, found by its own path
// ---------------------------------------------------------------------------------------------

/// Every custom force that `render` refuses, `scene check` refuses first (exit 2), naming the
/// user's file; none is blamed on texflow's own files.
#[test]
fn scene_check_refuses_the_custom_glsl_render_refuses() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::create_dir(d.join("folder.glsl")).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("syntax.glsl", b"vec3 force(vec3 x, vec3 v, float age, int type) {\n  return x +;\n}\n".to_vec(), "syntax.glsl:2"),
        ("version.glsl", [b"#version 450\n".as_slice(), LIFT.as_bytes()].concat(), "version.glsl:1"),
        ("error.glsl", [LIFT.as_bytes(), b"#error stop here\n".as_slice()].concat(), "error.glsl:4"),
        ("include.glsl", [b"#include \"x.glsl\"\n".as_slice(), LIFT.as_bytes()].concat(), "include.glsl:1"),
        ("line.glsl", [b"#line 9999\n".as_slice(), LIFT.as_bytes(), b"oops\n"].concat(), "line.glsl:1"),
        ("compute.glsl", [b"#extension GL_ARB_shader_storage_buffer_object : require\n".as_slice(), LIFT.as_bytes()].concat(), "compute.glsl:1"),
        ("utf8.glsl", [LIFT.as_bytes(), b"// \xff\n".as_slice()].concat(), "utf8.glsl:4:4"),
        ("nul.glsl", [LIFT.as_bytes(), b"\0\n".as_slice()].concat(), "nul.glsl:4:1"),
        ("endless.glsl", b"vec3 force(vec3 x, vec3 v, float age, int type) {\n  while (true) {}\n  return x;\n}\n".to_vec(), "endless.glsl:2"),
        ("missing.glsl", Vec::new(), "missing.glsl"),
        ("folder.glsl", Vec::new(), "folder.glsl"),
    ];
    for (name, text, want) in &cases {
        if !text.is_empty() {
            fs::write(d.join(name), text).unwrap();
        }
        let sc = d.join(format!("{name}.toml"));
        fs::write(&sc, scene_text(&custom(name))).unwrap();
        let check = run(&["scene", "check", s(&sc)]);
        let render = run(&["render", s(&sc), "--frames", "1", "--out", s(&d.join("o"))]);
        for (what, o) in [("check", &check), ("render", &render)] {
            assert_eq!(o.status.code(), Some(2), "{what} {name}: {}", stderr(o));
            assert!(
                stderr(o).contains(want),
                "{what} {name}: want {want}: {}",
                stderr(o)
            );
            assert!(
                !stderr(o).contains("glsl/sim"),
                "{what} {name}: {}",
                stderr(o)
            );
        }
    }
    assert!(!d.join("o").exists());
}

/// A user file whose path is a built-in include's (`common/rng.glsl`), and one file named by two
/// `[[forces.custom]]`: both valid, and the file named twice acts twice (twice the velocity of
/// the file named once, from rest under no other force).
#[test]
fn user_glsl_is_found_by_its_own_path_and_may_be_used_twice() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::create_dir(d.join("common")).unwrap();
    fs::write(d.join("common/rng.glsl"), LIFT).unwrap();
    let once = d.join("once.toml");
    fs::write(&once, scene_text(&custom("common/rng.glsl"))).unwrap();
    let twice = d.join("twice.toml");
    fs::write(
        &twice,
        scene_text(&(custom("common/rng.glsl") + &custom("common/rng.glsl"))),
    )
    .unwrap();
    let mut v = Vec::new();
    for sc in ["once.toml", "twice.toml"] {
        // Run from the scene's folder, so that the path is exactly `common/rng.glsl`.
        let o = run_in(Some(d), None, &["scene", "check", sc]);
        assert_eq!(o.status.code(), Some(0), "{sc}: {}", stderr(&o));
        let dumps = format!("dumps_{sc}");
        let o = run_in(
            Some(d),
            None,
            &[
                "render",
                sc,
                "--frames",
                "2",
                "--dump-state",
                &dumps,
                "--video",
                "a.gif",
            ],
        );
        assert_eq!(o.status.code(), Some(0), "{sc}: {}", stderr(&o));
        let vel = texflow::npy::read_f32_shaped(&d.join(&dumps).join("velocities_00001.npy"));
        v.push(vel.unwrap().1);
    }
    assert!(!v[0].is_empty());
    for (a, b) in v[0].chunks(4).zip(v[1].chunks(4)) {
        assert!(a[1] > 0.0, "the force acts: {a:?}");
        assert!(
            (b[1] - 2.0 * a[1]).abs() <= 1e-5 * a[1],
            "twice {b:?}, once {a:?}"
        );
    }
}

/// The user's GLSL errors are bad input (exit 2) at the user's file and line, and a byte-order
/// mark is no error.
#[test]
fn user_glsl_errors_name_the_users_file_and_a_bom_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(
        d.join("bom.glsl"),
        [b"\xEF\xBB\xBF".as_slice(), LIFT.as_bytes()].concat(),
    )
    .unwrap();
    let sc = d.join("bom.toml");
    fs::write(&sc, scene_text(&custom("bom.glsl"))).unwrap();
    let o = run(&["scene", "check", s(&sc)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    fs::write(
        d.join("undefined.glsl"),
        "\n\nvec3 force(vec3 x, vec3 v, float age, int type) {\n  return nothing_here;\n}\n",
    )
    .unwrap();
    let sc = d.join("undefined.toml");
    fs::write(&sc, scene_text(&custom("undefined.glsl"))).unwrap();
    let o = run(&["render", s(&sc), "--frames", "1", "--out", s(&d.join("o"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("undefined.glsl:4"), "{}", stderr(&o));
    assert!(
        !stderr(&o).contains("custom-force-"),
        "no internal names: {}",
        stderr(&o)
    );
    // An include of a file that is not texflow's, and a `#line` that would move the error into
    // texflow's files: bad input at the user's file and line, not "the machine failed".
    for (name, text, want) in [
        (
            "inc.glsl",
            format!("#include \"x.glsl\"\n{LIFT}"),
            "inc.glsl:1",
        ),
        (
            "line.glsl",
            format!("{LIFT}#line 9999\nnot glsl\n"),
            "line.glsl:4",
        ),
    ] {
        fs::write(d.join(name), text).unwrap();
        let sc = d.join(format!("{name}.toml"));
        fs::write(&sc, scene_text(&custom(name))).unwrap();
        let o = run(&["render", s(&sc), "--frames", "1", "--out", s(&d.join("o"))]);
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{name}: {}", stderr(&o));
        assert!(!stderr(&o).contains("glsl/"), "{name}: {}", stderr(&o));
    }
}

// ---------------------------------------------------------------------------------------------
// Messages name the option typed; point sizes in scene check
// ---------------------------------------------------------------------------------------------

#[test]
fn messages_name_the_option_typed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    let file = d.join("file");
    fs::write(&file, b"").unwrap();
    let sub = file.join("sub");
    for (args, flag) in [
        (
            vec!["render", s(&sc), "--particles", "99999"],
            "--particles",
        ),
        (
            vec!["render", s(&sc), "--resolution", "99999"],
            "--resolution",
        ),
        (vec!["collide-stats", "--iterations", "17"], "--iterations"),
        (vec!["collide-stats", "--k", "99"], "--k"),
        (vec!["render", s(&sc), "--out", s(&sub)], "--out"),
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(flag), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("particles.size"), "{}", stderr(&o));
        assert!(!stderr(&o).contains("render.resolution"), "{}", stderr(&o));
        assert!(!stderr(&o).contains("collisions."), "{}", stderr(&o));
    }
    // Without a display, `view` refuses a size over the limit for the size.
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args(["view", s(&sc), "--resolution", "99999"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--resolution"), "{}", stderr(&o));
    assert!(!stderr(&o).contains("display"), "{}", stderr(&o));
}

/// Sprites wider than the device's largest point: `scene check` refuses them at the key.
#[test]
fn scene_check_refuses_points_wider_than_the_device_draws() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let wide = |render: &str, emitter: &str| {
        format!(
            "name = \"wide\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
             dt = 0.02\n[[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
             speed = [0.0, 0.0]\n{emitter}\n[render]\nresolution = [16, 16]\nmode = \"sprites\"\n\
             {render}\n"
        )
    };
    for (text, at) in [
        (wide("point_size = 100000.0", ""), ":15:14:"),
        (
            wide("point_size = 200.0", "sprite_scale = 1000.0"),
            ":11:16:",
        ),
    ] {
        let sc = d.join("wide.toml");
        fs::write(&sc, &text).unwrap();
        let o = run(&["scene", "check", s(&sc)]);
        assert_eq!(o.status.code(), Some(2), "{text}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("wide.toml{at}")) && stderr(&o).contains("largest point"),
            "{text}: {}",
            stderr(&o)
        );
        let o = run(&["render", s(&sc), "--frames", "1", "--out", s(&d.join("o"))]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("wide.toml{at}")),
            "{}",
            stderr(&o)
        );
    }
}

// ---------------------------------------------------------------------------------------------
// Benchmarks
// ---------------------------------------------------------------------------------------------

/// The default warm-up is bounded (a long cycle, a tiny time step), and never wraps to zero.
#[test]
fn bench_warmup_is_bounded() {
    use texflow::bench::scene::{warmup_frames, MAX_WARMUP_FRAMES};
    let base = scene_text("");
    let parse = |t: &str| texflow::scene::parse("w", t).unwrap();
    let s = parse(&base);
    // dt 0.02 (a little less in f32), no cycle: one second of frames, and one more.
    assert_eq!(warmup_frames(&s, None).unwrap(), 52);
    assert_eq!(warmup_frames(&s, Some(7)).unwrap(), 7);
    assert!(warmup_frames(&s, Some(MAX_WARMUP_FRAMES + 1)).is_err());
    let mut long = s.clone();
    long.time.dt = 1e-30;
    assert_eq!(warmup_frames(&long, None).unwrap(), MAX_WARMUP_FRAMES);
    let cycle = base.replace(
        "[[emitters.initial]]",
        "[[emitters.timestamp]]\ncycle = 1000000.0\nlife = [1.0, 1.0]\nrate = 1.0\n\
         [[emitters.initial]]",
    );
    if let Ok(c) = texflow::scene::parse("w", &cycle) {
        assert_eq!(warmup_frames(&c, None).unwrap(), MAX_WARMUP_FRAMES);
    }
    // Through the command: the default warm-up of a `dt = 1e-30` scene is the cap (it used to
    // overflow the frame count).
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("tiny_dt.toml");
    fs::write(&sc, base.replace("dt = 0.02", "dt = 1e-30")).unwrap();
    let o = run(&[
        "bench",
        "scene",
        sc.to_str().unwrap(),
        "--repeats",
        "1",
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["records"][0]["warmup_frames"], MAX_WARMUP_FRAMES, "{v}");
    assert_eq!(v["records"][0]["live"], 256, "{v}");
}

/// A benchmark of a state with no live particle is refused with the reason.
#[test]
fn a_bench_of_an_empty_state_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sc = dir.path().join("dead.toml");
    fs::write(
        &sc,
        scene_text("").replace("mass = 1.0\n", "mass = 1.0\nlife = [0.01, 0.01]\n"),
    )
    .unwrap();
    let o = run(&["bench", "scene", s(&sc), "--repeats", "1", "--warmup", "2"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("no live particle"), "{}", stderr(&o));
}

// ---------------------------------------------------------------------------------------------
// --json: stdout is one JSON document, for every command
// ---------------------------------------------------------------------------------------------

#[test]
fn json_output_is_one_document_for_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    let out = d.join("o");
    let runs: Vec<Vec<&str>> = vec![
        vec!["info", "--json"],
        vec![
            "render",
            s(&sc),
            "--frames",
            "2",
            "--out",
            s(&out),
            "--json",
        ],
        vec![
            "render",
            s(&sc),
            "--frames",
            "2",
            "--out",
            s(&out),
            "--json",
            "--stats",
        ],
        vec![
            "render",
            s(&sc),
            "--frames",
            "2",
            "--out",
            s(&out),
            "--json",
            "--stats",
            "--quiet",
        ],
        vec!["scene", "passes", s(&sc), "--json"],
        vec![
            "collide-stats",
            "--particles",
            "16",
            "--steps",
            "2",
            "--json",
        ],
        vec![
            "bench",
            "scene",
            s(&sc),
            "--repeats",
            "1",
            "--warmup",
            "1",
            "--json",
        ],
        vec![
            "bench",
            "step",
            "--sizes",
            "16",
            "--repeats",
            "1",
            "--resolution",
            "16",
            "--json",
        ],
        vec![
            "bench",
            "sort",
            "--sizes",
            "16",
            "--variants",
            "fp",
            "--repeats",
            "1",
            "--no-cpu",
            "--json",
        ],
        vec![
            "collide-stats",
            "--particles",
            "16",
            "--steps",
            "2",
            "--sweep",
            "--json",
        ],
        vec![
            "bench",
            "scenes",
            "--sizes",
            "16",
            "--repeats",
            "1",
            "--warmup",
            "1",
            "--resolution",
            "16",
            "--json",
        ],
        // The slow one (about 7 s on llvmpipe); `report convergence --quick --json`, a minute
        // or more, has a test of its own in tests/report.rs.
        vec!["report", "stability", "--json"],
    ];
    for args in &runs {
        let o = run(args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let text = String::from_utf8(o.stdout).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text)
            .unwrap_or_else(|e| panic!("{args:?}: stdout is not one JSON document ({e}): {text}"));
        assert!(v.is_object(), "{args:?}: {text}");
    }
}
