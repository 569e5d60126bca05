//! `texflow report all --quick`: every file it promises, with what each must hold (the report
//! runs once; each part of it is checked by its own function), and a file in the way of --out.

mod common;

use std::path::{Path, PathBuf};

use serde_json::Value;

fn f64_of(v: &Value) -> f64 {
    v.as_f64().unwrap_or(f64::NAN)
}

fn json(out_dir: &Path, f: &str) -> Value {
    serde_json::from_str(&std::fs::read_to_string(out_dir.join(f)).unwrap()).unwrap()
}

const PROBLEMS: [&str; 4] = ["drag", "oscillator", "kepler", "bounce"];

/// `texflow report all --quick --out DIR` writes every file it promises (Tables 1 and 2, plots,
/// CSVs, JSON, markdown, summary) with what each must hold.
#[test]
fn cli_report_all_quick_writes_every_file() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("report");
    let out = common::cli::command()
        .args(["report", "all", "--quick", "--quiet", "--out"])
        .arg(&out_dir)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("warning"), "{stderr}");
    let listed: Vec<PathBuf> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(PathBuf::from)
        .collect();
    check_files(&out_dir, &listed);
    check_tables(&out_dir);
    check_sort_frames(&out_dir);
    check_collisions(&out_dir);
    check_convergence_and_summary(&out_dir);
    check_constraints_and_stability(&out_dir);
}

/// Every promised file is there, non-empty and listed, and nothing else is listed; the plots
/// have their sizes.
fn check_files(out_dir: &Path, listed: &[PathBuf]) {
    let mut promised = vec![
        "step.json",
        "step.md",
        "render_paths.json",
        "render_paths.md",
        "tables_runs.json",
        "table1_sort.json",
        "table1_sort.md",
        "table2_scenes.json",
        "table2_scenes.md",
        "convergence.csv",
        "convergence_orders.csv",
        "convergence.json",
        "sort_frames.csv",
        "sort_frames.json",
        "sort_frames_passes.png",
        "sort_frames_time.png",
        "sort_spread.json",
        "collisions.csv",
        "collisions.json",
        "collisions_miss_rate.png",
        "collisions_density.csv",
        "collisions_density.png",
        "pile_depth.json",
        "stability.json",
        "stability.md",
        "baselines.csv",
        "cost_model.json",
        "cost_model.md",
        "constraints.csv",
        "constraints.json",
        "constraints_passes.png",
        "constraints_time.png",
        "fluid_error.csv",
        "fluid_error.json",
        "fluid_error.png",
        "summary.md",
    ];
    let problems = PROBLEMS;
    let plots: Vec<String> = problems
        .iter()
        .flat_map(|p| [format!("wp_{p}.png"), format!("dt_{p}.png")])
        .collect();
    promised.extend(plots.iter().map(String::as_str));
    for f in &promised {
        let path = out_dir.join(f);
        let len = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        assert!(len > 0, "{f} missing or empty");
        assert!(listed.contains(&path), "{f} not listed: {listed:?}");
    }
    assert_eq!(listed.len(), promised.len(), "{listed:?}");
    for p in &plots {
        let img = image::open(out_dir.join(p)).unwrap();
        assert_eq!((img.width(), img.height()), (1000, 720), "{p}");
    }
    for p in [
        "sort_frames_passes.png",
        "sort_frames_time.png",
        "collisions_miss_rate.png",
        "collisions_density.png",
        "constraints_passes.png",
        "constraints_time.png",
    ] {
        let img = image::open(out_dir.join(p)).unwrap();
        assert_eq!((img.width(), img.height()), (900, 600), "{p}");
    }
}

/// Tables 1 and 2 and the render paths.
fn check_tables(out_dir: &Path) {
    let json = |f: &str| json(out_dir, f);
    // Table 1: six variants and two CPU baselines at 64² and 128², every GPU sort with its floor.
    let t1 = json("table1_sort.json");
    let t1 = t1.as_array().unwrap();
    assert_eq!(t1.len(), 2 * 8, "{t1:?}");
    for r in t1 {
        assert!(f64_of(&r["ms"]) > 0.0, "{r}");
        if !r["variant"].as_str().unwrap().starts_with("cpu") {
            assert!(f64_of(&r["ratio"]) > 0.0, "{r}");
        }
    }
    // Table 2: E1-E5, E3p and E4p at both sizes, every one measured with particles alive.
    let t2 = json("table2_scenes.json");
    let t2 = t2.as_array().unwrap();
    assert_eq!(t2.len(), 2 * 7, "{t2:?}");
    for r in t2 {
        assert!(f64_of(&r["fps"]) > 0.0, "{r}");
        assert!(r["live"].as_u64().unwrap() > 0, "{r}");
    }
    // Both render paths timed at both sizes, drawing the same live particles.
    let rp = json("render_paths.json");
    let rp = rp.as_array().unwrap();
    assert_eq!(rp.len(), 2, "{rp:?}");
    for r in rp {
        assert!(f64_of(&r["texture_fetch_ms"]) > 0.0 && f64_of(&r["vertex_buffer_ms"]) > 0.0);
        assert!(r["live"].as_u64().unwrap() > 0, "{r}");
    }
}

/// The sort spread over frames.
fn check_sort_frames(out_dir: &Path) {
    let json = |f: &str| json(out_dir, f);
    // The sort spread over frames: the whole sort leaves the drawing order exact at either camera
    // speed; under the slow pan fewer passes per frame leave it less sorted, never more; the fast
    // turn leaves it less sorted than the slow pan.
    let sf = json("sort_frames.json");
    let rows = sf["rows"].as_array().unwrap();
    let by_orbit = |o: f64| -> Vec<&serde_json::Value> {
        rows.iter()
            .filter(|r| f64_of(&r["orbit_deg_per_s"]) == o)
            .collect()
    };
    let (slow, fast) = (by_orbit(10.0), by_orbit(60.0));
    assert_eq!(slow.len(), fast.len());
    assert_eq!(slow.len() + fast.len(), rows.len(), "{rows:?}");
    for r in [&slow, &fast] {
        let whole = r.last().unwrap();
        assert_eq!(whole["passes_per_frame"], whole["total_passes"]);
        assert_eq!(whole["inversions_max"].as_u64(), Some(0), "{whole}");
        assert!(f64_of(&r[0]["inversions_mean"]) > 0.0, "{}", r[0]);
    }
    for w in slow.windows(2) {
        assert!(
            f64_of(&w[1]["inversions_mean"]) <= f64_of(&w[0]["inversions_mean"]),
            "{} then {}",
            w[0],
            w[1]
        );
    }
    assert!(
        f64_of(&slow[0]["inversion_fraction"]) < f64_of(&fast[0]["inversion_fraction"]),
        "{} against {}",
        slow[0],
        fast[0]
    );
}

/// Collision detection and the pile depth.
fn check_collisions(out_dir: &Path) {
    let json = |f: &str| json(out_dir, f);
    // Collisions: no reported pair is false; the staggered lattice misses no more than one.
    let col = json("collisions.json");
    let col = col.as_array().unwrap();
    let missed = |v: &str| {
        col.iter()
            .find(|r| r["variant"] == v)
            .map(|r| r["stats"]["missed"].as_u64().unwrap())
            .unwrap_or_else(|| panic!("no row {v}: {col:?}"))
    };
    for r in col {
        assert_eq!(r["stats"]["false_pairs"].as_u64(), Some(0), "{r}");
        assert!(r["stats"]["pairs_true"].as_u64().unwrap() > 0, "{r}");
    }
    assert!(missed("scene") <= missed("staggered off"), "{col:?}");
    // The pile: UberFlow's detection and the exact one at 1, 2 and 4 iterations, each timed.
    let pile = json("pile_depth.json");
    let pile = pile.as_array().unwrap();
    assert_eq!(pile.len(), 4, "{pile:?}");
    for r in pile {
        assert!(
            f64_of(&r["gpu_ms"]) > 0.0 && r["particles"].as_u64() > Some(0),
            "{r}"
        );
    }
}

/// The convergence curves and the summary's sections.
fn check_convergence_and_summary(out_dir: &Path) {
    let problems = PROBLEMS;
    // Every curve: the papers' 3 integrators x 3 precisions, less Verlet's half-float
    // velocities, and (quick) the thesis's 3 in fp32.
    let orders = std::fs::read_to_string(out_dir.join("convergence_orders.csv")).unwrap();
    assert_eq!(orders.lines().count(), 1 + problems.len() * 11, "{orders}");
    let points = std::fs::read_to_string(out_dir.join("convergence.csv")).unwrap();
    assert!(points
        .lines()
        .next()
        .unwrap()
        .contains("gpu_ms_per_simulated_s"));
    let summary = std::fs::read_to_string(out_dir.join("summary.md")).unwrap();
    for heading in [
        "## The fire's step against its floor",
        "## UberFlow's Table 1",
        "## UberFlow's Table 2",
        "## Render paths",
        "## Error against run time",
        "## Sort spread over frames",
        "## Collisions between particles",
        "## Stability on stiff and extreme cases",
        "## Stateless against stateful",
        "## Distance constraints",
        "## Run time",
        "## Files",
    ] {
        assert!(summary.contains(heading), "{heading} missing:\n{summary}");
    }
    // Every section's wall time, in the report's order.
    let times = summary.split("## Run time").nth(1).unwrap();
    for s in texflow::report::sections() {
        assert!(
            times.contains(&format!("| {} | ", s.name)),
            "{} has no time",
            s.name
        );
    }
}

/// The constraint schemes and the stability table.
fn check_constraints_and_stability(out_dir: &Path) {
    let json = |f: &str| json(out_dir, f);
    // Constraints: 4 schemes at 2 iteration counts; at each, Gauss-Seidel with attachments ends
    // with a smaller worst and mean edge error than Jacobi without, in more passes.
    let rows = json("constraints.json")["rows"].as_array().unwrap().clone();
    assert_eq!(rows.len(), 8, "{rows:?}");
    let at = |scheme: &str, n: u64| {
        rows.iter()
            .find(|r| r["scheme"] == scheme && r["iterations"] == n)
            .unwrap_or_else(|| panic!("{scheme} × {n} missing"))
            .clone()
    };
    for n in [2, 8] {
        let (j, g) = (at("jacobi", n), at("gauss-seidel + attachments", n));
        for k in ["worst", "mean"] {
            assert!(g[k].as_f64() < j[k].as_f64(), "{k} at {n}: {g} against {j}");
        }
        assert_eq!(g["passes"].as_u64(), Some(9 * n));
        assert!(g["gpu_ms"].as_f64().unwrap() > 0.0);
    }
    let stability = std::fs::read_to_string(out_dir.join("stability.md")).unwrap();
    assert!(
        stability.contains("| dt = 0 | refused | refused | yes |"),
        "{stability}"
    );
    assert!(!stability.contains("| NO |"), "{stability}");
}

/// A file where the folder should go: bad input, nothing created.
#[test]
fn report_all_refuses_a_file_as_its_folder() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, b"x").unwrap();
    let out = common::cli::command()
        .args(["report", "all", "--quick", "--quiet", "--out"])
        .arg(&file)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
}
