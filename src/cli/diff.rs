//! `texflow diff A.png B.png`: how far two frames are apart (a lossy variant against the exact).

use std::path::PathBuf;

use clap::Args;

#[derive(Args)]
pub struct DiffArgs {
    /// The reference frame (e.g. rendered with the exact sort).
    a: PathBuf,
    /// The frame to compare with it (same size).
    b: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

pub fn diff(args: DiffArgs) -> texflow::Result<()> {
    let d = texflow::output::diff::diff_files(&args.a, &args.b)?;
    if args.json {
        // The envelope every `--json` has (schema, version), the comparison as its record.
        super::print_json("texflow.diff/1", None, &d);
    } else {
        println!(
            "{}x{}: mean |difference| {:.4}/255 per channel, largest {}/255, {:.3} % of pixels \
             changed, PSNR {:.1} dB",
            d.size[0],
            d.size[1],
            d.mean,
            d.max,
            100.0 * d.pixels_changed,
            d.psnr_db
        );
    }
    Ok(())
}
