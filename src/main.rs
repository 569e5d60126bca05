//! The texflow command line. Parsing, calling the library and printing live in `src/cli/`; this
//! file only dispatches and maps errors to exit codes.

use std::process::ExitCode;

use clap::Parser;

mod cli;

use cli::{Cli, Command};

fn main() -> ExitCode {
    // A closed stdout (`texflow info | head -1`) ends the process quietly, as it does Unix tools,
    // instead of a panic on the failed write.
    // SAFETY: restoring the default action of SIGPIPE before any thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    cli::signals::install();
    let args = Cli::parse();
    let result = match args.command {
        Command::Info { json } => cli::info::info(json),
        Command::Render(a) => cli::render::render(a),
        Command::View(a) => cli::view::view(a),
        Command::Sort(a) => cli::sort::sort(a),
        Command::Scene(c) => cli::scene::scene_command(c),
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
