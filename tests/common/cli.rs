//! Running the built binary and looking at what it wrote.

use std::path::Path;
use std::process::{Command, Output};

/// The built `texflow` binary, not run yet (for a working folder, stdin or environment).
pub fn command() -> Command {
    Command::new(env!("CARGO_BIN_EXE_texflow"))
}

/// Runs `texflow ARGS` to the end and returns its status and output.
pub fn texflow(args: &[&str]) -> Output {
    command().args(args).output().expect("run texflow")
}

/// What a run wrote to stderr.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A path as the `&str` an argument list takes.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// The names of the entries of `dir`, sorted (the folder must exist).
pub fn file_names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The `.png` files of `dir`, sorted.
pub fn pngs(dir: &Path) -> Vec<String> {
    let mut v = file_names(dir);
    v.retain(|n| n.ends_with(".png"));
    v
}
