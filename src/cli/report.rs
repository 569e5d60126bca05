//! `texflow report`: error against run time, stability, and everything into one folder.

use std::path::PathBuf;

use clap::Subcommand;
use texflow::gl::Context;
use texflow::output::FrameWriter;

use super::{at_least_one, Common};

#[derive(Subcommand)]
pub enum ReportCommand {
    /// Work-precision diagrams and convergence orders per integrator and precision.
    #[command(allow_negative_numbers = true)]
    Convergence {
        /// Also write CSV and PNG plots into this folder (created if missing).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Fewer and shorter runs (for CI and a software renderer).
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
    #[command(allow_negative_numbers = true)]
    Stability {
        /// Print JSON instead of tables.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
    /// The cloth's worst and mean edge error against relaxation passes and GPU time, for each
    /// constraint scheme (the table; `report all --only constraints` also writes the plots).
    Constraints {
        /// A 16² sheet and two iteration counts (for CI and a software renderer).
        #[arg(long)]
        quick: bool,
        /// Print JSON (every row) instead of the table.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        common: Common,
    },
    /// Everything: plots, CSVs, stability JSON and markdown, and summary.md, into --out.
    #[command(allow_negative_numbers = true)]
    All {
        /// Output folder (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// Small sizes, for CI and a software renderer such as llvmpipe; the full report takes
        /// most of an hour there (minutes on a GPU).
        #[arg(long)]
        quick: bool,
        /// Only these sections, comma-separated: tables, convergence, sort_frames, collisions,
        /// stability, cost, baselines, constraints (default: all).
        #[arg(long, value_delimiter = ',')]
        only: Vec<String>,
        /// Runs of each benchmark table (the tables section); every cell reports the run of
        /// median time. The docs use 3.
        #[arg(long, default_value_t = 1, value_parser = at_least_one::<usize>)]
        runs: usize,
        #[command(flatten)]
        common: Common,
    },
}

pub fn report_cmd(cmd: ReportCommand) -> texflow::Result<()> {
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
                super::print_json("texflow.report.convergence/1", Some(&ctx), &r);
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
                super::print_json("texflow.report.stability/1", Some(&ctx), &r);
            } else {
                println!("device {}: {}", ctx.device_index(), r.device);
                print!("{}", stability::table(&r));
            }
            for w in stability::warnings(&r) {
                eprintln!("warning: {w}");
            }
            Ok(())
        }
        ReportCommand::Constraints {
            quick,
            json,
            common,
        } => constraints_cmd(quick, json, common),
        ReportCommand::All {
            out,
            quick,
            only,
            runs,
            common,
        } => {
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

/// `texflow report constraints`: the table (or JSON) of every scheme's edge error and GPU time.
fn constraints_cmd(quick: bool, json: bool, common: Common) -> texflow::Result<()> {
    use texflow::report::{constraints, ReportOptions};
    let ctx = Context::new(common.device)?;
    let size = ReportOptions::new(quick).size;
    let quiet = common.quiet;
    let r = constraints::run(&ctx, size, &mut |m: &str| {
        if !quiet {
            eprintln!("report: {m}");
        }
    })?;
    if json {
        super::print_json("texflow.report.constraints/1", Some(&ctx), &r);
    } else {
        println!(
            "device {}: {}; {}; {}² cloth after {} steps",
            ctx.device_index(),
            r.device,
            r.clock,
            r.side,
            r.steps
        );
        print!("{}", constraints::table(&r));
    }
    Ok(())
}
