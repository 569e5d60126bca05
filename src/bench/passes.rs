//! `bench passes`: every pass of one frame, timed draw by draw, next to its floor.
//!
//! `bench scene` times a phase as a whole (the fluid stage is one line: keys, sort, gather,
//! density, force, tally, copy). Here each program the frame draws gets its own line, so the
//! pass that bounds a stage can be named. A frame (the engine's steps, then its sort for drawing
//! and its render) is drawn with the GL layer's [`DrawProfiler`] on: every draw timed alone
//! (a timer query around each on a GPU, `glFinish` on both sides on llvmpipe). The draws are
//! grouped by program and named by the pass list lines that list the program
//! ([`Engine::passes`](crate::engine::Engine::passes)).
//!
//! A pass's floor is the one the collision stage has in `bench scene`: its draws times the fixed
//! cost of a dependent pass, plus the bytes its full-screen draws wrote at the rate of a
//! write-only pass into the state's targets, both measured in the same run. Points and lines
//! (births, tallies) and the render get none: their bytes depend on what they cover (`bench
//! scene` bounds the render).

use crate::bench::stats::{median, FixedCost, PassTimer, WriteFloor};
use crate::engine::Stages;
use crate::error::Result;
use crate::gl::{Clock, Context, DrawProfiler, DrawTime, PassInfo};
use crate::scene::SceneFile;

/// What `bench passes` runs.
#[derive(Debug, Clone)]
pub struct PassesOptions {
    /// Timed frames (the median per pass is reported).
    pub repeats: usize,
    /// Frames run before timing; `None`: one emission cycle, as `bench scene` warms up
    /// ([`warmup_frames`](crate::bench::scene::warmup_frames)).
    pub warmup_frames: Option<usize>,
    /// The clock; `None` picks [`Clock::for_context`].
    pub clock: Option<Clock>,
}

impl Default for PassesOptions {
    fn default() -> Self {
        PassesOptions {
            repeats: 5,
            warmup_frames: None,
            clock: None,
        }
    }
}

/// One program's draws in a frame.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PassTime {
    /// The stage of the first pass list line that lists the program (`unlisted` if none).
    pub stage: String,
    /// The pass list lines that list the program, joined by ` / `.
    pub pass: String,
    /// The program (`vertex+fragment`).
    pub program: String,
    /// The framebuffer it draws into (its label; the two sides of a ping-pong as one).
    pub target: String,
    /// Its draws in a frame (median).
    pub draws: u64,
    /// Its milliseconds in a frame (median of the frames' sums).
    pub ms: f64,
    /// Bytes its full-screen draws wrote in a frame (median).
    pub bytes: u64,
    /// Its floor, ms: draws × the fixed cost + bytes at the write rate; `None` for points and
    /// lines (what they write depends on what they cover).
    pub floor_ms: Option<f64>,
    /// `ms / floor_ms`.
    pub ratio: Option<f64>,
}

/// Every pass of a frame of one scene at one size.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PassesRecord {
    /// The scene's name.
    pub scene: String,
    /// State width and height.
    pub size: [u32; 2],
    /// The clock.
    pub clock: Clock,
    /// Timed frames.
    pub repeats: usize,
    /// A whole frame timed at once, ms (median; frames between the profiled ones).
    pub frame_ms: f64,
    /// The sum of the draws' times of a profiled frame, ms (median): what the table covers of
    /// the frame (the rest: clears, copies, CPU work, and on llvmpipe the waits between draws).
    pub draws_ms: f64,
    /// The fixed cost of a dependent pass, ms.
    pub fixed_ms: f64,
    /// The write rate of a write-only pass into the state's targets, GB/s.
    pub write_gb_s: f64,
    /// The programs, in the order the frame first draws them.
    pub passes: Vec<PassTime>,
}

/// Profiles `repeats` frames of `scene` (state size as given by the scene).
pub fn bench_passes(
    ctx: &Context,
    scene: &SceneFile,
    opts: &PassesOptions,
    mut progress: impl FnMut(),
) -> Result<PassesRecord> {
    let clock = opts.clock.unwrap_or_else(|| Clock::for_context(ctx));
    let timer = PassTimer::new(ctx, clock)?;
    let mut engine = crate::engine::build_gpu(ctx, scene, 1)?;
    let e = engine.as_mut();
    for _ in 0..super::scene::warmup_frames(scene, opts.warmup_frames)? {
        frame(e)?;
    }
    let fixed_cost = FixedCost::new(ctx)?;
    let scratch = super::scene::scratch_like(ctx, e.sim().state_target())?;
    let write = WriteFloor::for_target(ctx, &scratch)?;
    // Drawn once untimed: a new program's first draw pays for its code.
    write.draw(&scratch);
    let scratch_bytes =
        scratch.width() as u64 * scratch.height() as u64 * scratch.bytes_per_texel() as u64;
    let (mut frames, mut fixed, mut writes, mut profiles) = (vec![], vec![], vec![], vec![]);
    for _ in 0..opts.repeats {
        fixed.push(fixed_cost.measure(&timer)?);
        writes.push(timer.time(|| write.draw(&scratch))?);
        let mut ran = Ok(());
        frames.push(timer.time(|| ran = frame(e))?);
        ran?;
        let profiler = DrawProfiler::start(clock);
        frame(e)?;
        profiles.push(profiler.finish()?);
        progress();
    }
    ctx.check_error("bench passes")?;
    let fixed_ms = median(&fixed);
    let write_ms = median(&writes);
    // Bytes per ms of a write-only pass, its fixed cost taken off.
    let rate = scratch_bytes as f64 / (write_ms - fixed_ms).max(1e-9);
    let passes = group(&e.passes(), &profiles, fixed_ms, rate);
    let [w, h] = e.sim().size();
    Ok(PassesRecord {
        scene: scene.name.clone(),
        size: [w, h],
        clock,
        repeats: opts.repeats,
        frame_ms: median(&frames),
        draws_ms: median(
            &profiles
                .iter()
                .map(|p| p.iter().map(|d| d.ms).sum())
                .collect::<Vec<f64>>(),
        ),
        fixed_ms,
        write_gb_s: rate * 1e3 / 1e9,
        passes,
    })
}

/// One frame: the steps, then the sort for drawing and the render.
fn frame(e: &mut dyn Stages) -> Result<()> {
    e.advance_frame()?;
    e.draw()
}

/// The label of a framebuffer without the side of its ping-pong (`state:0` and `state:1`,
/// `blocked sort 0` and `blocked sort 1`).
fn family(label: &str) -> &str {
    match label.rsplit_once([':', ' ']) {
        Some((head, side)) if !side.is_empty() && side.chars().all(|c| c.is_ascii_digit()) => head,
        _ => label,
    }
}

/// The (program, target) pairs of the frames' draws, in first-drawn order, with their medians
/// and floors.
fn group(list: &[PassInfo], frames: &[Vec<DrawTime>], fixed_ms: f64, rate: f64) -> Vec<PassTime> {
    let mut order: Vec<(String, String)> = Vec::new();
    for d in frames.iter().flatten() {
        let key = (d.program.clone(), family(&d.target).to_owned());
        if !order.contains(&key) {
            order.push(key);
        }
    }
    order
        .into_iter()
        .map(|(program, target)| {
            let per_frame = |f: fn(&DrawTime) -> f64| -> f64 {
                let v: Vec<f64> = (frames.iter())
                    .map(|fr| {
                        (fr.iter())
                            .filter(|d| d.program == program && family(&d.target) == target)
                            .map(f)
                            .sum()
                    })
                    .collect();
                median(&v)
            };
            let ms = per_frame(|d| d.ms);
            let draws = per_frame(|_| 1.0).round() as u64;
            let bytes = per_frame(|d| d.bytes as f64).round() as u64;
            let lines: Vec<&PassInfo> = (list.iter())
                .filter(|p| p.draws.iter().any(|(name, _)| *name == program))
                .collect();
            let mut names: Vec<&str> = Vec::new();
            for p in &lines {
                if !names.contains(&p.name.as_str()) {
                    names.push(&p.name);
                }
            }
            let stage = lines.first().map_or("unlisted", |p| p.stage);
            // Full-screen state passes only: the render's triangles cover what they cover.
            let floor_ms = (bytes > 0 && stage != "render")
                .then(|| draws as f64 * fixed_ms + bytes as f64 / rate);
            PassTime {
                stage: stage.to_owned(),
                pass: names.join(" / "),
                program,
                target,
                draws,
                ms,
                bytes,
                floor_ms,
                ratio: floor_ms.map(|f| ms / f.max(1e-12)),
            }
        })
        .collect()
}

/// The record as a Markdown table, with the frame's totals above it.
pub fn passes_markdown(r: &PassesRecord) -> String {
    let mut s = format!(
        "{} at {}x{} ({} particles): medians of {} frames; a whole frame {:.3} ms, its draws \
         timed one by one {:.3} ms; fixed cost of a pass {:.4} ms, write rate {:.1} GB/s\n\n",
        r.scene,
        r.size[0],
        r.size[1],
        r.size[0] as u64 * r.size[1] as u64,
        r.repeats,
        r.frame_ms,
        r.draws_ms,
        r.fixed_ms,
        r.write_gb_s
    );
    s.push_str(
        "| stage | pass | program | target | draws | ms | share | MB written | floor ms | ratio |\n",
    );
    s.push_str("|---|---|---|---|---:|---:|---:|---:|---:|---:|\n");
    for p in &r.passes {
        let (floor, ratio) = match (p.floor_ms, p.ratio) {
            (Some(f), Some(q)) => (format!("{f:.3}"), super::stats::ratio_cell(q)),
            _ => ("–".to_owned(), "–".to_owned()),
        };
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {:.3} | {:.1} % | {:.1} | {floor} | {ratio} |\n",
            p.stage,
            p.pass,
            p.program,
            p.target,
            p.draws,
            p.ms,
            100.0 * p.ms / r.draws_ms.max(1e-12),
            p.bytes as f64 / 1e6,
        ));
    }
    s
}
