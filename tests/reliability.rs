//! The promises of docs/reliability.md, through the built binary: outputs that are refused when
//! they are not regular files or clash, written all together or not at all, never through a
//! planted link; SIGINT and SIGTERM that stop between frames and leave nothing unfinished; a
//! closed stdout that ends quietly; numbers refused by option name.

mod common;

use common::cli::{file_names, s, stderr, texflow};

use std::fs;
use std::io::Read;
use std::os::unix::fs::symlink;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn keys(dir: &Path) -> std::path::PathBuf {
    let p = dir.join("keys.npy");
    texflow::npy::write_f32(&p, &[3.0, 1.0, 2.0, -5.0, 0.5]).unwrap();
    p
}

#[test]
fn outputs_that_are_not_regular_files_are_refused_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let input = keys(dir.path());
    // A device node, a folder and a fifo: each refused with exit 2 before anything runs, and
    // left as it was (run as root, a rename over /dev/null would replace the device).
    let fifo = dir.path().join("fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for (flag, target) in [
        ("--output", Path::new("/dev/null")),
        ("--ids", Path::new("/dev/null")),
        ("--output", dir.path()),
        ("--output", fifo.as_path()),
    ] {
        let ok_out = dir.path().join("sorted.npy");
        let mut args = vec!["sort", "--input", s(&input), "--quiet"];
        if flag == "--ids" {
            args.extend(["--output", s(&ok_out), "--ids", s(target)]);
        } else {
            args.extend(["--output", s(target)]);
        }
        let o = texflow(&args);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{flag} {target:?}: {}",
            stderr(&o)
        );
        assert!(stderr(&o).contains(flag), "{}", stderr(&o));
        assert!(!ok_out.exists(), "no output is written when one is refused");
    }
    use std::os::unix::fs::FileTypeExt;
    assert!(fs::metadata("/dev/null")
        .unwrap()
        .file_type()
        .is_char_device());
    assert!(fs::metadata(&fifo).unwrap().file_type().is_fifo());
}

#[test]
fn clashing_paths_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let input = keys(dir.path());
    let before = fs::read(&input).unwrap();
    let out = dir.path().join("out.npy");
    // The same path twice, the input as an output, and the input under another name.
    let alias = dir.path().join("alias.npy");
    fs::hard_link(&input, &alias).unwrap();
    for (output, ids, what) in [
        (out.clone(), out.clone(), "another output"),
        (out.clone(), input.clone(), "the input"),
        (input.clone(), out.clone(), "the input"),
        (alias.clone(), out.clone(), "the input"),
        (
            dir.path().join(".").join("out.npy"),
            out.clone(),
            "another output",
        ),
    ] {
        let o = texflow(&[
            "sort",
            "--input",
            s(&input),
            "--output",
            s(&output),
            "--ids",
            s(&ids),
        ]);
        assert_eq!(
            o.status.code(),
            Some(2),
            "{output:?} {ids:?}: {}",
            stderr(&o)
        );
        assert!(stderr(&o).contains(what), "{}", stderr(&o));
    }
    assert_eq!(fs::read(&input).unwrap(), before, "the input is untouched");
    assert!(!out.exists());
}

#[test]
fn both_outputs_appear_together_and_no_temporary_file_is_left() {
    let dir = tempfile::tempdir().unwrap();
    let input = keys(dir.path());
    let (out, ids) = (dir.path().join("k.npy"), dir.path().join("i.npy"));
    let o = texflow(&[
        "sort",
        "--input",
        s(&input),
        "--output",
        s(&out),
        "--ids",
        s(&ids),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        texflow::npy::read_f32(&out).unwrap(),
        [-5.0, 0.5, 1.0, 2.0, 3.0]
    );
    assert_eq!(file_names(dir.path()), ["i.npy", "k.npy", "keys.npy"]);
    // An --ids folder that cannot be written is found before the sort: nothing is written.
    let locked = dir.path().join("locked");
    fs::create_dir(&locked).unwrap();
    let o = texflow(&[
        "sort",
        "--input",
        s(&input),
        "--output",
        s(&dir.path().join("k2.npy")),
        "--ids",
        s(&locked.join("missing/i.npy")),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!dir.path().join("k2.npy").exists());
}

#[test]
fn planted_links_are_replaced_not_followed() {
    let dir = tempfile::tempdir().unwrap();
    let victim = dir.path().join("victim.txt");
    fs::write(&victim, b"precious").unwrap();
    let out = dir.path().join("frames");
    fs::create_dir(&out).unwrap();
    // Every predictable name a careless writer might use, linked to the victim.
    for name in [
        "frame_00000.png",
        ".frame_00000.png.tmp",
        ".texflow-write-test-1",
    ] {
        symlink(&victim, out.join(name)).unwrap();
    }
    let o = texflow(&[
        "render",
        "fire",
        "--frames",
        "1",
        "--particles",
        "8",
        "--resolution",
        "16",
        "--out",
        s(&out),
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(fs::read(&victim).unwrap(), b"precious");
    // The frame replaced the link with a real file.
    let frame = out.join("frame_00000.png");
    assert!(!fs::symlink_metadata(&frame).unwrap().is_symlink());
    assert!(image::open(&frame).is_ok());
}

/// Starts a long render, waits for its first frame, sends `signal`, and returns its exit code
/// and the output folder's names.
fn interrupted_render(signal: &str) -> (Option<i32>, Vec<String>, String) {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    let mut child = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args([
            "render",
            "fire",
            "--frames",
            "100000",
            "--particles",
            "16",
            "--resolution",
            "32",
            "--quiet",
            "--out",
            s(&out),
        ])
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let t0 = Instant::now();
    while !out.join("frame_00002.png").exists() {
        assert!(
            t0.elapsed() < Duration::from_secs(120),
            "no frames appeared"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args([signal, &pid])
        .status()
        .unwrap()
        .success());
    let status = child.wait().unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    let n = file_names(&out);
    (status.code(), n, err)
}

#[test]
fn sigint_and_sigterm_stop_between_frames_and_leave_nothing_unfinished() {
    for (signal, code) in [("-INT", 130), ("-TERM", 143), ("-HUP", 129)] {
        let (status, files, err) = interrupted_render(signal);
        assert_eq!(status, Some(code), "{signal}: {err}");
        assert!(err.contains("interrupted"), "{err}");
        assert!(
            files.len() >= 3,
            "the frames written so far stay: {files:?}"
        );
        for f in &files {
            assert!(
                f.starts_with("frame_") && f.ends_with(".png"),
                "{signal} left {f} behind"
            );
        }
        // Every frame left is whole.
        let dir_frames = files.len();
        assert!(dir_frames > 0);
    }
}

#[test]
fn a_closed_stdout_ends_quietly() {
    // `texflow scene list | head -1`: the reader goes away after one line.
    let mut child = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args(["scene", "list", "snow"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let status = child.wait().unwrap();
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    assert!(!err.contains("panicked"), "{err}");
    assert_ne!(status.code(), Some(101), "a panic's exit code: {err}");
}

#[test]
fn numbers_out_of_range_are_refused_by_option() {
    for (args, message) in [
        (&["render", "--frames", "-1"][..], "--frames"),
        (&["render", "--dt", "-inf"][..], "--dt"),
        (&["render", "--dt", "1e39"][..], "--dt"),
        (&["render", "--substeps", "-2"][..], "--substeps"),
        (
            &["render", "--substeps", "1001"][..],
            "--substeps: substeps 1001 is more than 1000",
        ),
        (&["collide-stats", "--cell", "inf"][..], "--cell"),
        (&["collide-stats", "--cell", "nan"][..], "--cell"),
        (&["bench", "sort", "--repeats", "0"][..], "--repeats"),
        (
            &["scene", "check", "snow", "--device", "99"][..],
            "EGL device 99",
        ),
    ] {
        let o = texflow(args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(message), "{args:?}: {}", stderr(&o));
    }
}

#[test]
fn non_finite_state_stops_the_run_with_exit_3_unless_allowed() {
    let dir = tempfile::tempdir().unwrap();
    // Euler on a spring with ω·dt = 1000/60: the amplitude grows ~17× a step and overflows f32
    // within a few dozen steps (docs/numerics.md, the spring's stability limit ω·dt < 2).
    let scene = dir.path().join("unstable.toml");
    fs::write(
        &scene,
        r#"name = "unstable"
integrator = "euler"
[particles]
size = [4, 4]
[time]
dt = 0.016666668
[[emitters.initial]]
shape = "point"
center = [0.0, 0.0, 0.0]
direction = [1.0, 0.0, 0.0]
speed = [1.0, 1.0]
[[forces.spring]]
anchor = [0.0, 0.0, 0.0]
stiffness = 1000000.0
"#,
    )
    .unwrap();
    let out = dir.path().join("frames");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "render",
            s(&scene),
            "--frames",
            "60",
            "--resolution",
            "16",
            "--quiet",
            "--out",
            s(&out),
        ];
        args.extend(extra);
        texflow(&args)
    };
    let o = run(&[]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(stderr(&o).contains("NaN or infinite"), "{}", stderr(&o));
    assert!(stderr(&o).contains("--allow-non-finite"), "{}", stderr(&o));
    // The census names the emitter whose particles they are.
    assert!(
        stderr(&o).contains("all are particles of `emitters.initial.0`"),
        "{}",
        stderr(&o)
    );
    let written = file_names(&out).len();
    assert!(written < 60, "the run stopped at the first bad frame");
    // Non-finite state that shows only in the dumps (frame 0 alone is written) is an exit 3
    // too, and the dump that would hold it is not written.
    let dumps = dir.path().join("dumps");
    let o = run(&["--every", "1000", "--dump-state", s(&dumps)]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    for name in file_names(&dumps) {
        let (shape, v) = texflow::npy::read_f32_shaped(&dumps.join(&name)).unwrap();
        assert!(
            v.iter().all(|x| x.is_finite()),
            "{name} {shape:?} holds non-finite values"
        );
    }
    let o = run(&["--allow-non-finite"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("warning"), "{}", stderr(&o));
    assert_eq!(file_names(&out).len(), 60);
}

#[test]
fn a_video_that_would_replace_a_frame_and_inputs_that_never_end_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("frames");
    std::fs::create_dir(&out).unwrap();
    let link = dir.path().join("link");
    symlink(&out, &link).unwrap();
    for video in [out.join("frame_00000.png"), link.join("frame_00001.png")] {
        let o = texflow(&[
            "render",
            "--frames",
            "2",
            "--particles",
            "8",
            "--resolution",
            "8",
            "--quiet",
            "--out",
            s(&out),
            "--video",
            s(&video),
        ]);
        assert_eq!(o.status.code(), Some(2), "{video:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("will write"), "{}", stderr(&o));
    }
    assert!(file_names(&out).is_empty(), "nothing written");
    // A device or a fifo as --input would be read without end or block: refused at once.
    let fifo = dir.path().join("keys.fifo");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for input in [Path::new("/dev/zero"), fifo.as_path()] {
        let o = texflow(&[
            "sort",
            "--input",
            s(input),
            "--output",
            s(&dir.path().join("k.npy")),
        ]);
        assert_eq!(o.status.code(), Some(2), "{input:?}: {}", stderr(&o));
        assert!(stderr(&o).contains("not a regular file"), "{}", stderr(&o));
    }
    // A dangling link as --out, and a file as an output's folder, say what they are.
    let dangling = dir.path().join("dangling");
    symlink(dir.path().join("nowhere"), &dangling).unwrap();
    let o = texflow(&["render", "--frames", "1", "--quiet", "--out", s(&dangling)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("link to a missing path"),
        "{}",
        stderr(&o)
    );
    let file = dir.path().join("file");
    std::fs::write(&file, b"x").unwrap();
    let input = keys(dir.path());
    let o = texflow(&[
        "sort",
        "--input",
        s(&input),
        "--output",
        s(&file.join("x.npy")),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is a file, not a folder"),
        "{}",
        stderr(&o)
    );
}
