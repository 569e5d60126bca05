//! Helpers of the bad-input tests (`tests/bad_input*.rs`): texflow run with a hang guard, a tiny
//! particle scene, custom GLSL forces and a fake `ffmpeg`.

use std::fs;
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use super::cli::command;

/// Runs texflow in `dir` (None: the test's folder) with `path` prefixed to PATH when given, and
/// fails the test instead of hanging if it has not ended after a minute.
pub fn run_in(dir: Option<&Path>, path: Option<&Path>, args: &[&str]) -> Output {
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

pub fn run(args: &[&str]) -> Output {
    run_in(None, None, args)
}

pub fn finish(mut child: Child, limit: Duration, args: &[&str]) -> Output {
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

pub fn mkfifo(p: &Path) {
    assert!(Command::new("mkfifo").arg(p).status().unwrap().success());
}

/// A force of (0, 1, 0) N.
pub const LIFT: &str = "vec3 force(vec3 x, vec3 v, float age, int type) {\n    \
                    return vec3(0.0, 1.0, 0.0);\n}\n";

/// A tiny particle scene (16×16 state, 16×16 frame): particles at rest at the origin, no
/// gravity, then `extra` (custom forces, say).
pub fn scene_text(extra: &str) -> String {
    format!(
        "name = \"tiny\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
         dt = 0.02\n[[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
         speed = [0.0, 0.0]\nmass = 1.0\n{extra}[render]\nresolution = [16, 16]\n"
    )
}

/// Writes `scene.toml` with `extra` into `dir`, and returns its path.
pub fn scene_file(dir: &Path, extra: &str) -> PathBuf {
    let p = dir.join("scene.toml");
    fs::write(&p, scene_text(extra)).unwrap();
    p
}

pub fn custom(glsl: &str) -> String {
    format!("[[forces.custom]]\nglsl = \"{glsl}\"\n")
}

/// An executable `ffmpeg` in a new folder under `dir`, running `body` (sh).
pub fn fake_ffmpeg(dir: &Path, body: &str) -> PathBuf {
    let bin = dir.join("fakebin");
    fs::create_dir_all(&bin).unwrap();
    let p = bin.join("ffmpeg");
    fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
    fs::set_permissions(&p, fs::Permissions::from_mode(0o755)).unwrap();
    bin
}
