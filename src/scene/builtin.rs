//! Loading a scene by built-in name (the sources in `sources`) or by file path; the fire scenes
//! as the thesis model.

use std::path::Path;

use super::parse::parse;
use super::schema::SceneFile;
use super::sources::{builtin_source, BUILTIN};
use crate::error::{Error, Result};

/// The scene rendered when none is named.
pub const DEFAULT_SCENE: &str = "fire";

/// What a built-in scene shows, in one line (`texflow scene list`): the first line of its file's
/// opening comment, which the scene files keep as their title. The scene file is the one place
/// that says what the scene is for.
pub fn summary(name: &str) -> Option<String> {
    let first = builtin_source(name)?.lines().next()?;
    Some(first.strip_prefix('#')?.trim().to_owned())
}

/// The fire as the thesis draws it (square points): the faithful variant of [`DEFAULT_SCENE`],
/// and what `bench step` measures.
pub const THESIS_SCENE: &str = "fire-points";

/// Loads a scene by built-in name or from a `.toml` file (errors name file, line and column).
pub fn load(name_or_path: &str) -> Result<SceneFile> {
    let (label, src) = load_source(name_or_path)?;
    let mut scene = parse(&label, &src)?;
    super::load_custom(&label, &src, &mut scene)?;
    Ok(scene)
}

/// The label errors use for a scene and its TOML source, by built-in name or file path.
pub fn load_source(name_or_path: &str) -> Result<(String, String)> {
    if let Some(src) = builtin_source(name_or_path) {
        return Ok((format!("{name_or_path} (built-in)"), src.to_owned()));
    }
    let path = Path::new(name_or_path);
    let looks_like_file = path.extension().is_some_and(|e| e == "toml")
        || name_or_path.contains(std::path::MAIN_SEPARATOR);
    if !looks_like_file {
        return Err(Error::InvalidInput(format!(
            "unknown scene `{name_or_path}`: the built-in scenes are {}, or give a path to a \
             .toml scene file{}",
            BUILTIN.join(", "),
            super::suggest::did_you_mean(name_or_path, BUILTIN.iter().copied()),
        )));
    }
    // Bytes, not `read_to_string`: a file that is not UTF-8 gets a line and column.
    // A regular file of bounded size only: a fifo or `/dev/zero` would never end.
    let bytes = crate::input::read_bounded(path, crate::input::MAX_SCENE_BYTES).map_err(|e| {
        Error::InvalidInput(format!("cannot read scene file {}: {e}", path.display()))
    })?;
    let label = path.display().to_string();
    let src = super::locate::utf8(&label, bytes)?;
    Ok((label, src))
}

/// Loads a built-in scene by name (no file paths: see [`load`]).
pub fn builtin(name: &str) -> Result<SceneFile> {
    match builtin_source(name) {
        Some(src) => parse(&format!("{name} (built-in)"), src),
        None => Err(Error::InvalidInput(format!(
            "unknown scene `{name}`: the built-in scenes are {}{}",
            BUILTIN.join(", "),
            super::suggest::did_you_mean(name, BUILTIN.iter().copied()),
        ))),
    }
}

/// The fire as the thesis draws it, at 256×256 particles rendered at 512×512 in square points
/// (`examples/scenes/fire-points.toml`).
pub fn fire() -> SceneFile {
    builtin(THESIS_SCENE).expect("the built-in fire scene is valid")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_are_valid_and_unknown_names_list_them() {
        for name in BUILTIN {
            let f = load(name).unwrap();
            f.check().unwrap();
        }
        let msg = load("smok").unwrap_err().to_string();
        assert!(msg.contains("smok") && msg.contains("fire"), "{msg}");
        assert!(msg.contains("did you mean `smoke`?"), "{msg}");
    }

    #[test]
    fn every_builtin_has_a_one_line_title() {
        for name in BUILTIN {
            let title = summary(name).unwrap();
            let second = builtin_source(name).unwrap().lines().nth(1).unwrap();
            assert!(
                (20..=110).contains(&title.chars().count()) && title.ends_with('.'),
                "{name}: {title}"
            );
            // The title stands alone: a blank comment line follows it.
            assert_eq!(second.trim(), "#", "{name}");
        }
        assert_eq!(summary("no-such-scene"), None);
    }
}
