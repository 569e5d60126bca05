//! The benchmark tables on this device: the fire's step against its floors (`texflow bench
//! step`), UberFlow's Table 1 (`texflow bench sort`: every sort variant against its floor and
//! the CPU) and Table 2 (`texflow bench scenes`: E1-E5 frames per second), with the paper's
//! figures beside the measured ones. The full run uses the sizes of the docs (the step up to
//! 2048², Table 1 up to 1024², and 2048² on a hardware GPU, where a sort of 4 M entries takes
//! milliseconds rather than seconds); `--quick` measures 64² and 128² only.

use std::path::Path;

use super::{Progress, ReportOptions, SectionOutput, Size};
use crate::bench::scenes::{self as bs, SceneRecord, ScenesOptions};
use crate::bench::{bench_sort, bench_step, sort_markdown, step_markdown, Clock};
use crate::bench::{SortBenchOptions, SortRecord, StepOptions, StepRecord};
use crate::error::Result;
use crate::gl::Context;
use crate::sort::Variant;

/// The step benchmark's sizes and repeats.
pub fn step_sizes(size: Size) -> (Vec<u32>, usize) {
    match size {
        Size::Quick => (vec![64, 128], 5),
        Size::Full => (vec![256, 512, 1024, 2048], 21),
    }
}

/// Table 1's sizes and repeats for this run and device.
pub fn sort_sizes(size: Size, clock: Clock) -> (Vec<u32>, usize) {
    match size {
        Size::Quick => (vec![64, 128], 3),
        Size::Full if clock == Clock::Gpu => (vec![128, 256, 512, 1024, 2048], 11),
        Size::Full => (vec![128, 256, 512, 1024], 11),
    }
}

/// Table 2's sizes, repeats and warm-up frames (`None`: a full emission cycle).
pub fn scene_sizes(size: Size) -> (Vec<u32>, usize, Option<usize>) {
    match size {
        Size::Quick => (vec![64, 128], 3, Some(30)),
        Size::Full => (bs::PAPER_SIZES.to_vec(), 11, None),
    }
}

/// Runs the fire's step benchmark once.
pub fn step(ctx: &Context, size: Size, progress: Progress<'_>) -> Result<Vec<StepRecord>> {
    let (sizes, repeats) = step_sizes(size);
    let opts = StepOptions {
        repeats,
        ..StepOptions::default()
    };
    bench_step(ctx, &crate::scene::fire(), &sizes, &opts, |n| {
        progress(&format!("step: fire at {n}²"))
    })
}

/// Runs Table 1 once.
pub fn table1(ctx: &Context, size: Size, progress: Progress<'_>) -> Result<Vec<SortRecord>> {
    let (sizes, repeats) = sort_sizes(size, Clock::for_context(ctx));
    let opts = SortBenchOptions {
        repeats,
        clock: None,
        cpu: true,
        steps_per_pass: 2,
        blocked_shapes: Vec::new(),
    };
    bench_sort(ctx, &sizes, &Variant::ALL, &opts, |v, n| {
        progress(&format!("Table 1: {v} at {n}²"))
    })
}

/// Runs Table 2 once.
pub fn table2(ctx: &Context, size: Size, progress: Progress<'_>) -> Result<Vec<SceneRecord>> {
    let (sizes, repeats, warmup) = scene_sizes(size);
    let opts = ScenesOptions {
        repeats,
        warmup_frames: warmup,
        ..ScenesOptions::default()
    };
    bs::bench_scenes(ctx, &sizes, &opts, |e, n| {
        progress(&format!("Table 2: {e} at {n}²"))
    })
}

/// One size of the render-path comparison: E1's frame drawn by vertex texture fetch (thesis
/// Listing 3) and through a vertex buffer filled on the GPU from the position texture
/// (UberFlow §4.7, Latta §3.4.5).
#[derive(Debug, Clone, serde::Serialize)]
pub struct PathRecord {
    /// State side.
    pub size: u32,
    /// Live particles drawn.
    pub live: u64,
    /// Median time of the draw (clear, points) by vertex texture fetch, ms.
    pub texture_fetch_ms: f64,
    /// Median time of the draw (copy into the vertex buffer, clear, points), ms.
    pub vertex_buffer_ms: f64,
    /// vertex_buffer_ms / texture_fetch_ms.
    pub ratio: f64,
    /// The clock.
    pub clock: Clock,
}

/// Times E1's draw by both render paths at Table 2's sizes, once.
pub fn render_paths(ctx: &Context, size: Size, progress: Progress<'_>) -> Result<Vec<PathRecord>> {
    use crate::scene::RenderPath;
    let (sizes, repeats, warmup) = scene_sizes(size);
    let clock = Clock::for_context(ctx);
    let timer = crate::bench::PassTimer::new(ctx, clock)?;
    let mut records = Vec::new();
    for &n in &sizes {
        progress(&format!("render paths at {n}²"));
        let mut ms = [0.0; 2];
        let mut live = 0;
        for (k, path) in [RenderPath::TextureFetch, RenderPath::VertexBuffer]
            .into_iter()
            .enumerate()
        {
            let mut scene = crate::scene::load("e1")?;
            scene.particles.size = [n, n];
            scene.render.path = path;
            let mut engine = crate::engine::build_gpu(ctx, &scene, 1)?;
            for _ in 0..warmup.unwrap_or_else(|| bs::default_warmup_frames(&scene)) {
                engine.advance_frame()?;
            }
            engine.draw()?;
            let mut t = Vec::with_capacity(repeats);
            for _ in 0..repeats {
                let mut r = Ok(());
                t.push(timer.time(|| r = engine.draw())?);
                r?;
            }
            ms[k] = crate::bench::median(&t);
            live = (engine.sim().drawn().positions)
                .read_f32()?
                .chunks_exact(4)
                .filter(|p| p[3] > 0.0 && p.iter().all(|x| x.is_finite()))
                .count() as u64;
        }
        ctx.check_error("render path benchmark")?;
        records.push(PathRecord {
            size: n,
            live,
            texture_fetch_ms: ms[0],
            vertex_buffer_ms: ms[1],
            ratio: ms[1] / ms[0],
            clock,
        });
    }
    Ok(records)
}

/// The render-path records as a markdown table.
pub fn paths_markdown(records: &[PathRecord]) -> String {
    let mut md = String::from(
        "| state | live | vertex texture fetch ms | vertex buffer ms | buffer / fetch |\n\
         |---|---:|---:|---:|---:|\n",
    );
    for r in records {
        md.push_str(&format!(
            "| {0}² | {1} | {2:.3} | {3:.3} | {4:.2} |\n",
            r.size, r.live, r.texture_fetch_ms, r.vertex_buffer_ms, r.ratio
        ));
    }
    md
}

/// For every cell (records of equal `key`) of several runs, the record of median time (the
/// lower of the two middle ones for an even count; records without a time sort last), and the
/// cells whose slowest run took over 1.25 times their fastest, with that ratio.
pub fn median_of_runs<T: Clone, K: PartialEq>(
    runs: &[Vec<T>],
    key: impl Fn(&T) -> K,
    ms: impl Fn(&T) -> Option<f64>,
) -> (Vec<T>, Vec<(T, f64)>) {
    let Some(first) = runs.first() else {
        return (Vec::new(), Vec::new());
    };
    let (mut medians, mut spread) = (Vec::new(), Vec::new());
    for cell in first {
        let mut same: Vec<&T> = runs
            .iter()
            .flat_map(|r| r.iter().filter(|x| key(x) == key(cell)))
            .collect();
        same.sort_by(|a, b| {
            let t = |x: &T| ms(x).unwrap_or(f64::INFINITY);
            t(a).total_cmp(&t(b))
        });
        let median = same[(same.len() - 1) / 2].clone();
        let times: Vec<f64> = same.iter().filter_map(|x| ms(x)).collect();
        if let (Some(lo), Some(hi)) = (times.first(), times.last()) {
            if *lo > 0.0 && hi / lo > 1.25 {
                spread.push((median.clone(), hi / lo));
            }
        }
        medians.push(median);
    }
    (medians, spread)
}

/// `report all`'s section: the benchmark tables, each run `opts.runs` times (interleaved, so
/// that a slow spell of a shared machine does not fall on one table alone), every cell the run
/// of median time. Writes `step`, `table1_sort`, `table2_scenes` and `render_paths` as `.json`
/// (the median records) and `.md`, and `tables_runs.json` (every run).
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let clock = Clock::for_context(ctx);
    let runs = opts.runs.max(1);
    let (mut st, mut t1, mut t2, mut rp) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for run in 0..runs {
        if runs > 1 {
            progress(&format!("tables: run {} of {runs}", run + 1));
        }
        st.push(step(ctx, opts.size, progress)?);
        t1.push(table1(ctx, opts.size, progress)?);
        t2.push(table2(ctx, opts.size, progress)?);
        rp.push(render_paths(ctx, opts.size, progress)?);
    }
    let (st_m, st_s) = median_of_runs(&st, |r| r.size, |r| Some(r.sim_ms));
    let (t1_m, t1_s) = median_of_runs(&t1, |r| (r.variant.clone(), r.size), |r| Some(r.ms));
    let (mut t2_m, t2_s) = median_of_runs(&t2, |r| (r.experiment.clone(), r.size), |r| r.ms);
    with_vs_e5(&mut t2_m);
    let (rp_m, rp_s) = median_of_runs(&rp, |r| r.size, |r| Some(r.texture_fetch_ms));
    let mut files = write_medians(out, &st_m, &t1_m, &t2_m, &rp_m)?;
    let all_runs = out.join("tables_runs.json");
    super::write_json(
        &all_runs,
        &serde_json::json!({ "step": st, "table1_sort": t1, "table2_scenes": t2, "render_paths": rp }),
    )?;
    files.push(all_runs);
    let warnings = unmeasured(&t2_m);
    let noisy = noisy_cells(&st_s, &t1_s, &t2_s, &rp_s);
    let runs_note = runs_note(runs, &noisy);
    let markdown = tables_markdown(opts.size, clock, &runs_note, &st_m, &t1_m, &t2_m, &rp_m);
    Ok(SectionOutput {
        files,
        markdown,
        warnings,
    })
}

/// The cells whose slowest run took over 1.25× their fastest (from [`median_of_runs`]), named.
fn noisy_cells(
    st_s: &[(StepRecord, f64)],
    t1_s: &[(SortRecord, f64)],
    t2_s: &[(SceneRecord, f64)],
    rp_s: &[(PathRecord, f64)],
) -> Vec<String> {
    let mut noisy: Vec<String> = Vec::new();
    noisy.extend(
        st_s.iter()
            .map(|(r, x)| format!("step {}²: ×{x:.2}", r.size)),
    );
    noisy.extend(
        t1_s.iter()
            .map(|(r, x)| format!("Table 1 {} {}²: ×{x:.2}", r.variant, r.size)),
    );
    noisy.extend(
        t2_s.iter()
            .map(|(r, x)| format!("Table 2 {} {}²: ×{x:.2}", r.experiment, r.size)),
    );
    noisy.extend(
        rp_s.iter()
            .map(|(r, x)| format!("render paths {}²: ×{x:.2}", r.size)),
    );
    noisy
}

/// The section's markdown: the runs note, then each table of medians with how it was measured.
fn tables_markdown(
    size: Size,
    clock: Clock,
    runs_note: &str,
    st_m: &[StepRecord],
    t1_m: &[SortRecord],
    t2_m: &[SceneRecord],
    rp_m: &[PathRecord],
) -> String {
    let (_, repeats0) = step_sizes(size);
    let (_, repeats1) = sort_sizes(size, clock);
    let (_, repeats2, warmup) = scene_sizes(size);
    format!(
        "{runs_note}## The fire's step against its floor (`texflow bench step`)\n\n\
         Median of {repeats0} passes of each kind, {}; floor = a write-only pass into the same \
         targets. Files: `step.json`, `step.md`.\n\n{}\n\
         ## UberFlow's Table 1: sorting (`texflow bench sort`)\n\n\
         Median of {repeats1} full sorts (key pass, network, rearrangement of two RGBA32F \
         textures), {}; floor = write-only passes of the same formats and sizes, as many as the \
         sort has. Paper: ATI Radeon 9800 Pro, 2004. Files: `table1_sort.json`, \
         `table1_sort.md`.\n\n{}\n\
         ## UberFlow's Table 2: whole frames of E1-E5 (`texflow bench scenes`)\n\n\
         Median of {repeats2} frames after {}; E1-E4 on the GPU ({}), E5 the CPU engine \
         (wall time). Paper: ATI Radeon 9800 Pro and a Pentium 4 at 2 GHz. Files: \
         `table2_scenes.json`, `table2_scenes.md`.\n\n{}\n\
         ## Render paths: vertex texture fetch against the vertex buffer (E1's frame)\n\n\
         Median of {repeats2} draws of E1's frame (clear and 1-pixel points at 512×512; the \
         buffer path first copies the position texture into the vertex buffer through a pixel \
         pack buffer, on the GPU), {}. Files: `render_paths.json`, `render_paths.md`.\n\n{}",
        clock.name(),
        step_markdown(st_m),
        clock.name(),
        sort_markdown(t1_m),
        match warmup {
            Some(w) => format!("{w} warm-up frames"),
            None => "a full emission cycle".into(),
        },
        clock.name(),
        bs::markdown(t2_m),
        clock.name(),
        paths_markdown(rp_m)
    )
}

/// The GPU/CPU ratios of the median cells (which may come from different runs): each size's
/// frames per second against E5's.
fn with_vs_e5(t2_m: &mut [SceneRecord]) {
    let e5: Vec<(u32, f64)> = t2_m
        .iter()
        .filter(|r| r.experiment == "E5")
        .filter_map(|r| r.fps.map(|f| (r.size, f)))
        .collect();
    for r in t2_m.iter_mut() {
        if let (Some(f), Some(&(_, cpu))) = (r.fps, e5.iter().find(|(n, _)| *n == r.size)) {
            r.vs_e5 = Some(f / cpu);
        }
    }
}

/// Writes each table's medians as JSON and markdown; the files written.
fn write_medians(
    out: &Path,
    st_m: &[StepRecord],
    t1_m: &[SortRecord],
    t2_m: &[SceneRecord],
    rp_m: &[PathRecord],
) -> Result<Vec<std::path::PathBuf>> {
    let mut files = Vec::new();
    let mut write = |name: &str, json_text: Result<()>, md: String| -> Result<()> {
        json_text?;
        let m = out.join(format!("{name}.md"));
        super::write_atomic(&m, md.as_bytes())?;
        files.push(out.join(format!("{name}.json")));
        files.push(m);
        Ok(())
    };
    write(
        "step",
        super::write_json(&out.join("step.json"), st_m),
        step_markdown(st_m),
    )?;
    write(
        "table1_sort",
        super::write_json(&out.join("table1_sort.json"), t1_m),
        sort_markdown(t1_m),
    )?;
    write(
        "table2_scenes",
        super::write_json(&out.join("table2_scenes.json"), t2_m),
        bs::markdown(t2_m),
    )?;
    write(
        "render_paths",
        super::write_json(&out.join("render_paths.json"), rp_m),
        paths_markdown(rp_m),
    )?;
    Ok(files)
}

/// A warning for each Table 2 cell that was not measured.
fn unmeasured(t2_m: &[SceneRecord]) -> Vec<String> {
    let mut warnings = Vec::new();
    for r in t2_m.iter().filter(|r| r.fps.is_none()) {
        warnings.push(format!(
            "Table 2: {} at {}² was not measured{}",
            r.experiment,
            r.size,
            r.note
                .as_deref()
                .map(|n| format!(" ({n})"))
                .unwrap_or_default()
        ));
    }
    warnings
}

/// How the tables were run, with the cells whose runs spread (several runs only).
fn runs_note(runs: usize, noisy: &[String]) -> String {
    if runs > 1 {
        format!(
            "## How the benchmark tables were run\n\nEach table was run {runs} times, interleaved; every cell is the run of median time \
             (all runs: `tables_runs.json`). {}\n\n",
            if noisy.is_empty() {
                "No cell's slowest run took over 1.25× its fastest.".to_owned()
            } else {
                format!(
                    "Cells whose slowest run took over 1.25× their fastest: {}.",
                    noisy.join("; ")
                )
            }
        )
    } else {
        String::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_runs_takes_each_cells_middle_run() {
        // (cell, ms): cell 1's median is the 5.0 run, cell 2's the 3.0 one (no time sorts last).
        let runs = vec![
            vec![(1, Some(9.0)), (2, Some(3.0))],
            vec![(1, Some(5.0)), (2, None)],
            vec![(1, Some(4.0)), (2, Some(2.0))],
        ];
        let (m, spread) = median_of_runs(&runs, |r| r.0, |r| r.1);
        assert_eq!(m, vec![(1, Some(5.0)), (2, Some(3.0))]);
        // Cell 1 spans 4 to 9 ms, cell 2 2 to 3 ms: both over 1.25.
        assert_eq!(spread.len(), 2);
        assert!((spread[0].1 - 2.25).abs() < 1e-12);
        let (one, none) = median_of_runs(&runs[..1], |r| r.0, |r| r.1);
        assert_eq!(one, runs[0]);
        assert!(none.is_empty());
    }
}
