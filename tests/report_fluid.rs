//! `report`'s fluid section (src/report/fluid.rs), quick: the dam break swept over the time
//! step, the smoothing length and the speed of sound, every file with its rows, and the
//! compression falling as the speed of sound rises (weak compressibility: ~ (U / c)²).

mod common;

use common::{context, no_gl_error};
use texflow::report::{self, ReportOptions};

#[test]
fn the_fluid_section_writes_its_sweep_and_stiffer_fluid_compresses_less() {
    let ctx = context();
    let dir = tempfile::tempdir().unwrap();
    let sections = report::select(&["fluid".to_string()]).unwrap();
    let out = report::run_sections(
        &ctx,
        &ReportOptions::new(true),
        dir.path(),
        &sections,
        &mut |_| {},
    )
    .unwrap();
    for f in [
        "fluid_error.csv",
        "fluid_error.json",
        "fluid_error.png",
        "summary.md",
    ] {
        let path = dir.path().join(f);
        assert!(out.files.contains(&path), "{f} not listed: {:?}", out.files);
        assert!(std::fs::metadata(&path).unwrap().len() > 0, "{f}");
    }
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    let text = std::fs::read_to_string(dir.path().join("fluid_error.json")).unwrap();
    let rows: serde_json::Value = serde_json::from_str(&text).unwrap();
    let rows = rows.as_array().unwrap();
    let plan = report::fluid::plan(report::Size::Quick);
    assert_eq!(rows.len(), plan.len());
    let csv = std::fs::read_to_string(dir.path().join("fluid_error.csv")).unwrap();
    assert_eq!(csv.lines().count(), plan.len() + 1, "{csv}");
    let f = |r: &serde_json::Value, k: &str| r[k].as_f64().unwrap();
    for (r, (sweep, run)) in rows.iter().zip(&plan) {
        assert_eq!(r["sweep"], *sweep);
        assert_eq!(f(&r["run"], "dt") as f32, run.dt);
        assert_eq!(r["particles"], 256, "{r}");
        assert!(f(r, "ms_per_sim_second") > 0.0, "{r}");
        assert!(
            f(r, "max_density_error") >= f(r, "mean_density_error"),
            "{r}"
        );
        assert!(
            f(r, "mean_density_error") > 0.0 && f(r, "max_compression") < 0.1,
            "{r}"
        );
        // The front is compared at Martin & Moyce's T = 0.41 and 0.84 (quick: to T = 1).
        assert_eq!(r["front_points"], 2, "{r}");
        assert!(f(r, "front_error") < 0.5, "{r}");
        assert_eq!(r["truncated_searches"], 0, "{r}");
    }
    // Halving dt doubles the steps.
    let steps: Vec<f64> = rows[..3].iter().map(|r| f(r, "steps")).collect();
    assert!((steps[1] / steps[0] - 2.0).abs() < 0.05 && (steps[2] / steps[1] - 2.0).abs() < 0.05);
    // At the same dt, twice the speed of sound compresses the fluid less.
    let (soft, stiff) = (&rows[2], &rows[5]);
    assert_eq!(f(&soft["run"], "dt"), f(&stiff["run"], "dt"));
    assert!(
        f(stiff, "max_compression") < 0.6 * f(soft, "max_compression"),
        "c 15: {soft}\nc 30: {stiff}"
    );
    let md = std::fs::read_to_string(dir.path().join("summary.md")).unwrap();
    assert!(md.contains("## Fluid: error against run time"), "{md}");
    no_gl_error(&ctx);
}
