//! Bad input on the output side, through the built binary: nothing an input names is replaced,
//! no input or encoder hangs a run, a refused run creates nothing, and the messages name the
//! option or the file (docs/reliability.md). Custom GLSL and messages are in
//! `tests/bad_input_glsl.rs`, benchmarks and `--json` in `tests/bad_input_bench_json.rs`.

mod common;

use common::bad_input::{
    custom, fake_ffmpeg, finish, mkfifo, run, run_in, scene_file, scene_text, LIFT,
};
use common::cli::{command, file_names, s, stderr};

use std::fs;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

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
}

/// A run killed by SIGKILL leaves its temporary video; the next run writing that video removes
/// it.
#[test]
fn a_temporary_video_left_by_sigkill_is_removed_by_the_next_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
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
