//! The texflow command line: a thin layer over the library.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use texflow::bench::{
    bench_sort, bench_step, Clock, SortBenchOptions, SortRecord, StepOptions, StepRecord,
};
use texflow::gl::{list_devices, Context};
use texflow::render::FrameWriter;
use texflow::sort::{SortOptions, Sorter, Variant};
use texflow::{scene, Error, SceneRunner};

#[derive(Parser)]
#[command(
    name = "texflow",
    version,
    about = "The 2004 GPU particle engines, headless on EGL"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// List the EGL devices with their renderer, GL version and limits.
    Info {
        /// Print JSON instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Simulate a scene and write PNG frames.
    Render(RenderArgs),
    /// Sort float32 keys from a .npy file on the GPU.
    Sort(SortArgs),
    /// How well the GPU finds colliding pairs: UberFlow's detection against a CPU reference.
    CollideStats(CollideStatsArgs),
    /// Check scene files and list the passes a scene runs.
    #[command(subcommand)]
    Scene(SceneCommand),
    /// Benchmarks (GPU timer queries, medians, floors measured in the same run).
    #[command(subcommand)]
    Bench(BenchCommand),
    /// Error against run time, and stability on stiff and extreme cases (docs/numerics.md).
    #[command(subcommand)]
    Report(ReportCommand),
}

#[derive(Args)]
struct CollideStatsArgs {
    /// Scene with a [collisions] section (built-in: collide) or a .toml file.
    #[arg(default_value = "collide")]
    scene: String,
    /// Neighbours fetched to each side in the sorted row (UberFlow: 8).
    #[arg(long)]
    k: Option<u32>,
    /// Second sort and detection on the staggered lattice.
    #[arg(long, value_parser = ["on", "off"])]
    staggered: Option<String>,
    /// Sort only within sets of N consecutive rows (1 = rows only); 0 = the whole texture.
    #[arg(long)]
    rows_only: Option<u32>,
    /// Lattice mesh size g0 in metres (default: the scene's).
    #[arg(long)]
    cell: Option<f32>,
    /// Steps to run; the statistics are taken at the last one.
    #[arg(long, default_value_t = 240)]
    steps: u64,
    /// State texture size WxH, or N for NxN (powers of two).
    #[arg(long, value_parser = parse_size)]
    particles: Option<[u32; 2]>,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Measure with one setting changed at a time (k, staggered, rows-only, cell size) and
    /// print a table.
    #[arg(long)]
    sweep: bool,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    common: Common,
}

#[derive(Subcommand)]
enum SceneCommand {
    /// Validate a scene file (syntax, types, keys, values) without rendering.
    Check {
        /// Scene file (.toml) or built-in name.
        scene: String,
        /// EGL device whose size limits to check against.
        #[arg(long, default_value_t = 0)]
        device: usize,
    },
    /// Print the passes a scene runs per frame.
    Passes {
        /// Scene file (.toml) or built-in name.
        scene: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// List the built-in scenes, or print one's TOML source.
    List {
        /// Print the source of this built-in scene.
        name: Option<String>,
    },
}

#[derive(Args)]
struct SortArgs {
    /// Sort implementation: fp, gpfp, packed (UberFlow), oddeven (Latta), multistep (ours).
    #[arg(long, default_value = "packed")]
    variant: String,
    /// 1-D float32 .npy file of keys (any length up to 2^24).
    #[arg(long)]
    input: PathBuf,
    /// Where to write the sorted keys (1-D float32 .npy).
    #[arg(long)]
    output: PathBuf,
    /// Where to write the sorting permutation: int32 indices into the input (like argsort).
    #[arg(long)]
    ids: Option<PathBuf>,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct RenderArgs {
    /// Scene to render: a built-in name (fire, snow, fountain, smoke, e1, e2, e3, collide) or a
    /// .toml scene file.
    #[arg(default_value = scene::DEFAULT_SCENE)]
    scene: String,
    /// Number of frames to simulate.
    #[arg(long, default_value_t = 60)]
    frames: u64,
    /// Output folder (created if missing).
    #[arg(long, default_value = "frames")]
    out: PathBuf,
    /// State texture size WxH (one particle per texel), or N for NxN.
    #[arg(long, value_parser = parse_size)]
    particles: Option<[u32; 2]>,
    /// Frame size WxH in pixels, or N for NxN.
    #[arg(long, value_parser = parse_size)]
    resolution: Option<[u32; 2]>,
    /// Random seed (same seed, same device: same frames).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulation time step in seconds.
    #[arg(long, allow_negative_numbers = true)]
    dt: Option<f32>,
    /// Simulation steps per frame.
    #[arg(long)]
    substeps: Option<u32>,
    /// Write every K-th frame (frames keep their index in the name).
    #[arg(long, default_value_t = 1)]
    every: u64,
    /// Drop the scene's collisions between particles (to compare, UberFlow Fig. 4 right).
    #[arg(long)]
    no_collisions: bool,
    /// Also write the live particles' positions and velocities as .npy (N×4 float32).
    #[arg(long)]
    dump_state: Option<PathBuf>,
    /// Dump every K-th frame.
    #[arg(long, default_value_t = 1)]
    dump_every: u64,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
struct Common {
    /// EGL device index (see `texflow info`).
    #[arg(long, default_value_t = 0)]
    device: usize,
    /// No progress bar.
    #[arg(long, short)]
    quiet: bool,
}

#[derive(Subcommand)]
enum BenchCommand {
    /// UberFlow's Table 2: fps of whole frames of E1-E5 per state size, next to the paper's.
    Scenes(ScenesArgs),
    /// GPU time of the simulation pass and the render pass per state size, with floors.
    Step {
        /// Scene to measure.
        #[arg(long, default_value = scene::DEFAULT_SCENE)]
        scene: String,
        /// Square state sizes, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "256,512,1024,2048")]
        sizes: Vec<u32>,
        /// Timed repetitions per size (the median is reported).
        #[arg(long, default_value_t = 21)]
        repeats: usize,
        /// Frame size WxH of the render pass.
        #[arg(long, value_parser = parse_size)]
        resolution: Option<[u32; 2]>,
        /// How to time passes: auto (wall time on llvmpipe, timer queries on a GPU), gpu, wall.
        #[arg(long, value_enum, default_value_t = ClockArg::Auto)]
        clock: ClockArg,
        /// Print JSON (one record per size).
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
    /// UberFlow's Table 1: full sorts per variant and size, with floors and CPU baselines.
    Sort {
        /// Texture sides (size x size entries), powers of two, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "128,256,512,1024,2048")]
        sizes: Vec<u32>,
        /// Variants, comma-separated, or `all`.
        #[arg(long, value_delimiter = ',', default_value = "all")]
        variants: Vec<String>,
        /// Timed repetitions per variant and size (the median is reported).
        #[arg(long, default_value_t = 11)]
        repeats: usize,
        /// Skip the CPU baselines.
        #[arg(long)]
        no_cpu: bool,
        /// Steps of distance 2 or more per pass of the multistep variant (1 to 3).
        #[arg(long, default_value_t = 2)]
        steps: usize,
        /// How to time: auto, gpu, wall.
        #[arg(long, value_enum, default_value_t = ClockArg::Auto)]
        clock: ClockArg,
        /// Print JSON (one record per variant and size).
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
}

#[derive(Clone, Copy, clap::ValueEnum)]
enum ClockArg {
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

/// Parses `WxH` or `N`; both sides at least 1.
fn parse_size(s: &str) -> Result<[u32; 2], String> {
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

fn bad(msg: impl Into<String>) -> Error {
    Error::InvalidInput(msg.into())
}

fn progress_bar(len: u64, quiet: bool, what: &str) -> ProgressBar {
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

fn info(json: bool) -> texflow::Result<()> {
    let devices = list_devices()?;
    let mut rows = Vec::new();
    for d in &devices {
        let limits = Context::new(d.index).map(|c| c.limits().clone());
        if !json {
            println!(
                "device {}: {} ({}){}",
                d.index,
                d.name.as_deref().unwrap_or(if d.software {
                    "Mesa software device"
                } else {
                    "unnamed"
                }),
                d.vendor.as_deref().unwrap_or("unknown vendor"),
                if d.software { ", software" } else { "" }
            );
            match &limits {
                Ok(l) => {
                    println!("  renderer              {}", l.renderer);
                    println!("  GL version            {}", l.version);
                    println!("  GLSL version          {}", l.glsl_version);
                    println!("  max texture size      {}", l.max_texture_size);
                    println!("  max 3D texture size   {}", l.max_3d_texture_size);
                    println!("  max draw buffers      {}", l.max_draw_buffers);
                    println!("  max colour attachments {}", l.max_color_attachments);
                    println!(
                        "  vertex texture units  {}",
                        l.max_vertex_texture_image_units
                    );
                    println!(
                        "  max viewport          {}x{}",
                        l.max_viewport[0], l.max_viewport[1]
                    );
                    println!("  RGBA32F colour buffer {}", yes(l.float32_color_buffer));
                    println!("  RGBA16F colour buffer {}", yes(l.float16_color_buffer));
                    println!("  KHR_debug             {}", yes(l.khr_debug));
                }
                Err(e) => println!("  no usable context: {e}"),
            }
        }
        rows.push(serde_json::json!({
            "index": d.index,
            "name": d.name,
            "vendor": d.vendor,
            "software": d.software,
            "drm_node": d.drm_node,
            "limits": limits.as_ref().ok(),
            "error": limits.as_ref().err().map(|e| e.to_string()),
        }));
    }
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&rows).unwrap_or_default()
        );
    }
    Ok(())
}

fn yes(b: bool) -> &'static str {
    if b {
        "yes"
    } else {
        "no"
    }
}

fn render(a: RenderArgs) -> texflow::Result<()> {
    // Everything that can be checked without a GPU is checked before anything is created.
    let (label, src) = scene::load_source(&a.scene)?;
    let mut s = scene::file::parse(&label, &src)?;
    if a.frames == 0 {
        return Err(bad("--frames 0 renders nothing: ask for at least 1 frame"));
    }
    if a.every == 0 {
        return Err(bad("--every 0 is meaningless: use 1 to write every frame"));
    }
    if a.dump_every == 0 {
        return Err(bad(
            "--dump-every 0 is meaningless: use 1 to dump every frame",
        ));
    }
    if let Some(p) = a.particles {
        s.particles.size = p;
    }
    if let Some(r) = a.resolution {
        s.render.resolution = r;
    }
    if let Some(dt) = a.dt {
        s.time.dt = dt;
    }
    if let Some(n) = a.substeps {
        s.time.substeps = n;
    }
    if a.no_collisions {
        s.collisions = None;
    }
    if let Err(e) = s.validate() {
        return Err(bad(format!(
            "scene `{}` with the options given: {}",
            s.name, e.message
        )));
    }
    if s.fire.is_some() {
        scene::Scene::from_file(&s)?.validate()?;
    }
    FrameWriter::check(&a.out)?;
    if let Some(d) = &a.dump_state {
        FrameWriter::check(d)?;
    }
    let ctx = Context::new(a.common.device)?;
    let limits = scene::file::SizeLimits {
        max_texture: ctx.limits().max_texture_size,
        max_3d_texture: ctx.limits().max_3d_texture_size,
    };
    let mut skip = Vec::new();
    if a.particles.is_some() {
        skip.push("particles.size");
    }
    if a.resolution.is_some() {
        skip.push("render.resolution");
    }
    scene::file::check_limits(&label, &src, &s, limits, &skip)?;
    let mut engine = SceneRunner::new(&ctx, &s, a.seed)?;
    let writer = FrameWriter::create(&a.out)?;
    let dumps = a
        .dump_state
        .as_ref()
        .map(|d| FrameWriter::create(d))
        .transpose()?;
    let [sw, sh] = engine.state_size();
    let counter = texflow::sim::nonfinite::NonFiniteCounter::new(&ctx, sw, sh)?;
    let bar = progress_bar(a.frames, a.common.quiet, "rendering");
    let mut written = 0;
    let mut non_finite = 0;
    let mut bad_frames = 0u64;
    for frame in 0..a.frames {
        engine.advance_frame()?;
        if frame % a.every == 0 {
            // Garbage is reported, not rendered silently.
            let c = engine.non_finite(&counter)?;
            if c.non_finite > 0 {
                if bad_frames == 0 {
                    bar.suspend(|| {
                        eprintln!(
                            "warning: frame {frame}: {} of {} live particles have NaN or \
                             infinite values",
                            c.non_finite, c.live
                        )
                    });
                }
                bad_frames += 1;
                non_finite = non_finite.max(c.non_finite as usize);
            }
            writer.write(frame, &engine.render()?)?;
            written += 1;
        }
        if let (Some(w), true) = (&dumps, frame % a.dump_every == 0) {
            let d = engine.dump()?;
            non_finite = non_finite.max(d.non_finite);
            let rows = |v: &[[f32; 4]]| v.iter().flatten().copied().collect::<Vec<f32>>();
            let n = d.positions.len();
            for (what, data) in [
                ("positions", rows(&d.positions)),
                ("velocities", rows(&d.velocities)),
            ] {
                let path = w.dir().join(format!("{what}_{frame:05}.npy"));
                texflow::npy::write_f32_shaped(&path, &[n, 4], &data)?;
            }
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    if non_finite > 0 {
        eprintln!(
            "warning: up to {non_finite} live particle(s) had NaN or infinite values \
             ({bad_frames} written frame(s) affected; the dumps, if any, hold them)"
        );
    }
    if !a.common.quiet {
        eprintln!(
            "wrote {written} frame(s) of {}x{} to {} ({} particles, {} steps of {} s)",
            s.render.resolution[0],
            s.render.resolution[1],
            a.out.display(),
            s.particle_count(),
            engine.steps(),
            s.time.dt
        );
    }
    Ok(())
}

fn collide_stats(a: CollideStatsArgs) -> texflow::Result<()> {
    let (label, src) = scene::load_source(&a.scene)?;
    let mut s = scene::file::parse(&label, &src)?;
    let Some(c) = s.collisions.as_mut() else {
        return Err(bad(format!(
            "scene `{}` has no [collisions] section: try `collide`",
            s.name
        )));
    };
    if let Some(k) = a.k {
        c.neighbours = k;
    }
    if let Some(st) = &a.staggered {
        c.staggered = st == "on";
    }
    match a.rows_only {
        Some(0) => c.rows_only = None,
        Some(n) => c.rows_only = Some(n),
        None => {}
    }
    if let Some(g) = a.cell {
        c.cell = Some(g);
    }
    if let Some(p) = a.particles {
        s.particles.size = p;
    }
    if a.steps == 0 {
        return Err(bad("--steps 0 runs nothing: ask for at least 1 step"));
    }
    if let Err(e) = s.validate() {
        return Err(bad(format!(
            "scene `{}` with the options given: {}",
            s.name, e.message
        )));
    }
    let ctx = Context::new(a.common.device)?;
    let seed = texflow::engine::shader_seed(a.seed);
    if a.sweep {
        let bar = progress_bar(10, a.common.quiet, "collide-stats sweep");
        let rows = texflow::report::collide_stats::sweep(&ctx, &s, a.steps, seed, |name| {
            bar.set_message(name.to_owned());
            bar.inc(1);
        })?;
        bar.finish_and_clear();
        if a.json {
            println!(
                "{}",
                serde_json::to_string_pretty(&rows).unwrap_or_default()
            );
        } else {
            println!(
                "{} on {}, step {} (one setting changed at a time):\n",
                s.name,
                ctx.limits().renderer,
                a.steps
            );
            print!("{}", texflow::report::collide_stats::sweep_table(&rows));
        }
        return Ok(());
    }
    let bar = progress_bar(a.steps, a.common.quiet, "collide-stats");
    let stats = texflow::report::collide_stats::measure(&ctx, &s, a.steps, seed, || bar.inc(1))?;
    bar.finish_and_clear();
    let c = s.collisions.as_ref().expect("checked");
    if a.json {
        let mut v = serde_json::to_value(&stats).unwrap_or_default();
        v["scene"] = s.name.clone().into();
        v["k"] = c.neighbours.into();
        v["staggered"] = c.staggered.into();
        v["rows_only"] = c.rows_only.into();
        v["steps"] = a.steps.into();
        v["device"] = ctx.limits().renderer.clone().into();
        println!("{}", serde_json::to_string_pretty(&v).unwrap_or_default());
    } else {
        let pct = |n: usize| 100.0 * n as f64 / stats.pairs_true.max(1) as f64;
        println!(
            "{} on {}: step {}, {} live particles, {:.2} per occupied cell; k = {}, staggered {}, \
             sort {}",
            s.name,
            ctx.limits().renderer,
            a.steps,
            stats.particles,
            stats.particles_per_cell,
            c.neighbours,
            if c.staggered { "on" } else { "off" },
            match c.rows_only {
                None => "full".to_owned(),
                Some(1) => "rows only".to_owned(),
                Some(r) => format!("within {r} rows"),
            }
        );
        println!("pairs_true   {:>8}", stats.pairs_true);
        println!("found        {:>8}", stats.found);
        println!(
            "missed       {:>8}  ({:.1}%)",
            stats.missed,
            pct(stats.missed)
        );
        println!("  adjacent cells      {:>6}", stats.missed_adjacent_cells);
        println!("  partner in another row {:>3}", stats.missed_other_row);
        println!("  far along the row   {:>6}", stats.missed_far_along_row);
        println!("  closer partner kept {:>6}", stats.missed_closer_partner);
        println!("false_pairs  {:>8}", stats.false_pairs);
        println!("mutual       {:>8}", stats.mutual);
        println!(
            "conflicts    {:>8}  (partner took a closer one on the other lattice)",
            stats.conflicts
        );
        println!(
            "tunnelled    {:>8}  (overlapped during the step, apart at its end)",
            stats.tunnelled
        );
        println!(
            "gpu_ms       {:>8.3}  (collision passes of one step)",
            stats.gpu_ms
        );
    }
    Ok(())
}

fn scene_command(c: SceneCommand) -> texflow::Result<()> {
    match c {
        SceneCommand::Check {
            scene: name,
            device,
        } => {
            let (label, src) = scene::load_source(&name)?;
            let s = scene::file::parse(&label, &src)?;
            // Sizes against the device's limits, where there is a device to ask.
            let limits = match Context::new(device) {
                Ok(ctx) => {
                    let l = ctx.limits();
                    let limits = scene::file::SizeLimits {
                        max_texture: l.max_texture_size,
                        max_3d_texture: l.max_3d_texture_size,
                    };
                    scene::file::check_limits(&label, &src, &s, limits, &[])?;
                    format!("sizes fit {}", l.renderer)
                }
                Err(e) => format!("sizes not checked against a device: {e}"),
            };
            println!(
                "{name}: ok (scene `{}`, {} particles; {limits})",
                s.name,
                s.particle_count()
            );
        }
        SceneCommand::Passes { scene: name, json } => {
            let plan = scene::plan::plan(&scene::load(&name)?);
            if json {
                println!(
                    "{}",
                    serde_json::to_string_pretty(&plan).unwrap_or_default()
                );
            } else {
                print!("{plan}");
            }
        }
        SceneCommand::List { name: None } => {
            for n in scene::BUILTIN {
                println!("{n}");
            }
        }
        SceneCommand::List { name: Some(n) } => match scene::builtin_source(&n) {
            Some(src) => print!("{src}"),
            None => {
                return Err(bad(format!(
                    "unknown scene `{n}`: the built-in scenes are {}",
                    scene::BUILTIN.join(", ")
                )))
            }
        },
    }
    Ok(())
}

/// Checks that `path` can be written as a file: its folder exists and it is not a folder.
fn check_output_file(path: &std::path::Path, flag: &str) -> texflow::Result<()> {
    if path.is_dir() {
        return Err(bad(format!(
            "{flag} {} is a folder: name a .npy file",
            path.display()
        )));
    }
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => std::path::Path::new("."),
    };
    if !parent.is_dir() {
        return Err(bad(format!(
            "{flag} {}: folder {} does not exist",
            path.display(),
            parent.display()
        )));
    }
    let probe = parent.join(format!(".texflow-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .and_then(|_| std::fs::remove_file(&probe))
        .map_err(|e| {
            bad(format!(
                "{flag} {}: cannot write in {} ({e})",
                path.display(),
                parent.display()
            ))
        })
}

fn sort(a: SortArgs) -> texflow::Result<()> {
    let variant = Variant::from_name(&a.variant)?;
    let keys = texflow::npy::read_f32(&a.input).map_err(|e| match e {
        Error::Io { path, source } => bad(format!("--input {}: {source}", path.display())),
        e => e,
    })?;
    check_output_file(&a.output, "--output")?;
    if let Some(ids) = &a.ids {
        check_output_file(ids, "--ids")?;
    }
    let n = keys.len();
    if n > 1 << 24 {
        return Err(bad(format!(
            "{n} keys: ids are floats on the GPU and exact only up to 2^24 = 16777216 keys"
        )));
    }
    // The smallest power-of-two texture that holds the keys (rows of at least 2 entries), as
    // square as possible.
    let total = n.next_power_of_two().max(2) as u32;
    let k = total.trailing_zeros();
    let (w, h) = (1u32 << k.div_ceil(2), 1u32 << (k / 2));
    let ctx = Context::new(a.common.device)?;
    texflow::gl::check_size(&ctx, "sort texture", w, h)?;
    let mut sorter = Sorter::new(&ctx, variant, w, h, SortOptions::default())?;
    // Padding: +inf keys with ids past the input; dropped by id after the sort, so NaN keys of
    // the input (which sort after +inf) are kept.
    let entries: Vec<[f32; 2]> = (0..(w * h) as usize)
        .map(|i| [keys.get(i).copied().unwrap_or(f32::INFINITY), i as f32])
        .collect();
    sorter.load(&entries)?;
    sorter.sort();
    let sorted: Vec<[f32; 2]> = sorter
        .read()?
        .into_iter()
        .filter(|e| (e[1] as usize) < n)
        .collect();
    ctx.check_error("sorting")?;
    if sorted.len() != n {
        return Err(Error::Gl(format!(
            "the sort returned {} of {n} keys",
            sorted.len()
        )));
    }
    texflow::npy::write_f32(&a.output, &sorted.iter().map(|e| e[0]).collect::<Vec<_>>())?;
    if let Some(ids) = &a.ids {
        texflow::npy::write_i32(ids, &sorted.iter().map(|e| e[1] as i32).collect::<Vec<_>>())?;
    }
    if !a.common.quiet {
        eprintln!(
            "sorted {n} keys with {} ({} passes on a {w}x{h} texture) on {}",
            variant.name(),
            sorter.pass_count(),
            ctx.limits().renderer
        );
    }
    Ok(())
}

fn print_sort_table(records: &[SortRecord]) {
    print!("{}", texflow::bench::sort_markdown(records));
}

fn bench(cmd: BenchCommand) -> texflow::Result<()> {
    match cmd {
        BenchCommand::Scenes(a) => bench_scenes(a),
        BenchCommand::Sort {
            sizes,
            variants,
            repeats,
            no_cpu,
            steps,
            clock,
            json,
            common,
        } => {
            let variants: Vec<Variant> = if variants.iter().any(|v| v == "all") {
                Variant::ALL.to_vec()
            } else {
                variants
                    .iter()
                    .map(|v| Variant::from_name(v))
                    .collect::<texflow::Result<_>>()?
            };
            if sizes.is_empty() || sizes.iter().any(|&s| s < 2 || !s.is_power_of_two()) {
                return Err(bad(
                    "--sizes takes powers of two of at least 2, e.g. 128,256,512",
                ));
            }
            if repeats == 0 {
                return Err(bad("--repeats must be at least 1"));
            }
            let ctx = Context::new(common.device)?;
            for &n in &sizes {
                texflow::gl::check_size(&ctx, "--sizes", n, n)?;
            }
            let bar = progress_bar(
                (sizes.len() * (variants.len() + 1)) as u64,
                common.quiet,
                "bench sort",
            );
            if !(1..=3).contains(&steps) {
                return Err(bad("--steps must be 1, 2 or 3"));
            }
            let opts = SortBenchOptions {
                repeats,
                clock: clock.clock(),
                cpu: !no_cpu,
                steps_per_pass: steps,
            };
            let records = bench_sort(&ctx, &sizes, &variants, &opts, |_, _| bar.inc(1))?;
            bar.finish_and_clear();
            let clock = records.iter().find(|r| r.passes > 0).map(|r| r.clock);
            report(json, &records, &ctx, clock, &format!("medians of {repeats}; full sort = key pass + network + rearrangement of 2 RGBA32F textures"), print_sort_table);
            Ok(())
        }
        BenchCommand::Step {
            scene: name,
            sizes,
            repeats,
            resolution,
            clock,
            json,
            common,
        } => {
            let mut s = scene::builtin(&name)?;
            if let Some(r) = resolution {
                s.resolution = r;
            }
            if sizes.is_empty() || sizes.contains(&0) {
                return Err(bad("--sizes needs sizes of at least 1, e.g. 256,512"));
            }
            if repeats == 0 {
                return Err(bad("--repeats must be at least 1"));
            }
            s.validate()?;
            let ctx = Context::new(common.device)?;
            for &n in &sizes {
                texflow::gl::check_size(&ctx, "--sizes", n, n)?;
            }
            let bar = progress_bar(sizes.len() as u64, common.quiet, "bench step");
            let opts = StepOptions {
                repeats,
                clock: clock.clock(),
                ..StepOptions::default()
            };
            let records = bench_step(&ctx, &s, &sizes, &opts, |_| bar.inc(1))?;
            bar.finish_and_clear();
            let clock = records.first().map(|r| r.clock);
            report(
                json,
                &records,
                &ctx,
                clock,
                &format!("medians of {repeats}"),
                print_step_table,
            );
            Ok(())
        }
    }
}

#[derive(Args)]
struct ScenesArgs {
    /// Square state sizes (size x size particles), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024")]
    sizes: Vec<u32>,
    /// Experiments, comma-separated (E1, E2, E3, E4, E5), or `all`.
    #[arg(long, value_delimiter = ',', default_value = "all")]
    experiments: Vec<String>,
    /// Timed frames per experiment and size (the median is reported).
    #[arg(long, default_value_t = 11)]
    repeats: usize,
    /// Frames simulated before timing (default: one full emission cycle of the scene).
    #[arg(long)]
    warmup: Option<usize>,
    /// Frame size WxH (default: the scenes' 512x512).
    #[arg(long, value_parser = parse_size)]
    resolution: Option<[u32; 2]>,
    /// Seed of every experiment.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// How to time the GPU experiments: auto, gpu, wall (E5 always uses wall time).
    #[arg(long, value_enum, default_value_t = ClockArg::Auto)]
    clock: ClockArg,
    /// Print JSON (one record per experiment and size).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    common: Common,
}

fn bench_scenes(a: ScenesArgs) -> texflow::Result<()> {
    use texflow::bench_scenes as bs;
    if a.sizes.is_empty() || a.sizes.contains(&0) {
        return Err(bad("--sizes needs sizes of at least 1, e.g. 256,512,1024"));
    }
    if a.repeats == 0 {
        return Err(bad("--repeats must be at least 1"));
    }
    let experiments: Vec<String> = if a.experiments.iter().any(|e| e == "all") {
        Vec::new()
    } else {
        for e in &a.experiments {
            if !bs::experiments()
                .iter()
                .any(|x| x.name.eq_ignore_ascii_case(e.trim()))
            {
                return Err(bad(format!(
                    "unknown experiment `{e}`: use E1, E2, E3, E4, E5 or all"
                )));
            }
        }
        a.experiments.clone()
    };
    let ctx = Context::new(a.common.device)?;
    for &n in &a.sizes {
        texflow::gl::check_size(&ctx, "--sizes", n, n)?;
    }
    let count = if experiments.is_empty() {
        bs::experiments().len()
    } else {
        experiments.len()
    };
    let bar = progress_bar(
        (a.sizes.len() * count) as u64,
        a.common.quiet,
        "bench scenes",
    );
    let opts = bs::ScenesOptions {
        repeats: a.repeats,
        warmup_frames: a.warmup,
        clock: a.clock.clock(),
        resolution: a.resolution,
        seed: a.seed,
        experiments,
    };
    let records = bs::bench_scenes(&ctx, &a.sizes, &opts, |_, _| bar.inc(1))?;
    bar.finish_and_clear();
    let clock = records
        .iter()
        .filter(|r| r.engine == "gpu")
        .find_map(|r| r.clock)
        .or_else(|| records.iter().find_map(|r| r.clock));
    let warmup = match a.warmup {
        Some(w) => format!("{w} warm-up frames"),
        None => "a full emission cycle".into(),
    };
    let what = format!(
        "medians of {} whole frames after {warmup}; E1-E4 GPU, E5 CPU engine on {} threads \
         (wall time incl. upload, draw, glFinish); paper: ATI 9800 Pro / Pentium 4 2 GHz",
        a.repeats,
        rayon::current_num_threads()
    );
    report(a.json, &records, &ctx, clock, &what, |r| {
        print!("{}", bs::markdown(r))
    });
    Ok(())
}

/// Prints benchmark records as JSON, or as a header naming the device and clock and a table.
fn report<T: serde::Serialize>(
    json: bool,
    records: &[T],
    ctx: &Context,
    clock: Option<Clock>,
    what: &str,
    table: fn(&[T]),
) {
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(records).unwrap_or_default()
        );
    } else {
        println!(
            "device {}: {}; {}; {what}",
            ctx.device_index(),
            ctx.limits().renderer,
            clock.map(Clock::name).unwrap_or_default()
        );
        table(records);
    }
}

fn print_step_table(records: &[StepRecord]) {
    print!("{}", texflow::bench::step_markdown(records));
}

#[derive(Subcommand)]
enum ReportCommand {
    /// Work-precision diagrams and convergence orders per integrator and precision.
    Convergence {
        /// Also write CSV and PNG plots into this folder (created if missing).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Fewer and shorter runs (about 8 s on llvmpipe).
        #[arg(long)]
        quick: bool,
        /// Print JSON (every point) instead of the table of orders.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
    /// Stiff spring and drag across their stability limits, and the extreme cases with their
    /// documented outcomes.
    Stability {
        /// Print JSON instead of tables.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
    /// Everything: plots, CSVs, stability JSON and markdown, and summary.md, into --out.
    All {
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Sized for llvmpipe: about a minute instead of a quarter of an hour.
        #[arg(long)]
        quick: bool,
        /// Only these sections, comma-separated: tables, convergence, sort_frames, collisions,
        /// stability (default: all).
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
        /// Runs of each benchmark table (the tables section); every cell reports the run of
        /// median time. The docs use 3.
        #[arg(long, default_value_t = 1)]
        runs: usize,
        #[command(flatten)]
        common: Common,
    },
}

fn report_cmd(cmd: ReportCommand) -> texflow::Result<()> {
    use texflow::report::{self, convergence, stability, ReportOptions};
    let say = |quiet: bool| {
        move |m: &str| {
            if !quiet {
                eprintln!("report: {m}");
            }
        }
    };
    match cmd {
        ReportCommand::Convergence {
            out,
            quick,
            json,
            common,
        } => {
            if let Some(d) = &out {
                FrameWriter::check(d)?;
            }
            let ctx = Context::new(common.device)?;
            let opts = ReportOptions::new(quick);
            let r = convergence::run(
                &ctx,
                &convergence::default_sweeps(opts.size),
                &convergence::StatePrecision::ALL,
                &mut say(common.quiet),
            )?;
            if let Some(d) = &out {
                report::create_dir(d)?;
                convergence::write_files(&r, d)?;
            }
            if json {
                println!("{}", serde_json::to_string_pretty(&r).unwrap_or_default());
            } else {
                println!(
                    "device {}: {}; {}",
                    ctx.device_index(),
                    r.device,
                    r.clock.name()
                );
                print!("{}", convergence::table(&r));
            }
            Ok(())
        }
        ReportCommand::Stability { json, common } => {
            let ctx = Context::new(common.device)?;
            let opts = stability::StabilityOptions::default();
            let r = stability::run(&ctx, &opts, &mut say(common.quiet))?;
            if json {
                println!("{}", serde_json::to_string_pretty(&r).unwrap_or_default());
            } else {
                println!("device {}: {}", ctx.device_index(), r.device);
                print!("{}", stability::table(&r));
            }
            for w in stability::warnings(&r) {
                eprintln!("warning: {w}");
            }
            Ok(())
        }
        ReportCommand::All {
            out,
            quick,
            only,
            runs,
            common,
        } => {
            if runs == 0 {
                return Err(bad("--runs must be at least 1"));
            }
            let sections = if only.is_empty() {
                report::sections()
            } else {
                report::select(&only)?
            };
            FrameWriter::check(&out)?;
            let ctx = Context::new(common.device)?;
            let all = report::run_sections(
                &ctx,
                &ReportOptions {
                    runs,
                    ..ReportOptions::new(quick)
                },
                &out,
                &sections,
                &mut say(common.quiet),
            )?;
            for f in &all.files {
                println!("{}", f.display());
            }
            for w in &all.warnings {
                eprintln!("warning: {w}");
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info { json } => info(json),
        Command::Render(a) => render(a),
        Command::Sort(a) => sort(a),
        Command::Scene(c) => scene_command(c),
        Command::CollideStats(a) => collide_stats(a),
        Command::Bench(b) => bench(b),
        Command::Report(r) => report_cmd(r),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(if e.is_bad_input() { 2 } else { 1 })
        }
    }
}
