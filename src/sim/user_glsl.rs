//! What user GLSL files (`[[forces.custom]]`, `[[forces.pair]]`) share once checked: the names
//! they are added under as runtime sources, and compile errors that name the user's file and
//! line instead of those names.

use crate::error::Error;
use crate::gl::source::is_runtime_source;

/// The name a user file's text is added under: unique to its kind, index, path and text, and
/// never the name of one of texflow's files, so that a user's `common/rng.glsl` is not shadowed
/// by the built-in one, and one file named twice is spliced twice.
pub(crate) fn source_key(kind: &str, i: usize, path: &str, text: &str) -> String {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (path, text).hash(&mut h);
    format!("{kind}-{i}-{:016x}", h.finish())
}

/// A compile error in a user's file becomes an input error that names the file and line (not
/// under `glsl/`); other errors pass through. `files` pairs each source key with the user's
/// path; `what` names the feature ("custom force") and `signature` what the file must define.
/// The location is the first line of the driver's log that points into a user's file (Mesa may
/// place an error in an expression of the user's file at the root's source number, so the log's
/// first location is not always the one).
pub(crate) fn user_compile_error(
    e: Error,
    files: &[(String, String)],
    what: &str,
    signature: &str,
) -> Error {
    match e {
        Error::ShaderCompile { file, line, log } if is_runtime_source(&file) => {
            let mut log = log;
            let mut file = file;
            for (key, path) in files {
                log = log.replace(key.as_str(), path);
                if file == *key {
                    file.clone_from(path);
                }
            }
            let at = log.lines().find_map(|l| {
                files.iter().find_map(|(_, path)| {
                    let rest = l.strip_prefix(path.as_str())?.strip_prefix(':')?;
                    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
                    Some(format!("{path}:{digits}"))
                })
            });
            let at = at.unwrap_or(format!("{file}:{line}"));
            Error::InvalidInput(format!(
                "{what} {at}: the GLSL does not compile; it must define `{signature}`:\n{log}"
            ))
        }
        e => e,
    }
}
