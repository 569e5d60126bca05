//! The benchmark tables on this device: the fire's step against its floors (`texflow bench
//! step`), UberFlow's Table 1 (`texflow bench sort`: every sort variant against its floor and
//! the CPU) and Table 2 (`texflow bench scenes`: E1-E5 frames per second), with the paper's
//! figures beside the measured ones. The full run uses the sizes of the docs (the step up to
//! 2048², Table 1 up to 1024², and 2048² on a hardware GPU, where a sort of 4 M entries takes
//! milliseconds rather than seconds); `--quick` measures 64² and 128² only.

use std::path::{Path, PathBuf};

use super::{Progress, ReportOptions, SectionOutput, Size};
use crate::bench::{bench_sort, bench_step, sort_markdown, step_markdown, Clock};
use crate::bench::{SortBenchOptions, SortRecord, StepOptions, StepRecord};
use crate::bench_scenes::{self as bs, SceneRecord, ScenesOptions};
use crate::error::{Error, Result};
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

fn json<T: serde::Serialize>(path: &Path, v: &T) -> Result<()> {
    super::write_atomic(
        path,
        serde_json::to_string_pretty(v)
            .map_err(|e| Error::InvalidInput(format!("serialising the report: {e}")))?
            .as_bytes(),
    )
}

/// Runs the fire's step benchmark and writes `step.json` and `step.md`.
pub fn step(
    ctx: &Context,
    size: Size,
    out: &Path,
    progress: Progress<'_>,
) -> Result<(Vec<StepRecord>, Vec<PathBuf>)> {
    let (sizes, repeats) = step_sizes(size);
    let opts = StepOptions {
        repeats,
        ..StepOptions::default()
    };
    let records = bench_step(ctx, &crate::scene::fire(), &sizes, &opts, |n| {
        progress(&format!("step: fire at {n}²"))
    })?;
    let (j, m) = (out.join("step.json"), out.join("step.md"));
    json(&j, &records)?;
    super::write_atomic(&m, step_markdown(&records).as_bytes())?;
    Ok((records, vec![j, m]))
}

/// Runs Table 1 and writes `table1_sort.json` and `table1_sort.md`.
pub fn table1(
    ctx: &Context,
    size: Size,
    out: &Path,
    progress: Progress<'_>,
) -> Result<(Vec<SortRecord>, Vec<PathBuf>)> {
    let clock = Clock::for_context(ctx);
    let (sizes, repeats) = sort_sizes(size, clock);
    let opts = SortBenchOptions {
        repeats,
        clock: None,
        cpu: true,
        steps_per_pass: 2,
    };
    let records = bench_sort(ctx, &sizes, &Variant::ALL, &opts, |v, n| {
        progress(&format!("Table 1: {v} at {n}²"))
    })?;
    let (j, m) = (out.join("table1_sort.json"), out.join("table1_sort.md"));
    json(&j, &records)?;
    super::write_atomic(&m, sort_markdown(&records).as_bytes())?;
    Ok((records, vec![j, m]))
}

/// Runs Table 2 and writes `table2_scenes.json` and `table2_scenes.md`.
pub fn table2(
    ctx: &Context,
    size: Size,
    out: &Path,
    progress: Progress<'_>,
) -> Result<(Vec<SceneRecord>, Vec<PathBuf>)> {
    let (sizes, repeats, warmup) = scene_sizes(size);
    let opts = ScenesOptions {
        repeats,
        warmup_frames: warmup,
        ..ScenesOptions::default()
    };
    let records = bs::bench_scenes(ctx, &sizes, &opts, |e, n| {
        progress(&format!("Table 2: {e} at {n}²"))
    })?;
    let (j, m) = (out.join("table2_scenes.json"), out.join("table2_scenes.md"));
    json(&j, &records)?;
    super::write_atomic(&m, bs::markdown(&records).as_bytes())?;
    Ok((records, vec![j, m]))
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

/// Times E1's draw by both render paths at Table 2's sizes; writes `render_paths.json` and
/// `render_paths.md`.
pub fn render_paths(
    ctx: &Context,
    size: Size,
    out: &Path,
    progress: Progress<'_>,
) -> Result<(Vec<PathRecord>, Vec<PathBuf>)> {
    use crate::scene::file::RenderPath;
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
            let mut engine = crate::engine::ParticleEngine::new(ctx, &scene, 1)?;
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
            live = engine
                .sim()
                .read_positions()?
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
    let mut md = String::from(
        "| state | live | vertex texture fetch ms | vertex buffer ms | buffer / fetch |\n\
         |---|---:|---:|---:|---:|\n",
    );
    for r in &records {
        md.push_str(&format!(
            "| {0}² | {1} | {2:.3} | {3:.3} | {4:.2} |\n",
            r.size, r.live, r.texture_fetch_ms, r.vertex_buffer_ms, r.ratio
        ));
    }
    let (j, m) = (out.join("render_paths.json"), out.join("render_paths.md"));
    json(&j, &records)?;
    super::write_atomic(&m, md.as_bytes())?;
    Ok((records, vec![j, m]))
}

/// `report all`'s section: the benchmark tables.
pub fn section(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<SectionOutput> {
    let clock = Clock::for_context(ctx);
    let (st, mut files) = step(ctx, opts.size, out, progress)?;
    let (t1, f1) = table1(ctx, opts.size, out, progress)?;
    files.extend(f1);
    let (t2, f2) = table2(ctx, opts.size, out, progress)?;
    files.extend(f2);
    let (_, f3) = render_paths(ctx, opts.size, out, progress)?;
    let paths_md = std::fs::read_to_string(&f3[1]).map_err(|source| Error::Io {
        path: f3[1].clone(),
        source,
    })?;
    files.extend(f3);
    let (_, repeats0) = step_sizes(opts.size);
    let (_, repeats1) = sort_sizes(opts.size, clock);
    let (_, repeats2, warmup) = scene_sizes(opts.size);
    let mut warnings = Vec::new();
    for r in t2.iter().filter(|r| r.fps.is_none()) {
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
    let markdown = format!(
        "## The fire's step against its floor (`texflow bench step`)\n\n\
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
        step_markdown(&st),
        clock.name(),
        sort_markdown(&t1),
        match warmup {
            Some(w) => format!("{w} warm-up frames"),
            None => "a full emission cycle".into(),
        },
        clock.name(),
        bs::markdown(&t2),
        clock.name(),
        paths_md
    );
    Ok(SectionOutput {
        files,
        markdown,
        warnings,
    })
}
