//! `texflow view --frames N --screenshot FILE` under Xvfb: the window's frame N is the frame
//! `render` writes for the same seed and frame index N-1, byte for byte. The window shows the
//! engine's RGBA8 frame target through a 1:1 nearest blit (window size = frame size), so no
//! tolerance is needed; the frame is drawn by the same passes in the window's own GL context
//! (wrapped with `gl::Context::from_current`) instead of a surfaceless EGL one.
//!
//! Skipped, with the reason printed, where neither a DISPLAY nor an `Xvfb` executable exists;
//! `.ci/run` installs xvfb so that CI runs it.

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

/// An Xvfb server started for the test, killed on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts Xvfb on a free display number (it picks one and prints it on `-displayfd`).
fn start_xvfb() -> Option<Xvfb> {
    let mut child = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            "640x480x24",
            "-nolisten",
            "tcp",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .ok()?;
    let mut line = String::new();
    BufReader::new(child.stdout.take()?)
        .read_line(&mut line)
        .ok()?;
    let n = line.trim();
    if n.is_empty() {
        let _ = child.kill();
        return None;
    }
    Some(Xvfb {
        display: format!(":{n}"),
        child,
    })
}

fn run(display: &str, args: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args(args)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .expect("run texflow");
    assert!(
        o.status.success(),
        "texflow {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn compare(display: &str, dir: &Path, scene: &str, frames: u64) {
    let shot = dir.join(format!("{scene}_window.png"));
    let out = dir.join(format!("{scene}_frames"));
    let common = ["--particles", "16", "--resolution", "64x48", "--seed", "3"];
    let n = frames.to_string();
    let mut view = vec![
        "view",
        scene,
        "--frames",
        &n,
        "--screenshot",
        shot.to_str().unwrap(),
    ];
    view.extend(common);
    run(display, &view);
    // Every frame drawn, as the window draws every frame: a sort spread over frames (Latta
    // §3.4.4) advances once per drawn frame.
    let mut render = vec!["render", scene, "--frames", &n, "--every", "1", "-q"];
    render.extend(["--out", out.to_str().unwrap()]);
    render.extend(common);
    run(display, &render);
    let window = image::open(&shot).unwrap().to_rgb8();
    let headless = image::open(out.join(format!("frame_{:05}.png", frames - 1)))
        .unwrap()
        .to_rgb8();
    assert_eq!(
        window.dimensions(),
        (64, 48),
        "the window has the frame's size"
    );
    assert!(
        headless.pixels().any(|p| p.0 != [0, 0, 0]),
        "{scene}: the frame shows particles"
    );
    let differing = window
        .pixels()
        .zip(headless.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert_eq!(
        differing, 0,
        "{scene}: {differing} pixels of the window differ from the headless frame"
    );
}

#[test]
fn window_screenshot_equals_the_headless_frame() {
    let own;
    let display = match std::env::var("DISPLAY") {
        Ok(d) if !d.is_empty() => d,
        _ => match start_xvfb() {
            Some(x) => {
                own = x;
                own.display.clone()
            }
            None => {
                eprintln!(
                    "skipped: no DISPLAY and no Xvfb to start one (apt-get install xvfb; \
                     .ci/run does)"
                );
                return;
            }
        },
    };
    let dir = tempfile::tempdir().unwrap();
    // Additive points (the fountain) and an alpha-blended, GPU-sorted scene (smoke).
    compare(&display, dir.path(), "fountain", 8);
    compare(&display, dir.path(), "smoke-unlit", 8);
}
