//! The texflow command line. Parsing, calling the library and printing live in `src/cli/`; this
//! file only dispatches and maps errors to exit codes.

use std::process::ExitCode;

use clap::Parser;

mod cli;

use cli::{Cli, Command};

fn main() -> ExitCode {
    // A closed stdout or stderr (`texflow info | head -1`) ends the process quietly with 141 (as
    // SIGPIPE ends Unix tools), after removing unfinished files, instead of a panic message and
    // exit 101: Rust ignores SIGPIPE, so the failed write panics, and this hook catches that.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if message.starts_with("failed printing to std") && message.contains("Broken pipe") {
            match texflow::output::abandon(|| std::process::exit(141)) {}
        }
        default_hook(info);
    }));
    cli::signals::install();
    let args = Cli::parse();
    let result = match args.command {
        Command::Info { json } => cli::info::info(json),
        Command::Render(a) => cli::render::render(a),
        Command::View(a) => cli::view::view(a),
        Command::Sort(a) => cli::sort::sort(a),
        Command::Trace(a) => cli::trace::trace_cmd(a),
        Command::Scene(c) => cli::scene::scene_command(c),
        Command::Diff(a) => cli::diff::diff(a),
        Command::CollideStats(a) => cli::collide::collide_stats(a),
        Command::Bench(b) => cli::bench::bench(b),
        Command::Report(r) => cli::report::report_cmd(r),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
