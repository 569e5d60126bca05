//! `texflow bench`: step, sort and scenes benchmarks.

use clap::{Args, Subcommand};
use texflow::bench::{
    bench_sort, bench_step, SortBenchOptions, SortRecord, StepOptions, StepRecord,
};
use texflow::gl::Context;
use texflow::scene;
use texflow::sort::Variant;

use super::{at_least_one, bad, parse_size, progress_bar, report, warmup_frames, ClockArg, Common};

#[derive(Subcommand)]
pub enum BenchCommand {
    /// UberFlow's Table 2: fps of whole frames of E1-E5 per state size, next to the paper's.
    Scenes(ScenesArgs),
    /// Every phase of any scene's pass plan, each next to its same-run floor, and the frame's
    /// fps and particles per second.
    Scene(SceneArgs),
    /// GPU time of any scene's simulation step and render pass per state size, with floors.
    Step(StepArgs),
    /// UberFlow's Table 1: full sorts per variant and size, with floors and CPU baselines.
    Sort(SortArgs),
    /// Every pass of one frame of any scene, draw by draw, each next to its floor.
    Passes(super::bench_passes::PassesArgs),
}

/// `--blocked 4`, `3p`, `5c`, `4m`, `5cm`: entries-per-fragment bits, the pinned lane, compact
/// entries, merge passes.
fn parse_blocked_shape(s: &str) -> texflow::Result<texflow::sort::BlockedShape> {
    let (unmerged, merge) = match s.strip_suffix('m') {
        Some(d) => (d, true),
        None => (s, false),
    };
    let (rest, compact) = match unmerged.strip_suffix('c') {
        Some(d) => (d, true),
        None => (unmerged, false),
    };
    let (digits, pinned) = match rest.strip_suffix('p') {
        Some(d) => (d, true),
        None => (rest, false),
    };
    match (digits.parse::<u32>(), compact, pinned) {
        (Ok(bits @ 2..=4), false, _) | (Ok(bits @ 2..=5), true, false) if !(merge && pinned) => {
            Ok(texflow::sort::BlockedShape {
                bits,
                pinned,
                compact,
                merge,
            })
        }
        _ => Err(bad(format!(
            "--blocked {s}: give 2, 3 or 4 (bits of exact entries per fragment) with `p` for \
             the pinned lane, or 2 to 5 with `c` for compact 4-byte entries (not pinned), then \
             `m` to merge runs after the first pass (not pinned), e.g. --blocked 4,3p,5c,4m,5cm"
        ))),
    }
}

pub fn print_sort_table(records: &[SortRecord]) {
    print!("{}", texflow::bench::sort_markdown(records));
}

pub fn bench(cmd: BenchCommand) -> texflow::Result<()> {
    match cmd {
        BenchCommand::Scenes(a) => bench_scenes(a),
        BenchCommand::Sort(a) => sort(a),
        BenchCommand::Scene(a) => bench_scene(a),
        BenchCommand::Step(a) => step(a),
        BenchCommand::Passes(a) => super::bench_passes::bench_passes_cmd(a),
    }
}

/// `texflow bench sort`: UberFlow's Table 1.
fn sort(a: SortArgs) -> texflow::Result<()> {
    let SortArgs {
        sizes,
        variants,
        repeats,
        no_cpu,
        steps,
        blocked,
        clock,
        json,
        common,
    } = a;
    let blocked_shapes = blocked
        .iter()
        .map(|b| parse_blocked_shape(b))
        .collect::<texflow::Result<Vec<_>>>()?;
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
        blocked_shapes,
    };
    let records = bench_sort(&ctx, &sizes, &variants, &opts, |_, _| bar.inc(1))?;
    bar.finish_and_clear();
    let clock = records.iter().find(|r| r.passes > 0).map(|r| r.clock);
    report(json.then_some("texflow.bench.sort/1"), &records, &ctx, clock, &format!("medians of {repeats}; full sort = key pass + network + rearrangement of 2 RGBA32F textures"), print_sort_table);
    Ok(())
}

/// `texflow bench step`: a scene's step and render pass against their floors.
fn step(a: StepArgs) -> texflow::Result<()> {
    let StepArgs {
        scene: name,
        scene_flag,
        sizes,
        repeats,
        resolution,
        clock,
        json,
        set,
        common,
    } = a;
    let name = scene_flag.unwrap_or(name);
    let (label, src) = scene::load_source(&name)?;
    let mut s = scene::parse_with(&label, &src, &set.set)?;
    if let Some(r) = resolution {
        s.render.resolution = r;
    }
    if sizes.is_empty() || sizes.contains(&0) {
        return Err(bad("--sizes needs sizes of at least 1, e.g. 256,512"));
    }
    s.check()?;
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
        json.then_some("texflow.bench.step/1"),
        &records,
        &ctx,
        clock,
        &format!("medians of {repeats}"),
        print_step_table,
    );
    Ok(())
}

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct StepArgs {
    /// Scene to measure, built in or a file (its step and render pass; each phase apart:
    /// `bench scene`). The default is the thesis's fire, `fire-points`.
    #[arg(value_name = "SCENE", default_value = scene::THESIS_SCENE)]
    scene: String,
    /// The old spelling of SCENE (hidden; still accepted).
    #[arg(
        long = "scene",
        value_name = "SCENE",
        hide = true,
        conflicts_with = "scene"
    )]
    scene_flag: Option<String>,
    /// Square state sizes, comma-separated.
    #[arg(
        long,
        value_name = "N,...",
        value_delimiter = ',',
        default_value = "256,512,1024,2048"
    )]
    sizes: Vec<u32>,
    /// Timed repetitions per size (the median is reported).
    #[arg(long, value_name = "N", default_value_t = 21, value_parser = at_least_one::<usize>)]
    repeats: usize,
    /// Frame size of the render pass [default: the scene's].
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    resolution: Option<[u32; 2]>,
    /// How to time passes: auto (wall time on llvmpipe, timer queries on a GPU), gpu, wall.
    #[arg(long, value_enum, default_value_t = ClockArg::Auto)]
    clock: ClockArg,
    /// Print JSON (one record per size).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    set: super::set::SetArgs,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct SortArgs {
    /// Texture sides (size x size entries), powers of two, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "128,256,512,1024,2048")]
    sizes: Vec<u32>,
    /// Variants, comma-separated, or `all`.
    #[arg(long, value_delimiter = ',', default_value = "all")]
    variants: Vec<String>,
    /// Timed repetitions per variant and size (the median is reported).
    #[arg(long, default_value_t = 11, value_parser = at_least_one::<usize>)]
    repeats: usize,
    /// Skip the CPU baselines.
    #[arg(long)]
    no_cpu: bool,
    /// Steps of distance 2 or more per pass of the multistep variant (1 to 3).
    #[arg(long, default_value_t = 2)]
    steps: usize,
    /// Shapes of the blocked variant, one row each: `b` entries-per-fragment bits (2, 3 or
    /// 4: 4, 8 or 16 entries), with a `p` suffix for the pinned lane, or 2 to 5 with a `c`
    /// suffix for compact 4-byte entries (lossy keys), then an `m` suffix to merge runs after
    /// the first pass (the default shape is `4m`), e.g. `4,3p,5c,4m,5cm`.
    #[arg(long, value_delimiter = ',', value_name = "B[p|c][m],...")]
    blocked: Vec<String>,
    /// How to time: auto, gpu, wall.
    #[arg(long, value_enum, default_value_t = ClockArg::Auto)]
    clock: ClockArg,
    /// Print JSON (one record per variant and size).
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    common: Common,
}

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct ScenesArgs {
    /// Square state sizes (size x size particles), comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "256,512,1024")]
    sizes: Vec<u32>,
    /// Experiments, comma-separated (E1, E2, E3, E3p, E4, E4p, E5), or `all`.
    #[arg(long, value_delimiter = ',', default_value = "all")]
    experiments: Vec<String>,
    /// Timed frames per experiment and size (the median is reported).
    #[arg(long, default_value_t = 11, value_parser = at_least_one::<usize>)]
    repeats: usize,
    /// Frames simulated before timing (default: one full emission cycle of the scene).
    #[arg(long, value_parser = warmup_frames)]
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
    /// Whether a draw uploads only the uniform values its program does not hold already (on)
    /// or every value it carries (off: profiles what the cache saves; results are the same).
    #[arg(long, value_enum, value_name = "ON|OFF", default_value_t = CacheArg::On)]
    uniform_cache: CacheArg,
    #[command(flatten)]
    common: Common,
}

pub fn bench_scenes(a: ScenesArgs) -> texflow::Result<()> {
    use texflow::bench::scenes as bs;
    if a.sizes.is_empty() || a.sizes.contains(&0) {
        return Err(bad("--sizes needs sizes of at least 1, e.g. 256,512,1024"));
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
                    "unknown experiment `{e}`: use E1, E2, E3, E3p, E4, E4p, E5 or all"
                )));
            }
        }
        a.experiments.clone()
    };
    let ctx = Context::new(a.common.device)?;
    a.uniform_cache.apply(&ctx);
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
    report(
        a.json.then_some("texflow.bench.scenes/1"),
        &records,
        &ctx,
        clock,
        &what,
        |r| print!("{}", bs::markdown(r)),
    );
    Ok(())
}

pub fn print_step_table(records: &[StepRecord]) {
    print!("{}", texflow::bench::step_markdown(records));
}

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct SceneArgs {
    /// The scene: a built-in name or a .toml scene file.
    #[arg(help = super::scene_help("measure", ""), value_name = "NAME|FILE")]
    scene: String,
    /// Square state sizes (size x size particles), comma-separated [default: the scene's
    /// particles.size, when square].
    #[arg(long, value_name = "N,...", value_delimiter = ',')]
    sizes: Vec<u32>,
    /// Timed repetitions per size (the medians are reported).
    #[arg(long, value_name = "N", default_value_t = 11, value_parser = at_least_one::<usize>)]
    repeats: usize,
    /// Frames simulated before timing, at most 10000 [default: one emission cycle of the scene,
    /// capped at 10000 frames]. A state with no live particle is refused.
    #[arg(long, value_name = "FRAMES", value_parser = warmup_frames)]
    warmup: Option<usize>,
    /// Frame size [default: the scene's render.resolution].
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    resolution: Option<[u32; 2]>,
    /// Seed of the engine.
    #[arg(long, value_name = "SEED", default_value_t = 1)]
    seed: u64,
    /// How to time: auto (wall time on llvmpipe, timer queries on a GPU), gpu, wall.
    #[arg(long, value_enum, default_value_t = ClockArg::Auto)]
    clock: ClockArg,
    /// Print JSON: an object with texflow_version, schema, device, clock and one record per size.
    #[arg(long)]
    json: bool,
    /// Whether a draw uploads only the uniform values its program does not hold already (on)
    /// or every value it carries (off: profiles what the cache saves; results are the same).
    #[arg(long, value_enum, value_name = "ON|OFF", default_value_t = CacheArg::On)]
    uniform_cache: CacheArg,
    #[command(flatten)]
    set: super::set::SetArgs,
    #[command(flatten)]
    common: Common,
}

pub fn bench_scene(a: SceneArgs) -> texflow::Result<()> {
    use texflow::bench::scene as bs;
    let overrides = super::overrides::Overrides {
        particles: None,
        resolution: a.resolution,
        dt: None,
        substeps: None,
        no_collisions: false,
        seed: a.seed,
        device: a.common.device,
        set: a.set.set.clone(),
    };
    let prepared = overrides.prepare(&a.scene)?;
    let s = &prepared.scene;
    let sizes = if a.sizes.is_empty() {
        let [w, h] = s.particles.size;
        if w != h {
            return Err(bad(format!(
                "scene {} has a {w}x{h} state: give square sizes with --sizes, e.g. --sizes {w}",
                s.name
            )));
        }
        vec![w]
    } else {
        a.sizes.clone()
    };
    if sizes.contains(&0) {
        return Err(bad("--sizes needs sizes of at least 1, e.g. 64,128"));
    }
    let ctx = Context::new(a.common.device)?;
    a.uniform_cache.apply(&ctx);
    overrides.check_device(&ctx, &prepared)?;
    for &n in &sizes {
        texflow::gl::check_size(&ctx, "--sizes", n, n)?;
    }
    let bar = progress_bar(sizes.len() as u64, a.common.quiet, "bench scene");
    let opts = bs::SceneBenchOptions {
        repeats: a.repeats,
        warmup_frames: a.warmup,
        clock: a.clock.clock(),
        resolution: a.resolution,
        seed: a.seed,
    };
    let records = bs::bench_scene(&ctx, s, &sizes, &opts, |_| bar.inc(1))?;
    bar.finish_and_clear();
    let clock = records.first().map(|r| r.clock);
    let what = format!(
        "scene {} ({}); medians of {}; each phase run alone and finished, next to its floor \
         measured in the same run",
        s.name, prepared.label, a.repeats
    );
    report(
        a.json.then_some("texflow.bench.scene/1"),
        &records,
        &ctx,
        clock,
        &what,
        |r| print!("{}", bs::scene_markdown(r)),
    );
    Ok(())
}

/// `--uniform-cache`.
#[derive(Clone, Copy, clap::ValueEnum)]
pub enum CacheArg {
    /// Upload only the values a program does not hold already.
    On,
    /// Upload every value a draw carries.
    Off,
}

impl CacheArg {
    fn apply(self, ctx: &Context) {
        ctx.set_uniform_cache(matches!(self, CacheArg::On));
    }
}
