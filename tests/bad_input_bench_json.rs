//! Bad input to the benchmarks, and `--json` on every command, through the built binary
//! (docs/reliability.md).

mod common;

use common::bad_input::{run, scene_file, scene_text};
use common::cli::{s, stderr};

use std::fs;

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

/// The runs `--json` is checked on, `SCENE` and `OUT` standing for the scene and the frame
/// folder.
const JSON_RUNS: [&str; 12] = [
    "info --json",
    "render SCENE --frames 2 --out OUT --json",
    "render SCENE --frames 2 --out OUT --json --stats",
    "render SCENE --frames 2 --out OUT --json --stats --quiet",
    "scene passes SCENE --json",
    "collide-stats --particles 16 --steps 2 --json",
    "bench scene SCENE --repeats 1 --warmup 1 --json",
    "bench step --sizes 16 --repeats 1 --resolution 16 --json",
    "bench sort --sizes 16 --variants fp --repeats 1 --no-cpu --json",
    "collide-stats --particles 16 --steps 2 --sweep --json",
    "bench scenes --sizes 16 --repeats 1 --warmup 1 --resolution 16 --json",
    // The slow one (about 7 s on llvmpipe); `report convergence --quick --json`, a minute
    // or more, has a test of its own in tests/report.rs.
    "report stability --json",
];

#[test]
fn json_output_is_one_document_for_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    let out = d.join("o");
    let runs: Vec<Vec<&str>> = JSON_RUNS
        .iter()
        .map(|line| {
            line.split_whitespace()
                .map(|a| match a {
                    "SCENE" => s(&sc),
                    "OUT" => s(&out),
                    a => a,
                })
                .collect()
        })
        .collect();
    for args in &runs {
        let o = run(args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let text = String::from_utf8(o.stdout).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text)
            .unwrap_or_else(|e| panic!("{args:?}: stdout is not one JSON document ({e}): {text}"));
        assert!(v.is_object(), "{args:?}: {text}");
    }
}
