//! `texflow sort`: sort float32 keys from a .npy file on the GPU.

use std::path::PathBuf;

use clap::Args;
use texflow::gl::Context;
use texflow::npy;
use texflow::output::Outputs;
use texflow::sort::{SortOptions, Sorter, Variant};
use texflow::Error;

use super::{bad, Common};

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct SortArgs {
    /// Sort implementation: fp, gpfp, packed (UberFlow), oddeven (Latta), multistep, blocked
    /// (ours).
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

pub fn sort(a: SortArgs) -> texflow::Result<()> {
    let variant = Variant::from_name(&a.variant)?;
    // A device or a pipe would be read without end (`/dev/zero`) or block (a fifo).
    match std::fs::metadata(&a.input) {
        Ok(m) if !m.is_file() => {
            return Err(bad(format!(
                "--input {} is not a regular file (a device, pipe or folder): give a .npy file",
                a.input.display()
            )))
        }
        _ => {}
    }
    let keys = texflow::npy::read_f32(&a.input).map_err(|e| match e {
        Error::Io { path, source } => bad(format!("--input {}: {source}", path.display())),
        e => e,
    })?;
    // Every output is checked before the GPU runs: no clash with another output or the input,
    // no folder, device or pipe in the way.
    let mut outputs = Outputs::new();
    outputs.input(&a.input, "--input");
    let out_keys = outputs.file(&a.output, "--output")?;
    let out_ids = a
        .ids
        .as_ref()
        .map(|p| outputs.file(p, "--ids"))
        .transpose()?;
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
    let keys: Vec<f32> = sorted.iter().map(|e| e[0]).collect();
    outputs.stage(out_keys, &npy::encode_f32(&[keys.len()], &keys))?;
    if let Some(i) = out_ids {
        let ids: Vec<i32> = sorted.iter().map(|e| e[1] as i32).collect();
        outputs.stage(i, &npy::encode_i32(&ids))?;
    }
    // Both files are renamed into place only now that both are written.
    outputs.commit()?;
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
