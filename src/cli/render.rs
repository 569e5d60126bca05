//! `texflow render`: simulate a scene and write PNG frames, an animation (`--video`), or both.

use std::path::PathBuf;

use std::ops::ControlFlow;

use clap::Args;
use texflow::engine::{
    Event, FolderSink, FrameLoop, FrameSink, LoopOptions, LoopSummary, NonFinitePolicy, Overrides,
    StateDump,
};
use texflow::gl::Context;
use texflow::output::{video, FrameWriter, VideoWriter};
use texflow::scene;
use texflow::SceneEngine;

use super::{at_least_one, bad, parse_size, progress_bar, signals, time_step, Common};

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct RenderArgs {
    /// Scene to render: a built-in name (`texflow scene list`: fire, snow,
    /// fountain, smoke, e1, e2, e3, collide, gas, mesh, cloth, hair) or a .toml scene file.
    #[arg(default_value = scene::DEFAULT_SCENE)]
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
    /// State texture size WxH (one particle per texel), or N for NxN [default: the scene's
    /// particles.size].
    #[arg(long, value_parser = parse_size, value_name = "WxH")]
    particles: Option<[u32; 2]>,
    /// Frame size WxH in pixels, or N for NxN [default: the scene's render.resolution].
    #[arg(long, value_parser = parse_size, value_name = "WxH")]
    resolution: Option<[u32; 2]>,
    /// Random seed (same seed, same device: same frames).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulation time step in seconds [default: the scene's time.dt].
    #[arg(long, value_name = "SECONDS", value_parser = time_step, allow_hyphen_values = true)]
    dt: Option<f32>,
    /// Simulation steps per frame [default: the scene's time.substeps].
    #[arg(long, value_name = "N", value_parser = at_least_one::<u32>)]
    substeps: Option<u32>,
    /// Write every K-th frame (frames keep their index in the name).
    #[arg(long, value_name = "K", default_value_t = 1, value_parser = at_least_one::<u64>)]
    every: u64,
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
        }
    }
}

pub fn render(a: RenderArgs) -> texflow::Result<()> {
    // Everything that can be checked without a GPU is checked before anything is created.
    let options = LoopOptions {
        frames: a.frames,
        every: a.every,
        dump_every: a.dump_state.as_ref().map(|_| a.dump_every),
        non_finite: if a.allow_non_finite {
            NonFinitePolicy::Report
        } else {
            NonFinitePolicy::Fail
        },
        timing: a.stats,
    };
    options.check()?;
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
    // Before the run: a missing ffmpeg or an unwritable --video stops here, not after the frames.
    if let Some(v) = &a.video {
        video::check_video(v)?;
        // The video must not be one of the files the frame folders will hold.
        for (dir, flag) in [(&out, "--out"), (&a.dump_state, "--dump-state")] {
            if let Some(dir) = dir {
                if names_a_frame_file(v, dir) {
                    return Err(bad(format!(
                        "--video {} is a file that {flag} {} will write: give the video another \
                         name or folder",
                        v.display(),
                        dir.display()
                    )));
                }
            }
        }
    }
    if let Some(d) = &a.dump_state {
        FrameWriter::check_for(d, "--dump-state")?;
    }
    let ctx = Context::new(overrides.device)?;
    overrides.check_device(&ctx, &prepared)?;
    let mut engine = SceneEngine::new(&ctx, s, overrides.seed)?;
    let run = FrameLoop::new(&ctx, &engine, options)?;
    // With --video alone, a folder sink still writes the dumps (into --dump-state; no frames).
    let folder = match out.as_deref().or(a.dump_state.as_deref()) {
        Some(dir) => Some(FolderSink::create(dir, a.dump_state.as_deref())?),
        None => None,
    };
    let video = match &a.video {
        Some(v) => {
            let fps = a.fps.map(f64::from).unwrap_or_else(|| {
                1.0 / (s.time.dt as f64 * s.time.substeps as f64 * a.every as f64)
            });
            let count = a.frames.div_ceil(a.every);
            Some(VideoWriter::create(v, s.render.resolution, count, fps)?)
        }
        None => None,
    };
    let mut sink = RenderSink {
        folder,
        pngs: out.is_some(),
        video,
    };
    let bar = progress_bar(a.frames, a.common.quiet, "rendering");
    // SIGINT and SIGTERM stop the loop between frames (src/cli/signals.rs).
    signals::cooperate();
    let summary = run.run(&mut engine, &mut sink, |event| {
        match event {
            Event::Frame { .. } => bar.inc(1),
            Event::NonFinite { index, count } => bar.suspend(|| {
                eprintln!(
                    "warning: frame {index}: {} of {} live particles have NaN or infinite values",
                    count.non_finite, count.live
                )
            }),
            Event::BirthsDropped { index, total } => bar.suspend(|| {
                let hint = match s.capacity_check() {
                    Some(w) => format!(
                        "; a {0}x{0} state texture (--particles {0}) would hold them",
                        w.side
                    ),
                    None => String::new(),
                };
                eprintln!(
                    "warning: frame {index}: the state texture ({}x{}) is full: {total} \
                     birth(s) dropped{hint}",
                    s.particles.size[0], s.particles.size[1]
                )
            }),
        }
        match signals::received() {
            Some(_) => ControlFlow::Break(()),
            None => ControlFlow::Continue(()),
        }
    })?;
    bar.finish_and_clear();
    // Dropped unfinished (signal, early stop), the video's temporary file is removed.
    let video_path = match sink.video.take() {
        Some(v) if signals::received().is_none() && !summary.stopped => Some(v.finish()?),
        _ => None,
    };
    if let Some(signal) = signals::received() {
        texflow::output::remove_unfinished();
        return Err(texflow::Error::Interrupted { signal });
    }
    if summary.max_non_finite > 0 {
        eprintln!(
            "warning: up to {} live particle(s) had NaN or infinite values \
             ({} written frame(s) affected; the dumps, if any, hold them)",
            summary.max_non_finite, summary.non_finite_frames
        );
    }
    if !a.common.quiet {
        let mut to: Vec<String> = out.iter().map(|o| o.display().to_string()).collect();
        to.extend(video_path.iter().map(|v| v.display().to_string()));
        let dropped = match summary.dropped_births {
            0 => String::new(),
            n => format!(", {n} births dropped: the state texture was full"),
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
    if a.stats {
        println!("{}", stats_paragraph(s, &summary));
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
            "max_non_finite": summary.max_non_finite,
            "non_finite_frames": summary.non_finite_frames,
            "median_ms": t.map(|t| {
                let [sim, sort, draw] = t.medians();
                serde_json::json!({ "simulate": sim, "sort": sort, "draw": draw })
            }),
        });
        let clock = t.map(|t| t.clock);
        let v = texflow::bench::json_envelope("texflow.render/1", &ctx, clock, &body);
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    }
    Ok(())
}

/// Whether `video` lies in `dir` (by its canonical folder where both exist) under a name of the
/// frames or dumps written there (`frame_00000.png`, `positions_00000.npy`, ...).
fn names_a_frame_file(video: &std::path::Path, dir: &std::path::Path) -> bool {
    let canon = |p: &std::path::Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let parent = match video.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => std::path::Path::new("."),
    };
    if canon(parent) != canon(dir) {
        return false;
    }
    let name = video
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    ["frame_", "positions_", "velocities_"].iter().any(|p| {
        name.strip_prefix(p).is_some_and(|rest| {
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            !digits.is_empty() && matches!(&rest[digits.len()..], ".png" | ".npy")
        })
    })
}

/// The one-paragraph summary of `render --stats`.
fn stats_paragraph(s: &texflow::scene::SceneFile, summary: &LoopSummary) -> String {
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
        s.name
    )
}

/// The frames of `render`: PNGs in a folder, an animation, or both.
struct RenderSink {
    folder: Option<FolderSink>,
    /// Whether the folder sink takes the frames too (not only the dumps).
    pngs: bool,
    video: Option<VideoWriter>,
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
        match &mut self.folder {
            Some(f) => f.dump(index, dump),
            None => Ok(()),
        }
    }
}
