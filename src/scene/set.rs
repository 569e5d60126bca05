//! `--set KEY=VALUE`: scene keys changed from the command line. The file is parsed first (its
//! own mistakes keep their line and column); then each setting edits the parsed TOML document,
//! and the result goes through the same typed parse and validation as a file, so a setting is
//! checked exactly as the key would be in the file. An error about a setting names it as typed.

use toml::{Table, Value};

use super::locate::{locate, scene_error, Key};
use super::parse::{load_files, parse, parse_unloaded};
use super::schema::SceneFile;
use super::suggest::suggest_in_message;
use crate::error::{Error, Result};

/// One `KEY=VALUE` from the command line.
#[derive(Debug, Clone, PartialEq)]
pub struct Setting {
    /// The setting as typed, for messages.
    pub typed: String,
    /// The key's path: table keys and array indices (`emitters.allocator.0.rate`, or
    /// `emitters.allocator[0].rate`).
    pub path: Vec<String>,
    /// The value: TOML (`4`, `[320, 240]`, `"sprites"`), or a bare word taken as a string.
    pub value: Value,
}

impl Setting {
    /// Parses `KEY=VALUE`.
    pub fn parse(typed: &str) -> Result<Setting> {
        let bad = |m: String| Err(Error::InvalidInput(format!("--set {typed}: {m}")));
        let Some((key, raw)) = typed.split_once('=') else {
            return bad("give KEY=VALUE, e.g. --set render.point_size=4".into());
        };
        let key = key.trim();
        let path: Vec<String> = key
            .replace('[', ".")
            .replace(']', "")
            .split('.')
            .map(|s| s.trim().to_owned())
            .collect();
        if path.iter().any(String::is_empty) {
            return bad(format!(
                "`{key}` is not a key: give the path of dotted names, e.g. render.camera.distance \
                 or emitters.allocator.0.rate"
            ));
        }
        let raw = raw.trim();
        let value = match toml::from_str::<Table>(&format!("v = {raw}")) {
            Ok(mut t) => t.remove("v").expect("the one key"),
            // A bare word is a string: `--set render.mode=sprites`.
            Err(_)
                if !raw.is_empty()
                    && raw
                        .chars()
                        .all(|c| c.is_alphanumeric() || "_-./".contains(c)) =>
            {
                Value::String(raw.to_owned())
            }
            Err(e) => {
                return bad(format!(
                    "`{raw}` is not a TOML value ({}): give a number, true or false, a quoted \
                     string or an array like [1, 2, 3]",
                    e.message().trim()
                ))
            }
        };
        if !finite(&value) {
            return bad(format!(
                "`{raw}` is not a finite number: scenes take finite numbers only"
            ));
        }
        Ok(Setting {
            typed: typed.to_owned(),
            path,
            value,
        })
    }

    /// The key as the validation names it (`emitters.allocator.0.rate`).
    pub fn key(&self) -> String {
        self.path.join(".")
    }

    /// Sets the value in the document `root`, creating missing tables on the way.
    fn apply(&self, root: &mut Value) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidInput(format!("--set {}: {m}", self.typed)));
        let (last, parents) = self.path.split_last().expect("a non-empty path");
        let mut here: &mut Value = root;
        for (depth, seg) in parents.iter().enumerate() {
            let so_far = self.path[..=depth].join(".");
            here = match here {
                Value::Table(t) => t
                    .entry(seg.clone())
                    .or_insert_with(|| Value::Table(Table::new())),
                Value::Array(a) => match seg.parse::<usize>() {
                    Ok(i) if i < a.len() => &mut a[i],
                    _ => return bad(index_message(&so_far, seg, a.len())),
                },
                _ => {
                    return bad(format!(
                        "`{}` is a value, not a table: `{so_far}` cannot be set",
                        self.path[..depth].join(".")
                    ))
                }
            };
        }
        match here {
            Value::Table(t) => {
                t.insert(last.clone(), self.value.clone());
            }
            Value::Array(a) => match last.parse::<usize>() {
                Ok(i) if i < a.len() => a[i] = self.value.clone(),
                _ => return bad(index_message(&self.key(), last, a.len())),
            },
            _ => return bad(format!("`{}` is a value, not a table", parents.join("."))),
        }
        Ok(())
    }
}

fn index_message(key: &str, seg: &str, len: usize) -> String {
    let parent = key.rsplit_once('.').map_or(key, |(p, _)| p);
    match len {
        0 => format!("`{parent}` is an empty array: `{seg}` is no index into it"),
        n => format!(
            "`{seg}` is no index into `{parent}`, which holds {n} (indices 0 to {})",
            n - 1
        ),
    }
}

fn finite(v: &Value) -> bool {
    match v {
        Value::Float(f) => f.is_finite(),
        Value::Array(a) => a.iter().all(finite),
        Value::Table(t) => t.values().all(finite),
        _ => true,
    }
}

/// Parses and validates a scene file as [`parse`] does, then applies `settings` (each
/// `KEY=VALUE`, in order) and validates the result the same way. Errors in the file keep their
/// line and column; an error about a setting names it as typed.
pub fn parse_with(path: &str, src: &str, settings: &[String]) -> Result<SceneFile> {
    if settings.is_empty() {
        return parse(path, src);
    }
    // The file's own mistakes first, at their line and column; its files are read once the
    // settings are in (a setting may name another file).
    let (doc, base) = parse_unloaded(path, src)?;
    let settings = settings
        .iter()
        .map(|s| Setting::parse(s))
        .collect::<Result<Vec<_>>>()?;
    let table: Table = toml::from_str(src).map_err(|e| Error::InvalidInput(e.to_string()))?;
    let mut root = Value::Table(table);
    let mut scene = base;
    // One setting at a time, so that a value of the wrong type or an unknown key is blamed on
    // the setting that brought it.
    for s in &settings {
        s.apply(&mut root)?;
        scene = root.clone().try_into().map_err(|e: toml::de::Error| {
            Error::InvalidInput(format!(
                "--set {}: {}",
                s.typed,
                suggest_in_message(e.message().trim())
            ))
        })?;
    }
    if let Err(invalid) = scene.validate() {
        let at = dotted(&invalid.at);
        if let Some(s) = settings
            .iter()
            .rev()
            .find(|s| at == s.key() || at.starts_with(&format!("{}.", s.key())))
        {
            return Err(Error::InvalidInput(format!(
                "--set {}: {}",
                s.typed, invalid.message
            )));
        }
        let with: Vec<String> = settings
            .iter()
            .map(|s| format!("--set {}", s.typed))
            .collect();
        return Err(scene_error(
            path,
            src,
            locate(&doc, &invalid.at),
            format!("{} (with {})", invalid.message, with.join(" ")),
        ));
    }
    load_files(path, src, &doc, &mut scene)?;
    Ok(scene)
}

/// A validation path as dotted text (`emitters.allocator.0.rate`).
fn dotted(at: &[Key]) -> String {
    at.iter()
        .map(|k| match k {
            Key::Name(n) => (*n).to_owned(),
            Key::Index(i) => i.to_string(),
        })
        .collect::<Vec<_>>()
        .join(".")
}
