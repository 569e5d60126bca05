//! The texflow command line: argument types and printing over the library. `src/main.rs` only
//! dispatches; everything a test or an example would need lives in the library.

pub mod bench;
pub mod bench_passes;
pub mod collide;
pub mod compare;
pub mod diff;
pub mod info;
pub mod overrides;
pub mod render;
pub mod report;
pub mod scene;
pub mod set;
pub mod signals;
pub mod sort;
pub mod targets;
pub mod trace;
pub mod video_loop;
pub mod view;
pub mod warn;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use texflow::bench::Clock;
use texflow::Error;

#[derive(Parser)]
#[command(
    name = "texflow",
    version,
    about = "The 2004 GPU particle engines, headless on EGL"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// List the EGL devices with their renderer, GL version and limits.
    #[command(allow_negative_numbers = true)]
    Info {
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Simulate a scene and write PNG frames.
    Render(render::RenderArgs),
    /// Show a scene live in a window (X11 or Wayland): drag orbits, wheel zooms, space pauses,
    /// `.` steps, `r` restarts; a scene file is reloaded when it changes.
    View(view::ViewArgs),
    /// Sort float32 keys from a .npy file on the GPU.
    Sort(sort::SortArgs),
    /// Draw a frame of a scene, or a sort of random keys, pass by pass: each pass's output
    /// textures as PNGs and an index.md (`texflow trace sort` adds an animated GIF).
    Trace(trace::TraceArgs),
    /// How well the GPU finds colliding pairs: UberFlow's detection against a CPU reference.
    CollideStats(collide::CollideStatsArgs),
    /// Check scene files and list the passes a scene runs.
    #[command(subcommand)]
    Scene(scene::SceneCommand),
    /// How far two frames are apart: mean and largest channel difference, changed pixels, PSNR
    /// (e.g. a frame sorted with compact entries against the exact sort's).
    Diff(diff::DiffArgs),
    /// Benchmarks (GPU timer queries, medians, floors measured in the same run).
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// The papers' tables and every measurement of docs/reproduction.md: sorts, scenes, error
    /// against run time, stability, collisions (PNG plots, CSV, JSON, summary.md).
    #[command(subcommand)]
    Report(report::ReportCommand),
}

#[derive(Args)]
pub struct Common {
    /// EGL device index (see `texflow info`).
    #[arg(long, value_name = "N", default_value_t = 0)]
    device: usize,
    /// Hide the progress bar and the closing "wrote ..." line on stderr; results on stdout,
    /// warnings and errors still print.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum ClockArg {
    Auto,
    Gpu,
    Wall,
}

impl ClockArg {
    fn clock(self) -> Option<Clock> {
        match self {
            ClockArg::Auto => None,
            ClockArg::Gpu => Some(Clock::Gpu),
            ClockArg::Wall => Some(Clock::Wall),
        }
    }
}

/// The help of a scene argument: `verb` and the built-in names, read from the scene registry
/// so that a new built-in scene needs no edit here.
pub fn scene_help(verb: &str, more: &str) -> String {
    format!(
        "Scene to {verb}: a built-in name (`texflow scene list`: {}) or a .toml scene file{more}.",
        texflow::scene::BUILTIN.join(", ")
    )
}

/// Parses `WxH` or `N`; both sides at least 1.
pub fn parse_size(s: &str) -> Result<[u32; 2], String> {
    let parse = |t: &str| {
        t.trim()
            .parse::<u32>()
            .map_err(|_| format!("`{s}` is not a size: use WxH, e.g. 512x512, or N for NxN"))
    };
    let size = match s.split_once(['x', 'X']) {
        Some((w, h)) => [parse(w)?, parse(h)?],
        None => {
            let n = parse(s)?;
            [n, n]
        }
    };
    if size[0] == 0 || size[1] == 0 {
        return Err(format!(
            "size `{s}` is empty: both sides must be at least 1"
        ));
    }
    Ok(size)
}

/// Parses a time step: a positive, finite number of seconds.
pub fn time_step(s: &str) -> Result<f32, String> {
    positive_finite(s).map_err(|e| format!("{e}; a time step is a positive number of seconds"))
}

/// Parses a positive, finite number (lengths).
pub fn positive_finite(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) => Err(format!(
            "{v} is not allowed: give a positive, finite number (e.g. 0.01)"
        )),
        Err(_) => Err(format!(
            "`{s}` is not a number: give a positive, finite number"
        )),
    }
}

/// Parses a count of at least 1 (negative numbers get this message too, not clap's).
pub fn at_least_one<T: TryFrom<i128>>(s: &str) -> Result<T, String> {
    match s.trim().parse::<i128>() {
        Ok(v) if v >= 1 => T::try_from(v).map_err(|_| format!("{v} is too large")),
        Ok(v) => Err(format!(
            "{v} is not allowed: give a whole number of at least 1"
        )),
        Err(_) => Err(format!(
            "`{s}` is not a whole number: give one of at least 1"
        )),
    }
}

/// Prints `body` as the JSON object every command prints (`texflow_version`, `schema`,
/// `device`, `clock`, `records`); `device` is null for commands that use no context.
pub fn print_json<T: serde::Serialize>(schema: &str, ctx: Option<&texflow::gl::Context>, body: &T) {
    let v = match ctx {
        Some(ctx) => texflow::bench::json_envelope(schema, ctx, None, body),
        None => serde_json::json!({
            "texflow_version": env!("CARGO_PKG_VERSION"),
            "schema": schema,
            "device": null,
            "clock": null,
            "records": body,
        }),
    };
    println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
}

pub fn bad(msg: impl Into<String>) -> Error {
    Error::InvalidInput(msg.into())
}

pub fn progress_bar(len: u64, quiet: bool, what: &str) -> ProgressBar {
    if quiet {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} ({elapsed}, eta {eta})")
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    bar.set_message(what.to_owned());
    bar
}

/// `--warmup N`: at most the library's bound, named as the option.
pub fn warmup_frames(s: &str) -> Result<usize, String> {
    let max = texflow::bench::scene::MAX_WARMUP_FRAMES;
    match s.parse::<usize>() {
        Ok(n) if n <= max => Ok(n),
        Ok(n) => Err(format!("{n} frames of warm-up: give at most {max}")),
        Err(e) => Err(format!("{e}: give a whole number of frames, at most {max}")),
    }
}

/// Prints benchmark records as JSON (an object: `texflow_version`, `schema`, `device`, `clock`,
/// `records`), or as a header naming the device and clock and a table.
pub fn report<T: serde::Serialize>(
    json: Option<&str>,
    records: &[T],
    ctx: &texflow::gl::Context,
    clock: Option<texflow::bench::Clock>,
    what: &str,
    table: fn(&[T]),
) {
    if let Some(schema) = json {
        let mut v = texflow::bench::json_envelope(schema, ctx, clock, &records);
        v["what"] = what.into();
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else {
        println!(
            "device {}: {}; {}; {what}",
            ctx.device_index(),
            ctx.limits().renderer,
            clock.map(texflow::bench::Clock::name).unwrap_or_default()
        );
        table(records);
    }
}
