//! `texflow trace`: the pictures are read back and checked, not only found. A 16×16 sort's first
//! picture is out of order and its last one sorted (keys read from the pixels through the ramp);
//! a scene trace's last picture is the frame `render` writes, pixel for pixel, and its sort
//! pictures show the keys in order after the network.

mod common;

use common::cli::{pngs, stderr, texflow};

use std::path::Path;

use texflow::trace::{keys_from_picture, picture::ramp_position};

fn rgb(path: &Path) -> image::RgbImage {
    image::open(path).expect("decodable PNG").to_rgb8()
}

/// Entries whose key (read from the picture) is smaller than the one before.
fn descents(keys: &[Option<f32>]) -> usize {
    let k: Vec<f32> = keys.iter().map(|k| k.expect("a ramp colour")).collect();
    k.windows(2).filter(|w| w[1] + 1e-3 < w[0]).count()
}

#[test]
fn a_16x16_sort_trace_ends_sorted() {
    for variant in ["oddeven", "fp", "packed"] {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("t");
        let o = texflow(&[
            "trace",
            "sort",
            "--variant",
            variant,
            "--size",
            "16",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ]);
        assert!(o.status.success(), "{variant}: {}", stderr(&o));
        let names = pngs(&out);
        // 256 keys: odd-even and bitonic both take 36 passes, plus the input picture.
        assert_eq!(names.len(), 37, "{variant}: {names:?}");
        let first = keys_from_picture(&rgb(&out.join(&names[0])), 16);
        let last = keys_from_picture(&rgb(&out.join(names.last().unwrap())), 16);
        assert!(descents(&first) > 50, "{variant}: the input is random");
        assert_eq!(descents(&last), 0, "{variant}: the last picture is sorted");
        // The same keys: the sorted picture holds the input's values in order.
        let mut a: Vec<f32> = first.iter().map(|k| k.unwrap()).collect();
        a.sort_by(f32::total_cmp);
        let b: Vec<f32> = last.iter().map(|k| k.unwrap()).collect();
        assert!(
            a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 2e-3),
            "{variant}"
        );
        let index = std::fs::read_to_string(out.join("index.md")).unwrap();
        assert!(index.contains("Pass 36 of 36"), "{index}");
        assert!(index.contains("![pass_036.png](pass_036.png)"));
        let gif = std::fs::read(out.join("sort.gif")).unwrap();
        assert_eq!(&gif[..6], b"GIF89a");
    }
}

#[test]
fn sort_trace_sizes_are_capped() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t");
    for size in ["128", "12", "1"] {
        let o = texflow(&[
            "trace",
            "sort",
            "--size",
            size,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(!out.exists());
    }
    let o = texflow(&["trace", "--help"]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("from 2 to 64"));
}

#[test]
fn a_scene_trace_ends_with_the_frame_render_writes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t");
    let frames = dir.path().join("f");
    let common = ["--particles", "16", "--resolution", "48x32", "-q"];
    let mut args = vec![
        "trace",
        "smoke-unlit",
        "--frame",
        "3",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(&common);
    let o = texflow(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let mut args = vec![
        "render",
        "smoke-unlit",
        "--frames",
        "4",
        "--out",
        frames.to_str().unwrap(),
    ];
    args.extend_from_slice(&common);
    let o = texflow(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let names = pngs(&out);
    let last = names.last().unwrap();
    assert!(last.ends_with("_frame.png"), "{names:?}");
    assert_eq!(rgb(&out.join(last)), rgb(&frames.join("frame_00003.png")));
    // After the network the keys rise along the rows (dead particles' +inf keys, magenta,
    // come last); after the key pass they did not.
    let index = std::fs::read_to_string(out.join("index.md")).unwrap();
    for pass in ["integrate", "sort keys", "sort network", "gather", "render"] {
        assert!(index.contains(pass), "{pass} missing:\n{index}");
    }
    let key_picture = |phase: &str| {
        let name = names
            .iter()
            .filter(|n| n.ends_with("_sort_key.png"))
            .find(|n| {
                let number = &n[..2];
                index.contains(&format!("## {}. {phase}", number.trim_start_matches('0')))
            })
            .unwrap_or_else(|| panic!("no key picture for {phase}: {names:?}"));
        let img = rgb(&out.join(name));
        let s = img.width() / 16;
        (0..256u32)
            .map(|i| ramp_position(img.get_pixel((i % 16) * s + s / 2, (i / 16) * s + s / 2).0))
            .collect::<Vec<_>>()
    };
    let sorted = key_picture("sort network");
    let live: Vec<f32> = sorted.iter().map_while(|k| *k).collect();
    assert!(live.len() > 10, "few live particles: {}", live.len());
    assert!(sorted[live.len()..].iter().all(|k| k.is_none()));
    assert!(live.windows(2).all(|w| w[1] + 1e-3 >= w[0]), "{live:?}");
    let keyed = key_picture("sort keys");
    let before: Vec<f32> = keyed.iter().flatten().copied().collect();
    assert!(before.windows(2).any(|w| w[1] + 1e-3 < w[0]));
}

/// A sparse state (the fountain's first live rows of a 128×128 state at frame 10) is pictured
/// cropped to the rows that hold its live particles, so most of each position picture is live
/// particles rather than black, and the legend says which rows it shows.
#[test]
fn sparse_state_pictures_show_the_live_rows() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("t");
    let o = texflow(&[
        "trace",
        "fountain",
        "--frame",
        "10",
        "--particles",
        "128",
        "--resolution",
        "32x32",
        "--out",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let index = std::fs::read_to_string(out.join("index.md")).unwrap();
    assert!(index.contains("of 128 hold the live particles"), "{index}");
    let names = pngs(&out);
    let shots: Vec<_> = names
        .iter()
        .filter(|n| n.ends_with("_position.png"))
        .collect();
    assert!(!shots.is_empty(), "{names:?}");
    for name in shots {
        let img = rgb(&out.join(name));
        let live = img.pixels().filter(|p| p.0 != [0, 0, 0]).count();
        let fraction = live as f64 / (img.width() * img.height()) as f64;
        assert!(fraction > 0.5, "{name}: {fraction} of the picture is live");
    }
}

/// Every model and stage is traced through the engine's own stages: the fire's one pass, and
/// the cloth's integration and constraint relaxation; each trace ends with the frame `render`
/// writes.
#[test]
fn traces_of_the_fire_and_the_cloth_end_with_the_frame_render_writes() {
    for (name, stage) in [("fire", "integrate"), ("cloth", "constraint relaxation")] {
        let dir = tempfile::tempdir().unwrap();
        let (out, frames) = (dir.path().join("t"), dir.path().join("f"));
        let common = ["--particles", "16", "--resolution", "32x32", "-q"];
        let (o, f) = (out.to_str().unwrap(), frames.to_str().unwrap());
        let mut args = vec!["trace", name, "--frame", "2", "--out", o];
        args.extend_from_slice(&common);
        let run = texflow(&args);
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        let mut args = vec!["render", name, "--frames", "3", "--out", f];
        args.extend_from_slice(&common);
        let run = texflow(&args);
        assert!(run.status.success(), "{name}: {}", stderr(&run));
        let names = pngs(&out);
        let last = names.last().unwrap();
        assert!(last.ends_with("_frame.png"), "{name}: {names:?}");
        assert_eq!(
            rgb(&out.join(last)),
            rgb(&frames.join("frame_00002.png")),
            "{name}"
        );
        let index = std::fs::read_to_string(out.join("index.md")).unwrap();
        assert!(index.contains(stage), "{name}: no {stage} in\n{index}");
    }
}
