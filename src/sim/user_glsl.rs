//! What user GLSL files (`[[forces.custom]]`, `[[forces.pair]]`) share once checked: the names
//! they are added under as runtime sources, and compile errors that name the user's file and
//! line instead of those names.

use crate::error::Error;

/// The name a user file's text is added under: unique to its kind, index, path and text, and
/// never the name of one of texflow's files, so that a user's `common/rng.glsl` is not shadowed
/// by the built-in one, and one file named twice is spliced twice.
pub(crate) fn source_key(kind: &str, i: usize, path: &str, text: &str) -> String {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (path, text).hash(&mut h);
    format!("{kind}-{i}-{:016x}", h.finish())
}

/// How a user's function is renamed where it is spliced: the `i`-th file's `name` becomes
/// `{prefix}{i}` (`force` → `custom_force_0`, `pair_force` → `pair_force_0`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Renamed {
    /// The name the user's file defines.
    pub name: &'static str,
    /// The prefix of the name it is compiled under, before the file's index.
    pub prefix: &'static str,
}

/// A compile error in a user's file becomes an input error that names the file and line (not
/// under `glsl/`); other errors pass through. `files` pairs each source key with the user's
/// path; `what` names the feature ("custom force") and `signature` what the file must define.
/// The location is the first line of the driver's log that points into a user's file (Mesa may
/// place an error in an expression of the user's file at the root's source number, so the log's
/// first location is not always the one). An error at texflow's call of the user's function (a
/// wrong signature) is placed at the function's definition in the user's file. The log speaks
/// of the user's names: the function as the file spells it, texflow's own sources by role.
pub(crate) fn user_compile_error(
    e: Error,
    files: &[(String, String)],
    what: &str,
    signature: &str,
    renamed: Renamed,
) -> Error {
    match e {
        // Every compile error of a program built from the user's GLSL is the user's to fix,
        // wherever the driver places it (texflow's file that calls the user's function too).
        Error::ShaderCompile { file, line, log } => {
            let mut log = log;
            let mut file = file;
            for (key, path) in files {
                log = log.replace(key.as_str(), path);
                if file == *key {
                    file.clone_from(path);
                }
            }
            // Highest index first: `pair_force_1` is not a prefix of `pair_force_10`.
            for i in (0..files.len()).rev() {
                log = log.replace(&format!("{}{i}", renamed.prefix), renamed.name);
            }
            let in_user = |l: &str| {
                files.iter().find_map(|(_, path)| {
                    let rest = l.strip_prefix(path.as_str())?.strip_prefix(':')?;
                    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
                    // Mesa writes `LINE(COLUMN)`; the column too where the driver gives one.
                    let column: String = (rest[digits.len()..].strip_prefix('('))
                        .map(|c| c.chars().take_while(char::is_ascii_digit).collect())
                        .unwrap_or_default();
                    Some(match column.is_empty() {
                        true => format!("{path}:{digits}"),
                        false => format!("{path}:{digits}:{column}"),
                    })
                })
            };
            let at = log.lines().find_map(in_user);
            let at = at
                .or_else(|| definition(files, renamed.name))
                .unwrap_or(format!("{file}:{line}"));
            // texflow's own warnings are not the user's to fix.
            let log: Vec<String> = log
                .lines()
                .filter_map(|l| match in_user(l) {
                    Some(_) => Some(l.to_owned()),
                    None if l.contains(": warning: ") => None,
                    None => Some(texflow_line(l)),
                })
                .collect();
            Error::InvalidInput(format!(
                "{what} {at}: the GLSL does not compile; it must define `{signature}`:\n{}",
                log.join("\n")
            ))
        }
        e => e,
    }
}

/// `path:line:column` of the first definition of function `name` in the user's files (a name
/// followed by `(` outside a comment), if any: where a call with the wrong arguments is fixed.
fn definition(files: &[(String, String)], name: &str) -> Option<String> {
    files.iter().find_map(|(key, path)| {
        let text = crate::gl::source::embedded(key)?;
        let mut in_block = false;
        for (n, l) in text.lines().enumerate() {
            let mut col = 0;
            let bytes = l.as_bytes();
            while col < bytes.len() {
                let rest = &l[col..];
                if in_block {
                    match rest.find("*/") {
                        Some(k) => {
                            in_block = false;
                            col += k + 2;
                            continue;
                        }
                        None => break,
                    }
                }
                if rest.starts_with("//") {
                    break;
                }
                if rest.starts_with("/*") {
                    in_block = true;
                    col += 2;
                    continue;
                }
                let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
                let starts = col == 0 || !word(bytes[col - 1]);
                if starts && rest.starts_with(name) {
                    let after = rest[name.len()..].trim_start();
                    let whole = rest.as_bytes().get(name.len()).is_none_or(|b| !word(*b));
                    if whole && after.starts_with('(') {
                        return Some(format!("{path}:{}:{}", n + 1, col + 1));
                    }
                }
                col += rest.chars().next().map_or(1, char::len_utf8);
            }
        }
        None
    })
}

/// A log line that points into texflow's own sources (`NAME:LINE(COL): text`): the text, as
/// said of texflow's call of the user's function, without texflow's internal source name.
fn texflow_line(l: &str) -> String {
    let located = l.find("): ").filter(|&k| {
        let head = &l[..k];
        head.rsplit_once('(')
            .is_some_and(|(_, col)| col.bytes().all(|b| b.is_ascii_digit()))
    });
    match located {
        Some(k) => format!("(texflow's call) {}", &l[k + 3..]),
        None => l.to_owned(),
    }
}
