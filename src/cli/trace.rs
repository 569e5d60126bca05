//! `texflow trace`: a frame of a scene, or a sort, drawn pass by pass.

use std::path::PathBuf;

use super::overrides::Overrides;
use clap::Args;
use texflow::gl::Context;
use texflow::output::FrameWriter;
use texflow::sort::Variant;
use texflow::trace::{self, MAX_SORT_SIDE, MAX_TRACE_FRAME, MAX_TRACE_SIDE};

use super::{at_least_one, bad, parse_size, targets, Common};

#[derive(Args)]
#[command(
    allow_negative_numbers = true,
    after_help = format!(
        "Limits: a scene trace draws state textures up to {MAX_TRACE_SIDE}x{MAX_TRACE_SIDE} and \
         runs to frame {MAX_TRACE_FRAME} at most; a sort trace is N×N keys with N a power of two \
         from 2 to {MAX_SORT_SIDE}.\n\nExamples:\n  texflow trace smoke-unlit --frame 10 --particles 32 \
         --out trace-smoke\n  texflow trace sort --variant oddeven --size 16 --out trace-sort"
    )
)]
pub struct TraceArgs {
    /// What to trace: a scene (built-in name or .toml file), or `sort` for a sort of random keys.
    #[arg(default_value = texflow::scene::DEFAULT_SCENE)]
    target: String,
    /// Scene traces: the frame whose passes are drawn (frames before it run as `render` runs
    /// them).
    #[arg(long, value_name = "N", default_value_t = 0)]
    frame: u64,
    /// Sort traces: fp, gpfp, packed (UberFlow), oddeven (Latta), multistep, blocked (ours;
    /// the blocked sort is drawn as one step: between its passes its entries are not row-major).
    #[arg(long, default_value = "oddeven")]
    variant: String,
    /// Sort traces: N×N keys, N a power of two from 2 to 64.
    #[arg(long, value_name = "N", default_value_t = 16, value_parser = at_least_one::<u32>)]
    size: u32,
    /// Scene traces: state texture size WxH or N (at most 256x256) [default: the scene's
    /// particles.size].
    #[arg(long, value_parser = parse_size, value_name = "WxH")]
    particles: Option<[u32; 2]>,
    /// Scene traces: frame size WxH or N [default: the scene's render.resolution].
    #[arg(long, value_parser = parse_size, value_name = "WxH")]
    resolution: Option<[u32; 2]>,
    /// Random seed (the scene's, or the sort's keys).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Output folder (created if missing): the PNGs and index.md (and sort.gif).
    #[arg(long, value_name = "DIR", default_value = "trace")]
    out: PathBuf,
    /// Scene traces: scene keys set as KEY=VALUE, as `render --set`.
    #[command(flatten)]
    set: super::set::SetArgs,
    #[command(flatten)]
    common: Common,
}

pub fn trace_cmd(a: TraceArgs) -> texflow::Result<()> {
    FrameWriter::check(&a.out)?;
    let existed = a.out.exists();
    let result = run_trace(&a);
    // A trace that fails leaves no folder it made (a folder with files in it stays).
    if result.is_err() && !existed {
        let _ = std::fs::remove_dir(&a.out);
    }
    result
}

fn run_trace(a: &TraceArgs) -> texflow::Result<()> {
    let written = if a.target == "sort" {
        if a.particles.is_some() || a.resolution.is_some() || a.frame != 0 || !a.set.set.is_empty()
        {
            return Err(bad(
                "--frame, --particles, --resolution and --set are for scene traces: a sort trace \
                 takes --variant, --size and --seed",
            ));
        }
        let variant = Variant::from_name(&a.variant)?;
        trace::check_sort_size(a.size)?;
        targets::check_folder(&a.out, "--out", &targets::trace_writes, &[])?;
        let ctx = Context::new(a.common.device)?;
        let out = FrameWriter::create(&a.out)?;
        trace::trace_sort(&ctx, variant, a.size, a.seed, out.dir())?
    } else {
        let overrides = Overrides {
            particles: a.particles,
            resolution: a.resolution,
            seed: a.seed,
            device: a.common.device,
            set: a.set.set.clone(),
            ..Overrides::default()
        };
        let prepared = overrides.prepare(&a.target)?;
        trace::check_scene_trace(&prepared.scene, a.frame)?;
        // Nothing the scene reads may be a picture or the index the trace writes.
        let inputs = targets::inputs(&prepared.label, &prepared.scene);
        targets::check_folder(&a.out, "--out", &targets::trace_writes, &inputs)?;
        let ctx = Context::new(overrides.device)?;
        overrides.check_device(&ctx, &prepared)?;
        let out = FrameWriter::create(&a.out)?;
        trace::trace_scene(&ctx, &prepared.scene, a.seed, a.frame, out.dir())?
    };
    if !a.common.quiet {
        eprintln!(
            "wrote {} files for {} passes to {} (open {}/index.md)",
            written.files.len(),
            written.passes,
            a.out.display(),
            a.out.display()
        );
    }
    if !written.ok {
        return Err(texflow::Error::Gl(
            "the traced sort did not end sorted: the GPU's passes disagree with the network".into(),
        ));
    }
    Ok(())
}
