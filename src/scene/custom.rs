//! The front end of custom forces (`[[forces.custom]] glsl = "wind.glsl"`): the user's file is
//! read (a regular file of at most [`MAX_GLSL_BYTES`](crate::input::MAX_GLSL_BYTES)) and its text
//! checked before any compiler sees it, so that `scene check` and `render` refuse the same files
//! with the same message, naming the user's file, line and column.
//!
//! texflow writes the `#version` line and splices the force after `common/rng.glsl` and
//! `sim/fields.glsl` itself, so a user's file may not have `#version`, `#extension` (the
//! pipeline is GL 3.3 core fragment passes: no compute, storage buffers or image stores),
//! `#include` (it would be looked up among texflow's own files) or `#line` (it would make
//! compile errors point at texflow's files). A byte-order mark is dropped; NUL and other control
//! bytes are refused (a driver stops at a NUL and reports a missing `main` instead).
//!
//! A shader that never ends hangs a real GPU's frame (and then the driver resets it); llvmpipe
//! caps loops, so there it ends. Loops written to never end, `for (;;)`, `while (true)` and
//! `do ... while (true)`, are refused here; a loop whose bound comes from data is the user's
//! responsibility (docs/scenes.md says so beside the feature).

use std::path::Path;

use super::locate::{document, line_column, locate, scene_error, Key};
use super::schema::SceneFile;
use crate::error::Result;

use Key::{Index as I, Name as N};

/// What a user's GLSL file must define: a function's name and its signature, for messages.
#[derive(Debug, Clone, Copy)]
struct Defines {
    name: &'static str,
    signature: &'static str,
}

const FORCE: Defines = Defines {
    name: "force",
    signature: "vec3 force(vec3 x, vec3 v, float age, int type)",
};

/// The signature of a `[[forces.pair]]` file's function.
pub const PAIR_SIGNATURE: &str = "vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, \
                                  vec3 vj, int type_j, float mass_j, float distance)";

const PAIR: Defines = Defines {
    name: "pair_force",
    signature: PAIR_SIGNATURE,
};

/// A `[[state]]` file defines helper functions of any name.
const HELPERS: Defines = Defines {
    name: "",
    signature: "functions the state's expressions call",
};

/// Reads a user state's helper file `path` (`[[state]] glsl`) and checks its text as
/// [`read_glsl`] does; it may define any functions.
pub fn read_state_glsl(path: &str) -> std::result::Result<String, String> {
    read_checked(path, HELPERS)
}

/// Reads the custom force file `path` and checks its text; an error names `path`, the line and
/// the column.
pub fn read_glsl(path: &str) -> std::result::Result<String, String> {
    read_checked(path, FORCE)
}

/// Reads the pair force file `path` (`[[forces.pair]]`) and checks its text as [`read_glsl`]
/// does; it must define `pair_force`.
pub fn read_pair_glsl(path: &str) -> std::result::Result<String, String> {
    read_checked(path, PAIR)
}

fn read_checked(path: &str, what: Defines) -> std::result::Result<String, String> {
    let bytes = crate::input::read_bounded(Path::new(path), crate::input::MAX_GLSL_BYTES)
        .map_err(|e| format!("cannot read `{path}`: {e}"))?;
    check(path, &bytes, what)
}

/// Checks the bytes of a custom force file named `path` (in messages) and returns its text.
pub fn check_glsl(path: &str, bytes: &[u8]) -> std::result::Result<String, String> {
    check(path, bytes, FORCE)
}

/// Checks the bytes of a pair force file named `path` (in messages) and returns its text.
pub fn check_pair_glsl(path: &str, bytes: &[u8]) -> std::result::Result<String, String> {
    check(path, bytes, PAIR)
}

fn check(path: &str, bytes: &[u8], what: Defines) -> std::result::Result<String, String> {
    let text = decode(path, bytes)?;
    raw_lines(path, text)?;
    let code = strip_comments(text);
    directives(path, &code)?;
    endless_loops(path, &code)?;
    let defines_force = what.name.is_empty()
        || code
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .any(|w| w == what.name);
    if !defines_force {
        return Err(format!(
            "{path}: it defines no `{}`: a {} file defines `{}`",
            what.name,
            if what.name == "force" {
                "custom force"
            } else {
                "pair force"
            },
            what.signature
        ));
    }
    Ok(text.to_owned())
}

/// The file's text: UTF-8 (a byte-order mark dropped) without control characters.
fn decode<'a>(path: &str, bytes: &'a [u8]) -> std::result::Result<&'a str, String> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let text = match std::str::from_utf8(bytes) {
        Ok(t) => t,
        Err(e) => {
            let valid = e.valid_up_to();
            let before = std::str::from_utf8(&bytes[..valid]).unwrap_or_default();
            let (line, column) = line_column(before, valid);
            return Err(format!(
                "{path}:{line}:{column}: byte 0x{:02x} is not UTF-8: save the file as UTF-8",
                bytes[valid]
            ));
        }
    };
    if let Some((at, c)) = text
        .char_indices()
        .find(|(_, c)| c.is_control() && !matches!(c, '\n' | '\r' | '\t' | '\x0b' | '\x0c'))
    {
        let (line, column) = line_column(text, at);
        return Err(format!(
            "{path}:{line}:{column}: control character U+{:04X} in the GLSL: remove it",
            c as u32
        ));
    }
    Ok(text)
}

/// Checks on the text's lines before comments are stripped: `#include` and lone carriage returns.
fn raw_lines(path: &str, text: &str) -> std::result::Result<(), String> {
    // texflow's include resolver reads lines, comments or not: an `#include` line in a
    // comment would be spliced too.
    for (n, line) in text.lines().enumerate() {
        let rest = line.trim_start().strip_prefix('#').map(str::trim_start);
        if rest.is_some_and(|r| r.starts_with("include")) {
            return Err(format!(
                "{path}:{}: `#include` is not allowed (not even in a comment): the force is \
                 compiled after common/rng.glsl and sim/fields.glsl, whose functions need no \
                 include; put other code in this file",
                n + 1
            ));
        }
    }
    // A carriage return is a line end only before a line feed (CRLF): alone, a driver may
    // count it as one and the lines of its errors would no longer be the file's.
    if let Some(at) = text
        .match_indices('\r')
        .map(|(i, _)| i)
        .find(|&i| text.as_bytes().get(i + 1) != Some(&b'\n'))
    {
        let (line, column) = line_column(text, at);
        return Err(format!(
            "{path}:{line}:{column}: a carriage return without a line feed: save the file with \
             LF or CRLF line ends"
        ));
    }
    Ok(())
}

/// Line continuations and the directives texflow writes itself, in comment-free `code`.
fn directives(path: &str, code: &str) -> std::result::Result<(), String> {
    for (n, line) in code.lines().enumerate() {
        let at = |why: String| format!("{path}:{}: {why}", n + 1);
        if line.trim_end().ends_with('\\') {
            return Err(at(
                "a line ends with `\\` (a line continuation): join the lines".into(),
            ));
        }
        if let Some(directive) = line.trim_start().strip_prefix('#') {
            let name: String = directive
                .trim_start()
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            let why = match name.as_str() {
                "version" => "`#version` is not allowed: texflow writes `#version 330 core` itself",
                "extension" => {
                    "`#extension` is not allowed: forces run in a GL 3.3 core fragment pass \
                     (no compute shaders, storage buffers or image stores)"
                }
                "include" => {
                    "`#include` is not allowed: the force is compiled after common/rng.glsl and \
                     sim/fields.glsl, whose functions need no include; put other code in this file"
                }
                "line" => {
                    "`#line` is not allowed: it would make compile errors point at other files"
                }
                _ => continue,
            };
            return Err(at(why.into()));
        }
    }
    Ok(())
}

/// Loops written to never end, in comment-free `code`.
fn endless_loops(path: &str, code: &str) -> std::result::Result<(), String> {
    let flat: String = code.split_whitespace().collect::<Vec<_>>().join("");
    for endless in ["for(;;)", "while(true)", "while(1)"] {
        if let Some(i) = flat.find(endless) {
            // The line of the loop: count the words before it in the text.
            let words = flat[..i].len();
            let line = line_of_flat_offset(code, words);
            return Err(format!(
                "{path}:{line}: `{endless}` never ends: a shader that does not end hangs the GPU's \
                 frame; give the loop a fixed bound"
            ));
        }
    }
    Ok(())
}

/// The line of `code` holding the `n`-th non-whitespace character.
fn line_of_flat_offset(code: &str, n: usize) -> usize {
    let mut seen = 0;
    for (i, line) in code.lines().enumerate() {
        let k = line.chars().filter(|c| !c.is_whitespace()).count();
        if seen + k > n {
            return i + 1;
        }
        seen += k;
    }
    code.lines().count().max(1)
}

/// `text` with comments blanked (newlines kept, so lines keep their numbers).
fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, chars.peek()) {
            ('/', Some('/')) => {
                for c in chars.by_ref() {
                    if c == '\n' {
                        out.push('\n');
                        break;
                    }
                }
            }
            ('/', Some('*')) => {
                chars.next();
                out.push(' ');
                let mut last = ' ';
                for c in chars.by_ref() {
                    if c == '\n' {
                        out.push('\n');
                    }
                    if last == '*' && c == '/' {
                        break;
                    }
                    last = c;
                }
            }
            _ => out.push(c),
        }
    }
    out
}

/// Reads and checks every custom force, pair force and user state file of `scene` (paths already resolved against the
/// scene's folder) into its `source`; a failure is a scene error at the `glsl` key.
pub fn load_custom(path: &str, src: &str, scene: &mut SceneFile) -> Result<()> {
    if scene.forces.custom.is_empty()
        && scene.forces.pair.is_empty()
        && scene.state.iter().all(|s| s.glsl.is_none())
    {
        return Ok(());
    }
    let doc = document(path, src)?;
    for (i, c) in scene.forces.custom.iter_mut().enumerate() {
        let text = read_glsl(&c.glsl).map_err(|m| {
            let at = locate(&doc, &[N("forces"), N("custom"), I(i), N("glsl")]);
            scene_error(
                path,
                src,
                at,
                format!("custom force: {m} (the path is relative to the scene file)"),
            )
        })?;
        c.source = Some(text);
    }
    for (i, c) in scene.forces.pair.iter_mut().enumerate() {
        let text = read_pair_glsl(&c.glsl).map_err(|m| {
            let at = locate(&doc, &[N("forces"), N("pair"), I(i), N("glsl")]);
            scene_error(
                path,
                src,
                at,
                format!("pair force: {m} (the path is relative to the scene file)"),
            )
        })?;
        c.source = Some(text);
    }
    for (i, c) in scene.state.iter_mut().enumerate() {
        let Some(glsl) = &c.glsl else { continue };
        let text = read_state_glsl(glsl).map_err(|m| {
            let at = locate(&doc, &[N("state"), I(i), N("glsl")]);
            scene_error(
                path,
                src,
                at,
                format!(
                    "state `{}`: {m} (the path is relative to the scene file)",
                    c.name
                ),
            )
        })?;
        c.source = Some(text);
    }
    Ok(())
}

/// `PATH:LINE:COLUMN` of the key at `keys` (table names, then the key) in the scene file the
/// scene was parsed from; `None` for a scene made in code.
pub fn key_place(scene: &SceneFile, keys: &[&'static str]) -> Option<String> {
    let origin = scene.origin.0.as_ref()?;
    let (path, src) = (&origin.0, &origin.1);
    let doc = document(path, src).ok()?;
    let keys: Vec<Key> = keys.iter().map(|k| N(k)).collect();
    let (l, c) = line_column(src, locate(&doc, &keys));
    Some(format!("{path}:{l}:{c}"))
}

/// Where each `[[state]]`'s `init`, `update` and `pair` are in the scene file it was parsed from
/// (`state.NAME.update is at PATH:LINE:COLUMN; ...`), for compile errors in them; `None` for a
/// scene made in code.
pub fn state_places(scene: &SceneFile) -> Option<String> {
    let origin = scene.origin.0.as_ref()?;
    let (path, src) = (&origin.0, &origin.1);
    let doc = document(path, src).ok()?;
    let mut out = Vec::new();
    for (i, s) in scene.state.iter().enumerate() {
        for key in ["init", "update", "pair"] {
            if (key == "update" && s.update.is_none()) || (key == "pair" && s.pair.is_none()) {
                continue;
            }
            let at = locate(&doc, &[N("state"), I(i), N(key)]);
            let (l, c) = line_column(src, at);
            out.push(format!("state.{}.{key} is at {path}:{l}:{c}", s.name));
        }
    }
    Some(out.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_checks_name_the_file_and_line() {
        let ok = "vec3 force(vec3 x, vec3 v, float age, int type) { return x; }\n";
        assert_eq!(check_glsl("f.glsl", ok.as_bytes()).unwrap(), ok);
        let bom = [b"\xEF\xBB\xBF".as_slice(), ok.as_bytes()].concat();
        assert_eq!(check_glsl("f.glsl", &bom).unwrap(), ok);
        let e = |s: &[u8]| check_glsl("f.glsl", s).unwrap_err();
        for (src, want) in [
            (b"#version 330 core\n".as_slice(), "f.glsl:1: `#version`"),
            (
                b"// x\n  #  extension GL_ARB_compute_shader : enable\n",
                "f.glsl:2: `#extension`",
            ),
            (
                b"/* a\nb */ #include \"common/rng.glsl\"\n",
                "f.glsl:2: `#include`",
            ),
            (b"\n\n#line 9999\n", "f.glsl:3: `#line`"),
            (
                b"vec3 force() {\n for ( ; ; ) {}\n}\n",
                "f.glsl:2: `for(;;)`",
            ),
            (
                b"vec3 force() {\0}\n",
                "f.glsl:1:15: control character U+0000",
            ),
            (b"vec3 force() {\n\xff}\n", "f.glsl:2:1: byte 0xff"),
            (b"vec3 f() { return vec3(0); }\n", "defines no `force`"),
            (b"#define A \\\n 1\n", "f.glsl:1: a line ends"),
            (b"vec3 force() {}\r\r\n", "f.glsl:1:16: a carriage return"),
        ] {
            assert!(e(src).contains(want), "{:?}: {}", src, e(src));
        }
        // In a comment, a directive is text.
        let commented = "// #version 330\nvec3 force(vec3 x, vec3 v, float age, int type) {\
                         return x; }\n";
        assert!(check_glsl("f.glsl", commented.as_bytes()).is_ok());
    }
}
