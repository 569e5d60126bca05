//! `texflow render`: simulate a scene and write PNG frames, an animation (`--video`), or both.

use std::path::PathBuf;

use std::ops::ControlFlow;

use clap::Args;
use texflow::engine::{
    Event, FolderSink, FrameLoop, FrameSink, LoopOptions, LoopSummary, NonFinitePolicy, StateDump,
};

use super::overrides::Overrides;
use texflow::gl::Context;
use texflow::output::{video, FrameWriter, VideoWriter};
use texflow::scene;
use texflow::EngineKind;

use super::video_loop::LoopedVideo;
use super::{at_least_one, bad, parse_size, progress_bar, signals, targets, time_step, Common};

/// `--engine`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum EngineArg {
    /// The GPU engine.
    Gpu,
    /// The CPU engine (E5).
    Cpu,
}

impl From<EngineArg> for EngineKind {
    fn from(e: EngineArg) -> EngineKind {
        match e {
            EngineArg::Gpu => EngineKind::Gpu,
            EngineArg::Cpu => EngineKind::Cpu,
        }
    }
}

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct RenderArgs {
    /// The scene: a built-in name or a .toml scene file.
    #[arg(help = super::scene_help("render", ""), default_value = scene::DEFAULT_SCENE)]
    scene: String,
    /// Number of frames to simulate.
    #[arg(long, value_name = "N", default_value_t = 60, value_parser = at_least_one::<u64>)]
    frames: u64,
    /// Output folder of PNG frames (created if missing). Default: `frames`, unless --video is
    /// given, which then writes the only output.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Also (or only) write the frames as one animation: .gif, .png (APNG), .mp4 or .webm (the
    /// last two through an `ffmpeg` on PATH). One video frame per written frame (--every).
    #[arg(long, value_name = "FILE")]
    video: Option<PathBuf>,
    /// Frames a second of the video. Default: real time, 1 / (dt × substeps × every).
    #[arg(long, value_parser = super::positive_finite, requires = "video")]
    fps: Option<f32>,
    /// Make the video loop without a seam: its last F written frames are cross-faded into its
    /// first F (the video holds F frames fewer than were written).
    #[arg(
        long = "loop",
        value_name = "F",
        default_value_t = 0,
        requires = "video"
    )]
    loop_fade: u64,
    /// State texture size WxH (one particle per texel), or N for NxN [default: the scene's
    /// particles.size]. Below the scene's count the point size grows by sqrt(own / new), up to
    /// 64 px, so the frame stays covered (not with [collisions], [fluid] or surfaces).
    #[arg(long, value_parser = parse_size, value_name = "WxH")]
    particles: Option<[u32; 2]>,
    /// Frame size WxH in pixels, or N for NxN [default: the scene's render.resolution].
    #[arg(long, value_parser = parse_size, value_name = "WxH")]
    resolution: Option<[u32; 2]>,
    /// Random seed (same seed, same device: same frames).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// The engine: `gpu` (the papers' fragment passes) or `cpu` (UberFlow's E5: the same
    /// physics on every core, a quicksort, points uploaded every frame; explicit integrators,
    /// time-stamp and initial emitters, points only).
    #[arg(long, value_enum, default_value = "gpu")]
    engine: EngineArg,
    /// Simulation time step in seconds [default: the scene's time.dt].
    #[arg(long, value_name = "SECONDS", value_parser = time_step, allow_hyphen_values = true)]
    dt: Option<f32>,
    /// Simulation steps per frame [default: the scene's time.substeps].
    #[arg(long, value_name = "N", value_parser = at_least_one::<u32>)]
    substeps: Option<u32>,
    /// Write every K-th frame (frames keep their index in the name).
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = at_least_one::<u64>)]
    every: u64,
    /// First frame to write: the frames before it are simulated, not written (a video that
    /// skips the build-up). Frames keep their index.
    #[arg(long, value_name = "N", default_value_t = 0)]
    start: u64,
    /// Drop the scene's collisions between particles (to compare, UberFlow Fig. 4 right).
    #[arg(long)]
    no_collisions: bool,
    /// Also write the live particles' positions and velocities as .npy (N×4 float32) into DIR.
    #[arg(long, value_name = "DIR")]
    dump_state: Option<PathBuf>,
    /// Dump every K-th frame.
    #[arg(long, default_value_t = 1, value_parser = at_least_one::<u64>)]
    dump_every: u64,
    /// After the run, print one paragraph with the median time of each phase (simulate, sort,
    /// draw), fps and particles per second, like CUDA's `particles -benchmark`; timing waits for
    /// the GPU after each phase. `texflow bench scene` adds floors.
    #[arg(long)]
    stats: bool,
    /// Print the run's summary as JSON on stdout (frames, steps, births dropped, non-finite
    /// counts, and the phase times with --stats).
    #[arg(long)]
    json: bool,
    /// Write the frames even when the state turns NaN or infinite (by default the run stops
    /// there with exit code 3; see docs/reliability.md).
    #[arg(long)]
    allow_non_finite: bool,
    #[command(flatten)]
    set: super::set::SetArgs,
    #[command(flatten)]
    compare: super::compare::CompareArgs,
    #[command(flatten)]
    common: Common,
}

impl RenderArgs {
    /// The scene overrides these options carry.
    pub fn overrides(&self) -> Overrides {
        Overrides {
            particles: self.particles,
            resolution: self.resolution,
            dt: self.dt,
            substeps: self.substeps,
            no_collisions: self.no_collisions,
            seed: self.seed,
            device: self.common.device,
            set: self.set.set.clone(),
        }
    }
}

/// Refuses loop options that would run or write nothing, by the option the user typed (the
/// library names LoopOptions' fields).
fn check_loop(options: &LoopOptions) -> texflow::Result<()> {
    match options.problem() {
        Some((field, reason)) => Err(bad(format!(
            "--{} {} {reason}",
            field.replace('_', "-"),
            options.value_of(field)
        ))),
        None => Ok(()),
    }
}

pub fn render(a: RenderArgs) -> texflow::Result<()> {
    // Everything that can be checked without a GPU is checked before anything is created.
    let golden = a.compare.prepare(a.frames)?;
    let user_dumps = a.dump_state.as_ref().map(|_| a.dump_every);
    let options = loop_options(&a, golden.as_ref().map(|g| g.frame()), user_dumps);
    check_loop(&options)?;
    super::video_loop::check(a.loop_fade, options.written_count())?;
    let overrides = a.overrides();
    let prepared = overrides.prepare(&a.scene)?;
    let s = &prepared.scene;
    let out = match (&a.out, &a.video) {
        (Some(o), _) => Some(o.clone()),
        (None, None) => Some(PathBuf::from("frames")),
        (None, Some(_)) => None,
    };
    if let Some(o) = &out {
        FrameWriter::check(o)?;
    }
    let (count, fps) = check_outputs(&a, s, options.written_count())?;
    // Every output against every input and every other output, and every frame target.
    let mut inputs = targets::inputs(&prepared.label, s);
    inputs.extend(a.compare.inputs());
    let plan = targets::Plan {
        frames: a.frames,
        every: a.every,
        dump_every: a.dump_every,
        out: out.as_deref(),
        dumps: a.dump_state.as_deref(),
        video: a.video.as_deref(),
        inputs: &inputs,
    };
    plan.check()?;
    let ctx = Context::new(overrides.device)?;
    overrides.check_device(&ctx, &prepared)?;
    let mut engine = texflow::engine::build(&ctx, s, overrides.seed, a.engine.into())?;
    let run = FrameLoop::new(&ctx, engine.as_ref(), options.clone())?;
    // The video first: should its encoder fail to start, no folder has been made yet.
    let video = match &a.video {
        Some(v) => {
            let writer = VideoWriter::create(v, s.render.resolution, count, fps)?;
            Some(LoopedVideo::new(
                writer,
                options.written_count(),
                a.loop_fade,
            ))
        }
        None => None,
    };
    // With --video alone, a folder sink still writes the dumps (into --dump-state; no frames).
    let folder = match out.as_deref().or(a.dump_state.as_deref()) {
        Some(dir) => Some(FolderSink::create_named(
            dir,
            a.dump_state.as_deref(),
            "--dump-state",
        )?),
        None => None,
    };
    // What a killed run left in these folders (its own temporary files only) goes now.
    plan.remove_stale();
    let mut sink = RenderSink {
        folder,
        pngs: out.is_some(),
        video,
        user_dumps,
        golden,
    };
    let bar = progress_bar(a.frames, a.common.quiet, "rendering");
    // SIGINT and SIGTERM stop the loop between frames (src/cli/signals.rs).
    signals::cooperate();
    let summary = run.run(engine.as_mut(), &mut sink, |event| on_event(&bar, s, event));
    // A signal may have ended the encoder under a frame being written: the signal is the
    // reason, not the broken pipe it left.
    let summary = match (summary, signals::received()) {
        (Err(_), Some(signal)) => {
            drop(sink);
            texflow::output::remove_unfinished();
            return Err(texflow::Error::Interrupted { signal });
        }
        (r, _) => r?,
    };
    bar.finish_and_clear();
    let video_path = finish_video(&mut sink, &summary)?;
    if let Some(g) = &sink.golden {
        let line = g.verdict()?;
        if !a.common.quiet {
            eprintln!("{line}");
        }
    }
    report(&a, s, &ctx, &summary, out.as_deref(), video_path.as_deref());
    Ok(())
}

/// The video finished, unless a signal or an early stop ended the run (dropped unfinished, its
/// temporary file is removed); a signal is the reason for any failure, and ends the command.
fn finish_video(sink: &mut RenderSink, summary: &LoopSummary) -> texflow::Result<Option<PathBuf>> {
    let video_path = match sink.video.take() {
        Some(v) if signals::received().is_none() && !summary.stopped => Some(v.finish()),
        _ => None,
    };
    // A signal while the encoder finished (and was killed) is the reason it failed.
    let video_path = match (video_path, signals::received()) {
        (Some(Err(_)), Some(signal)) => {
            texflow::output::remove_unfinished();
            return Err(texflow::Error::Interrupted { signal });
        }
        (v, _) => v.transpose()?,
    };
    if let Some(signal) = signals::received() {
        texflow::output::remove_unfinished();
        return Err(texflow::Error::Interrupted { signal });
    }
    Ok(video_path)
}

/// The frame loop's options from the command line.
fn loop_options(a: &RenderArgs, golden_frame: Option<u64>, user_dumps: Option<u64>) -> LoopOptions {
    LoopOptions {
        frames: a.frames,
        every: a.every,
        start: a.start,
        dump_every: dump_every(user_dumps, golden_frame, a.frames),
        non_finite: if a.allow_non_finite {
            NonFinitePolicy::Report
        } else {
            NonFinitePolicy::Fail
        },
        timing: a.stats,
    }
}

/// Before the run: a missing ffmpeg, an unwritable --video or a video the format cannot hold
/// stops here, not after the frames (outputs against inputs: [`targets::Plan::check`]). The
/// video's frame count and rate.
fn check_outputs(
    a: &RenderArgs,
    s: &scene::SceneFile,
    written: u64,
) -> texflow::Result<(u64, f64)> {
    let count = LoopedVideo::length(written, a.loop_fade);
    let fps = a
        .fps
        .map(f64::from)
        .unwrap_or_else(|| 1.0 / (s.time.dt as f64 * s.time.substeps as f64 * a.every as f64));
    if let Some(v) = &a.video {
        video::check_video_run(v, s.render.resolution, count, fps)?;
    }
    if let Some(d) = &a.dump_state {
        FrameWriter::check_for(d, "--dump-state")?;
    }
    Ok((count, fps))
}

/// Progress and warnings while the loop runs; stops between frames on SIGINT and SIGTERM.
fn on_event(
    bar: &indicatif::ProgressBar,
    s: &scene::SceneFile,
    event: Event<'_>,
) -> ControlFlow<()> {
    match event {
        Event::Frame { .. } => bar.inc(1),
        Event::NonFinite { index, count } => bar.suspend(|| {
            eprintln!(
                "warning: frame {index}: {} of {} live particles have NaN or infinite values",
                count.non_finite, count.live
            )
        }),
        Event::Stretched { index, count } => bar.suspend(|| {
            eprintln!(
                "warning: frame {index}: {} of {} constraints are stretched past {} % of their \
                 rest length (raise [constraints] iterations or shorten [time] dt; later frames \
                 count in --json's max_stretched_edges)",
                count.edges,
                count.constraints,
                100.0 * count.bound
            )
        }),
        Event::BirthsDropped { index, total } => {
            bar.suspend(|| eprintln!("{}", super::warn::births_dropped(s, index, total)))
        }
    }
    match signals::received() {
        Some(_) => ControlFlow::Break(()),
        None => ControlFlow::Continue(()),
    }
}

/// What the run did: warnings, the line naming what was written, --stats and --json.
fn report(
    a: &RenderArgs,
    s: &scene::SceneFile,
    ctx: &Context,
    summary: &LoopSummary,
    out: Option<&std::path::Path>,
    video_path: Option<&std::path::Path>,
) {
    if summary.max_non_finite > 0 {
        eprintln!(
            "warning: up to {} live particle(s) had NaN or infinite values \
             ({} written frame(s) affected; the dumps, if any, hold them)",
            summary.max_non_finite, summary.non_finite_frames
        );
    }
    if summary.dropped_child_births > 0 {
        eprintln!(
            "{}",
            super::warn::child_births_dropped(s, summary.dropped_child_births)
        );
    }
    if summary.truncated_searches > 0 {
        eprintln!(
            "{}",
            super::warn::searches_truncated(s, summary.truncated_searches, summary.steps)
        );
    }
    if summary.truncated_bounces > 0 {
        eprintln!(
            "{}",
            super::warn::bounces_truncated(summary.truncated_bounces, summary.steps)
        );
    }
    if !a.common.quiet {
        let mut to: Vec<String> = out.iter().map(|o| o.display().to_string()).collect();
        to.extend(video_path.iter().map(|v| v.display().to_string()));
        let dropped = match summary.dropped_births {
            0 => String::new(),
            n => format!(", {n} births dropped: the state texture was full"),
        };
        let dropped = match summary.dropped_child_births {
            0 => dropped,
            n => format!("{dropped}, {n} child births dropped"),
        };
        eprintln!(
            "wrote {} frame(s) of {}x{} to {} ({} particles, {} steps of {} s{dropped})",
            summary.written,
            s.render.resolution[0],
            s.render.resolution[1],
            to.join(" and "),
            s.particle_count(),
            summary.steps,
            s.time.dt
        );
    }
    // With --json, stdout holds the JSON document alone; the paragraph goes to stderr.
    if a.stats && a.json {
        eprintln!("{}", stats_paragraph(s, &a.scene, summary));
    } else if a.stats {
        println!("{}", stats_paragraph(s, &a.scene, summary));
    }
    if a.json {
        let t = summary.times.as_ref();
        let body = serde_json::json!({
            "scene": s.name,
            "particles": s.particle_count(),
            "live": summary.live,
            "resolution": s.render.resolution,
            "frames": summary.frames,
            "written": summary.written,
            "dumps": summary.dumps,
            "steps": summary.steps,
            "dt": s.time.dt,
            "dropped_births": summary.dropped_births,
            "dropped_child_births": summary.dropped_child_births,
            "truncated_searches": summary.truncated_searches,
            "truncated_bounces": summary.truncated_bounces,
            "max_non_finite": summary.max_non_finite,
            "non_finite_frames": summary.non_finite_frames,
            "max_stretched_edges": summary.max_stretched,
            "stretched_frames": summary.stretched_frames,
            "median_ms": t.map(|t| {
                let [sim, sort, draw] = t.medians();
                serde_json::json!({ "simulate": sim, "sort": sort, "draw": draw })
            }),
        });
        let mut body = body;
        add_fluid(&mut body, summary);
        let clock = t.map(|t| t.clock);
        let v = texflow::bench::json_envelope("texflow.render/1", ctx, clock, &body);
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    }
}

/// With `[fluid]`: each written frame's density error and energy, as `fluid` in `--json`.
fn add_fluid(body: &mut serde_json::Value, summary: &LoopSummary) {
    if !summary.fluid.is_empty() {
        body["fluid"] = (summary.fluid.iter())
            .map(|(frame, f)| {
                let mut v = serde_json::json!(f);
                v["frame"] = serde_json::json!(frame);
                v
            })
            .collect();
    }
}

/// The one-paragraph summary of `render --stats`; `given` is the scene as typed (a name or a
/// file), which the closing hint repeats.
fn stats_paragraph(s: &texflow::scene::SceneFile, given: &str, summary: &LoopSummary) -> String {
    let Some(t) = &summary.times else {
        return String::new();
    };
    let [sim, sort, draw] = t.medians();
    // A frame that is written costs all three; one that is not, the first two.
    let frame = sim + sort + if draw.is_nan() { 0.0 } else { draw };
    let particles = s.particle_count() as f64;
    format!(
        "texflow render, scene {}: {} frames of {} particles ({} live at the last written \
         frame), {}x{} frame, {} step(s) of {} s per frame; median simulate {sim:.3} ms, sort \
         {sort:.3} ms, draw and read back {draw:.3} ms: {frame:.3} ms = {:.1} fps, {:.4} M \
         particles/s ({}). Floors per phase: texflow bench scene {}",
        s.name,
        summary.frames,
        s.particle_count(),
        summary.live,
        s.render.resolution[0],
        s.render.resolution[1],
        s.time.substeps,
        s.time.dt,
        1e3 / frame,
        particles * 1e-3 / frame,
        t.clock.name(),
        given
    )
}

/// The frames of `render`: PNGs in a folder, an animation, or both.
struct RenderSink {
    folder: Option<FolderSink>,
    /// Whether the folder sink takes the frames too (not only the dumps).
    pngs: bool,
    video: Option<LoopedVideo>,
    /// --dump-every when --dump-state is given: the dumps the folder receives.
    user_dumps: Option<u64>,
    /// The reference of --compare, which takes the dump of its frame.
    golden: Option<super::compare::Golden>,
}

/// The loop's dump period: every frame the folder wants (--dump-every) and the frame --compare
/// needs are multiples of it (their greatest common divisor); `None` when neither asks.
fn dump_every(user: Option<u64>, compare: Option<u64>, frames: u64) -> Option<u64> {
    fn gcd(a: u64, b: u64) -> u64 {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }
    match (user, compare) {
        (None, None) => None,
        (Some(k), None) => Some(k),
        // Frame 0 is dumped whatever the period.
        (None, Some(f)) => Some(if f == 0 { frames } else { f }),
        (Some(k), Some(f)) => Some(gcd(k, f)),
    }
}

impl FrameSink for RenderSink {
    fn frame(&mut self, index: u64, image: &image::RgbImage) -> texflow::Result<()> {
        if let Some(f) = self.folder.as_mut().filter(|_| self.pngs) {
            f.frame(index, image)?;
        }
        if let Some(v) = &mut self.video {
            v.push(image)?;
        }
        Ok(())
    }

    fn dump(&mut self, index: u64, dump: &StateDump) -> texflow::Result<()> {
        if let Some(g) = &mut self.golden {
            g.offer(index, dump);
        }
        match &mut self.folder {
            Some(f) if self.user_dumps.is_some_and(|k| index.is_multiple_of(k)) => {
                f.dump(index, dump)
            }
            _ => Ok(()),
        }
    }
}
