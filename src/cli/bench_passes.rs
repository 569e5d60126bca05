//! `texflow bench passes`: every pass of a frame, draw by draw, next to its floor.

use clap::Args;
use texflow::bench::{bench_passes, passes_markdown, PassesOptions};
use texflow::gl::Context;

use super::{at_least_one, progress_bar, report, ClockArg, Common};

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct PassesArgs {
    /// The scene: a built-in name or a .toml scene file.
    #[arg(help = super::scene_help("profile", ""), value_name = "NAME|FILE")]
    scene: String,
    /// State texture size, WxH or N for NxN [default: the scene's particles.size].
    #[arg(long, value_name = "WxH", value_parser = super::parse_size)]
    particles: Option<[u32; 2]>,
    /// Profiled frames (the median per pass is reported).
    #[arg(long, value_name = "N", default_value_t = 5, value_parser = at_least_one::<usize>)]
    repeats: usize,
    /// Frames simulated before timing, at most 10000 [default: one emission cycle of the scene].
    #[arg(long, value_name = "FRAMES", value_parser = super::warmup_frames)]
    warmup: Option<usize>,
    /// Frame size [default: the scene's render.resolution].
    #[arg(long, value_name = "WxH", value_parser = super::parse_size)]
    resolution: Option<[u32; 2]>,
    /// How to time: auto (wall time on llvmpipe, timer queries on a GPU), gpu, wall.
    #[arg(long, value_enum, default_value_t = ClockArg::Auto)]
    clock: ClockArg,
    /// Print JSON: an object with texflow_version, schema, device, clock and the record.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    set: super::set::SetArgs,
    #[command(flatten)]
    common: Common,
}

/// Profiles the scene's frames and prints one line per program drawn.
pub fn bench_passes_cmd(a: PassesArgs) -> texflow::Result<()> {
    let overrides = super::overrides::Overrides {
        particles: a.particles,
        resolution: a.resolution,
        dt: None,
        substeps: None,
        no_collisions: false,
        seed: 1,
        device: a.common.device,
        set: a.set.set.clone(),
    };
    let prepared = overrides.prepare(&a.scene)?;
    let s = &prepared.scene;
    let ctx = Context::new(a.common.device)?;
    overrides.check_device(&ctx, &prepared)?;
    let bar = progress_bar(a.repeats as u64, a.common.quiet, "bench passes");
    let opts = PassesOptions {
        repeats: a.repeats,
        warmup_frames: a.warmup,
        clock: a.clock.clock(),
    };
    let record = bench_passes(&ctx, s, &opts, || bar.inc(1))?;
    bar.finish_and_clear();
    let what = format!(
        "scene {} ({}); every draw of a frame timed alone, grouped by program; floor: draws × \
         the fixed cost of a pass + bytes at the state's write rate, measured in the same run",
        s.name, prepared.label
    );
    report(
        a.json.then_some("texflow.bench.passes/1"),
        std::slice::from_ref(&record),
        &ctx,
        Some(record.clock),
        &what,
        |r| r.iter().for_each(|r| print!("{}", passes_markdown(r))),
    );
    Ok(())
}
