//! The knobs a stranger brings from other particle tools, each against an expectation that does
//! not use the code under test: `--set` against the same edit made to the file's text,
//! `render --start` against the frames of a run without it, `--loop` against the cross-fade
//! computed here from the run's own PNG frames, "did you mean" against the names.

mod common;

use common::cli::{stderr, texflow};

use std::path::Path;

use texflow::scene;

fn set(settings: &[&str]) -> Vec<String> {
    settings.iter().map(|s| s.to_string()).collect()
}

#[test]
fn set_gives_the_scene_that_editing_the_file_gives() {
    let src = scene::builtin_source("fountain").unwrap();
    let label = "fountain (built-in)";
    let edited = src
        .replacen("point_size = 5.0", "point_size = 3.5", 1)
        .replacen("rate = 12000.0", "rate = 500.0", 1)
        .replacen("mode = \"sprites\"", "mode = \"points\"", 1)
        .replacen("[render]", "[render]\norder = \"front_to_back\"", 1);
    assert_ne!(edited, src, "the edits apply to the fountain's source");
    let by_file = scene::parse(label, &edited).unwrap();
    let by_set = scene::parse_with(
        label,
        src,
        &set(&[
            "render.point_size=3.5",
            "emitters.allocator[0].rate=500",
            "render.mode=points",
            "render.order=\"front_to_back\"",
        ]),
    )
    .unwrap();
    assert_eq!(by_set, by_file);
    assert_ne!(by_set, scene::parse(label, src).unwrap());
    // A table the file lacks is created; the later of two settings of one key wins.
    let s = scene::parse_with(
        label,
        src,
        &set(&[
            "render.sort.variant=packed",
            "time.substeps=2",
            "time.substeps=3",
        ]),
    )
    .unwrap();
    assert_eq!(s.render.sort.variant, Some(texflow::sort::Variant::Packed));
    assert_eq!(s.time.substeps, 3);
}

#[test]
fn set_errors_name_the_setting_as_typed() {
    let src = scene::builtin_source("fountain").unwrap();
    let err = |settings: &[&str]| {
        scene::parse_with("fountain (built-in)", src, &set(settings))
            .unwrap_err()
            .to_string()
    };
    let cases: [(&[&str], &[&str]); 7] = [
        (
            &["render.pointsize=4"],
            &["--set render.pointsize=4", "did you mean `point_size`?"],
        ),
        (
            &["render.point_size=4", "render.mode=sprite"],
            &["--set render.mode=sprite", "did you mean `sprites`?"],
        ),
        (
            &["emitters.allocator.0.rate=-5"],
            &["--set emitters.allocator.0.rate=-5", "rate must be above 0"],
        ),
        (
            &["emitters.allocator.3.rate=5"],
            &["--set emitters.allocator.3.rate=5", "indices 0 to 0"],
        ),
        (
            &["render.point_size=inf"],
            &["--set render.point_size=inf", "finite"],
        ),
        (
            &["render.point_size"],
            &["--set render.point_size", "KEY=VALUE"],
        ),
        (
            &["render.point_size.x=1"],
            &["--set render.point_size.x=1", "is a value, not a table"],
        ),
    ];
    for (settings, wanted) in cases {
        let e = err(settings);
        for w in wanted {
            assert!(e.contains(w), "{settings:?}: `{w}` missing from: {e}");
        }
    }
    let e = err(&["particles.size=[4, 4]", "emitters.allocator.0.rate=1e9"]);
    assert!(e.contains("--set emitters.allocator.0.rate=1e9"), "{e}");
    // A key that a setting makes invalid elsewhere is reported at its line in the file, with
    // the settings: the fire's `life` (line 23) no longer fits a shorter `max_age`.
    let fire = scene::builtin_source("fire").unwrap();
    let line = 1 + fire[..fire.find("life = ").unwrap()].matches('\n').count();
    let e = scene::parse_with("fire.toml", fire, &set(&["fire.max_age=1.0"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with(&format!("fire.toml:{line}:")) && e.contains("(with --set fire.max_age=1.0)"),
        "{e}"
    );
    // The file's own mistakes keep their line and column.
    let bad = src.replacen("[render]", "[render]\npointsize = 3.0", 1);
    let e = scene::parse_with("f.toml", &bad, &set(&["render.point_size=4"]))
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("f.toml:") && e.contains("did you mean `point_size`?"),
        "{e}"
    );
}

#[test]
fn every_command_that_takes_a_scene_takes_set() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("f");
    let out = out.to_str().unwrap();
    let ok: [&[&str]; 3] = [
        &["scene", "check", "fountain", "--set", "render.point_size=3"],
        &[
            "scene",
            "passes",
            "smoke-unlit",
            "--set",
            "render.blending=additive",
        ],
        &[
            "render",
            "fire",
            "--particles",
            "16",
            "--frames",
            "1",
            "--out",
            out,
            "-q",
            "--set",
            "render.mode=points",
        ],
    ];
    for args in ok {
        let o = texflow(args);
        assert!(o.status.success(), "{args:?}: {}", stderr(&o));
    }
    // Without the sort (additive blending), smoke's pass list has no sort stage.
    let o = texflow(&[
        "scene",
        "passes",
        "smoke-unlit",
        "--set",
        "render.blending=additive",
    ]);
    assert!(!String::from_utf8_lossy(&o.stdout).contains("sort"));
    for cmd in [
        &["render", "fire"][..],
        &["view", "fire"],
        &["scene", "check", "fire"],
        &["collide-stats", "collide"],
        &["bench", "scene", "fire"],
        &["bench", "step"],
    ] {
        let mut args = cmd.to_vec();
        args.extend(["--set", "render.pointsize=2"]);
        let o = texflow(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("--set render.pointsize=2")
                && stderr(&o).contains("did you mean `point_size`?"),
            "{args:?}: {}",
            stderr(&o)
        );
    }
}

#[test]
fn unknown_scene_names_get_the_closest_built_in() {
    for (cmd, typed, meant) in [
        (&["render"][..], "fountian", "fountain"),
        (&["scene", "check"], "smok", "smoke"),
        (&["scene", "list"], "colide", "collide"),
        (&["bench", "step"], "fire-point", "fire-points"),
    ] {
        let mut args = cmd.to_vec();
        args.push(typed);
        let o = texflow(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        assert!(
            stderr(&o).contains(&format!("did you mean `{meant}`?")),
            "{args:?}: {}",
            stderr(&o)
        );
    }
    let o = texflow(&["render", "waterfall"]);
    assert!(!stderr(&o).contains("did you mean"), "{}", stderr(&o));
}

fn frames(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn start_skips_the_first_frames_and_keeps_the_indices() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let mut args = vec![
            "render",
            "fountain",
            "--particles",
            "16",
            "--resolution",
            "32x24",
            "--frames",
            "9",
            "--out",
            out.to_str().unwrap(),
            "-q",
        ];
        args.extend(extra);
        let o = texflow(&args);
        assert!(o.status.success(), "{}", stderr(&o));
        out
    };
    let all = run("all", &[]);
    let late = run("late", &["--start", "4", "--every", "2"]);
    assert_eq!(
        frames(&late),
        ["frame_00004.png", "frame_00006.png", "frame_00008.png"]
    );
    for f in frames(&late) {
        assert_eq!(
            std::fs::read(late.join(&f)).unwrap(),
            std::fs::read(all.join(&f)).unwrap(),
            "{f} differs from the run that wrote every frame"
        );
    }
    let o = texflow(&["render", "fire", "--frames", "5", "--start", "5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("--start 5"), "{}", stderr(&o));
}

#[test]
fn loop_cross_fades_the_last_frames_into_the_first() {
    let dir = tempfile::tempdir().unwrap();
    let (video, out) = (dir.path().join("loop.png"), dir.path().join("f"));
    // Frames 2 .. 9 written (8), fade 2: the video is f4 .. f7, then f8 into f2, f9 into f3.
    let o = texflow(&[
        "render",
        "fountain",
        "--particles",
        "16",
        "--resolution",
        "32x24",
        "--start",
        "2",
        "--frames",
        "10",
        "--video",
        video.to_str().unwrap(),
        "--loop",
        "2",
        "--out",
        out.to_str().unwrap(),
        "-q",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let png = |i: u64| {
        image::open(out.join(format!("frame_{i:05}.png")))
            .unwrap()
            .to_rgb8()
            .into_raw()
    };
    let mix = |tail: Vec<u8>, head: Vec<u8>, w: f32| -> Vec<u8> {
        tail.iter()
            .zip(&head)
            .map(|(t, h)| ((1.0 - w) * *t as f32 + w * *h as f32).round() as u8)
            .collect()
    };
    let expected = [
        png(4),
        png(5),
        png(6),
        png(7),
        mix(png(8), png(2), 1.0 / 3.0),
        mix(png(9), png(3), 2.0 / 3.0),
    ];
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&video).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let control = reader.info().animation_control().expect("an APNG");
    assert_eq!(control.num_frames, 6);
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    for (k, want) in expected.iter().enumerate() {
        let info = reader.next_frame(&mut buf).unwrap();
        assert!(
            &buf[..info.buffer_size()] == want.as_slice(),
            "video frame {k} is not the expected frame or cross-fade"
        );
    }
    assert_ne!(png(8), png(2), "the fade mixes different frames");
    // Too short a run for its fade is refused before anything is written.
    let o = texflow(&[
        "render",
        "fire",
        "--frames",
        "4",
        "--video",
        dir.path().join("short.gif").to_str().unwrap(),
        "--loop",
        "2",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(!dir.path().join("short.gif").exists());
}
