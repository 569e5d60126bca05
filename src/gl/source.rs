//! The GLSL files under `glsl/`, embedded in the binary, and the `#include` resolver.
//!
//! Files carry no `#version` line: [`resolve`] prepends the version and the `#define`s, splices
//! `#include "path"` (each file at most once, so includes act as guarded), and emits
//! `#line N S` directives where `S` numbers the file and N is the line plus S × [`LINE_STRIDE`]:
//! Mesa 22 reports the source number 0 for an error inside an included function, so the line
//! carries the file as well. [`map_log`] turns the driver's `S:N` back into the file under
//! `glsl/` and its line.

use std::collections::HashSet;

use crate::error::{Error, Result};

macro_rules! embed {
    ($($path:literal),* $(,)?) => {
        &[$(($path, include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/glsl/", $path)))),*]
    };
}

/// Every GLSL file of the crate, by path relative to `glsl/`.
pub static EMBEDDED: &[(&str, &str)] = embed![
    "common/rng.glsl",
    "common/state.glsl",
    "common/fullscreen.vert",
    "common/write_floor.frag",
    "bench/render_floor.vert",
    "bench/render_floor_at.vert",
    "bench/fetch_probe.frag",
    "bench/fill_floor.frag",
    "bench/chain_floor.vert",
    "bench/chain_floor.frag",
    "bench/fetch_floor.frag",
    "bench/vertex_probe.vert",
    "common/compare.glsl",
    "common/precision.glsl",
    "common/mass.glsl",
    "sort/keys.frag",
    "sort/bitonic_fp.frag",
    "sort/gpfp.vert",
    "sort/bitonic_gpfp.frag",
    "sort/bitonic_packed.frag",
    "sort/oddeven_recursion.frag",
    "sort/oddeven_end.frag",
    "sort/multistep.frag",
    "sort/blocked.frag",
    "sort/blocked_unpack.frag",
    "sort/merge.frag",
    "sort/blocked_entry.glsl",
    "sort/first_id.glsl",
    "sort/merge_path.glsl",
    "sort/merge_search.glsl",
    "sort/merge_partition.frag",
    "sort/sorted_id.glsl",
    "sort/rearrange.frag",
    "sim/fire_init.frag",
    "sim/fire.frag",
    "sim/fields.glsl",
    "sim/spawn.glsl",
    "sim/stamp_birth.glsl",
    "sim/forces.glsl",
    "sim/colliders.glsl",
    "sim/stages.glsl",
    "sim/children.glsl",
    "sim/child_birth.glsl",
    "sim/integrate.frag",
    "sim/stateless.frag",
    "sim/init.frag",
    "sim/emit.vert",
    "sim/emit.frag",
    "sim/verlet_start.frag",
    "sim/constraint.glsl",
    "sim/constrain.frag",
    "sim/constrain_set.frag",
    "sim/attach.frag",
    "sim/nonfinite.frag",
    "sim/user_state.frag",
    "sim/user_state_inputs.glsl",
    "sim/user_state_step.glsl",
    "sim/sdf_slice.frag",
    "collide/detect.frag",
    "collide/mutual.frag",
    "collide/response.frag",
    "collide/copy.frag",
    "collide/exchange.frag",
    "collide/sorted_keys.glsl",
    "collide/cells.glsl",
    "collide/cell_block.frag",
    "collide/cell_start.frag",
    "collide/pair.glsl",
    "collide/spin.glsl",
    "collide/exact_count.frag",
    "collide/exact_response.frag",
    "collide/tally.frag",
    "collide/dem.glsl",
    "collide/neighbour_force.frag",
    "collide/neighbour_apply.frag",
    "fluid/kernel.glsl",
    "fluid/density.frag",
    "fluid/force.frag",
    "fluid/lattice.frag",
    "fluid/merge.frag",
    "fluid/order.frag",
    "render/fire_ramp.glsl",
    "render/shade_floor.glsl",
    "render/keyframes.glsl",
    "render/sprite.glsl",
    "render/birth_curves.glsl",
    "render/particle.vert",
    "render/particle.frag",
    "render/background.frag",
    "render/sprite_tile.glsl",
    "render/halfangle.vert",
    "render/halfangle_eye.frag",
    "render/halfangle_light.frag",
    "render/cpu_points.vert",
    "render/cpu_points.frag",
    "render/geometry.vert",
    "render/geometry.frag",
    "render/geometry_depth.frag",
    "render/cloth.vert",
    "render/cloth.frag",
    "render/strand.vert",
    "render/strand.frag",
    "render/ribbon.vert",
    "render/ribbon.frag",
];

/// Looks an embedded file up, then a source added at run time ([`add_runtime_source`]).
pub fn embedded(path: &str) -> Option<&'static str> {
    EMBEDDED
        .iter()
        .find(|(p, _)| *p == path)
        .map(|(_, s)| *s)
        .or_else(|| runtime_sources().lock().ok()?.get(path).copied())
}

fn runtime_sources() -> &'static std::sync::Mutex<std::collections::HashMap<String, &'static str>> {
    static SOURCES: std::sync::OnceLock<
        std::sync::Mutex<std::collections::HashMap<String, &'static str>>,
    > = std::sync::OnceLock::new();
    SOURCES.get_or_init(Default::default)
}

/// Adds a shader source that is not under `glsl/` (a scene's custom force, read from the user's
/// file), found by `#include "path"` and by [`Program::new`](super::Program::new) like an
/// embedded file; compile errors in it name `path` as given (no `glsl/` prefix). Adding the same
/// path again replaces its text (the old text stays allocated: sources live for the process).
pub fn add_runtime_source(path: &str, text: &str) {
    if let Ok(mut map) = runtime_sources().lock() {
        if map.get(path).is_some_and(|t| *t == text) {
            return;
        }
        map.insert(path.to_owned(), Box::leak(text.to_owned().into_boxed_str()));
    }
}

/// Whether `path` is a source added by [`add_runtime_source`] (and not an embedded file).
pub fn is_runtime_source(path: &str) -> bool {
    !EMBEDDED.iter().any(|(p, _)| *p == path)
        && runtime_sources().lock().is_ok_and(|m| m.contains_key(path))
}

/// Lines numbered per file in `#line` directives: file S's line n is S × LINE_STRIDE + n.
pub const LINE_STRIDE: u32 = 100_000;

/// The GLSL version line every program starts with.
pub const VERSION: &str = "#version 330 core";

/// A shader's text after includes are spliced, with the file behind each source number.
#[derive(Debug, Clone)]
pub struct Resolved {
    /// The complete source handed to the driver.
    pub text: String,
    /// `files[S]` is the path of source number `S` in `#line` directives.
    pub files: Vec<String>,
}

/// Builds the full text of shader `root`: version, `defines`, then the file with its includes.
pub fn resolve<'a>(
    root: &str,
    defines: &[(String, String)],
    lookup: &dyn Fn(&str) -> Option<&'a str>,
) -> Result<Resolved> {
    let mut text = format!("{VERSION}\n");
    for (k, v) in defines {
        text.push_str(&format!("#define {k} {v}\n"));
    }
    let mut files = Vec::new();
    let mut seen = HashSet::new();
    splice(root, lookup, &mut text, &mut files, &mut seen)?;
    Ok(Resolved { text, files })
}

fn splice<'a>(
    path: &str,
    lookup: &dyn Fn(&str) -> Option<&'a str>,
    out: &mut String,
    files: &mut Vec<String>,
    seen: &mut HashSet<String>,
) -> Result<()> {
    let src = lookup(path).ok_or_else(|| Error::MissingSource(path.to_owned()))?;
    seen.insert(path.to_owned());
    let index = files.len();
    files.push(path.to_owned());
    let base = index as u32 * LINE_STRIDE;
    out.push_str(&format!("#line {} {index}\n", base + 1));
    for (n, line) in src.lines().enumerate() {
        match include_target(line) {
            Some(Ok(inc)) => {
                if !seen.contains(inc) {
                    splice(inc, lookup, out, files, seen)?;
                    // `#line N` numbers the line that follows it.
                    out.push_str(&format!("#line {} {index}\n", base + n as u32 + 2));
                } else {
                    out.push('\n');
                }
            }
            Some(Err(())) => {
                return Err(Error::ShaderCompile {
                    file: path.to_owned(),
                    line: n as u32 + 1,
                    log: format!("malformed #include (expected #include \"path\"): {line}"),
                })
            }
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    Ok(())
}

/// `Some(Ok(path))` for `#include "path"`, `Some(Err)` for a malformed include, `None` otherwise.
fn include_target(line: &str) -> Option<Result<&str, ()>> {
    let rest = line.trim_start().strip_prefix('#')?.trim_start();
    let rest = rest.strip_prefix("include")?.trim();
    let inner = rest.strip_prefix('"').and_then(|r| r.strip_suffix('"'));
    Some(inner.filter(|s| !s.is_empty()).ok_or(()))
}

/// Finds a `S:N(` (Mesa) or `S(N)` (NVIDIA) location at the start of a log line.
fn locate(line: &str) -> Option<(usize, u32, usize)> {
    let digits = |s: &str| s.bytes().take_while(u8::is_ascii_digit).count();
    let trimmed = line.trim_start();
    let lead = line.len() - trimmed.len();
    let ds = digits(trimmed);
    if ds == 0 {
        return None;
    }
    let source: usize = trimmed[..ds].parse().ok()?;
    let rest = &trimmed[ds..];
    let (sep, close) = if rest.starts_with(':') {
        (':', None)
    } else if rest.starts_with('(') {
        ('(', Some(')'))
    } else {
        return None;
    };
    let after = &rest[sep.len_utf8()..];
    let dl = digits(after);
    if dl == 0 {
        return None;
    }
    let line_no: u32 = after[..dl].parse().ok()?;
    let mut end = lead + ds + 1 + dl;
    if let Some(c) = close {
        if !after[dl..].starts_with(c) {
            return None;
        }
        end += 1;
    }
    Some((source, line_no, end))
}

/// Rewrites a driver log so that locations name `glsl/` files; returns the first location too.
pub fn map_log(log: &str, files: &[String]) -> (String, Option<(String, u32)>) {
    let mut first = None;
    let mut out = String::new();
    for line in log.lines() {
        // The line names the file where it is past LINE_STRIDE (whatever source the driver
        // says); below it, the source number does (file 0, or a driver's own numbering).
        let located = locate(line).map(|(s, n, end)| match n >= LINE_STRIDE {
            true => ((n / LINE_STRIDE) as usize, n % LINE_STRIDE, end),
            false => (s, n, end),
        });
        match located.filter(|(s, _, _)| *s < files.len()) {
            Some((s, n, end)) => {
                if first.is_none() {
                    first = Some((files[s].clone(), n));
                }
                let prefix = if is_runtime_source(&files[s]) {
                    ""
                } else {
                    "glsl/"
                };
                out.push_str(&format!("{prefix}{}:{}{}\n", files[s], n, &line[end..]));
            }
            None => {
                out.push_str(line);
                out.push('\n');
            }
        }
    }
    (out, first)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lookup(p: &str) -> Option<&'static str> {
        match p {
            "a.frag" => Some("line1\n#include \"b.glsl\"\nline3\n#include \"b.glsl\"\nline5\n"),
            "b.glsl" => Some("b1\n#include \"c.glsl\"\nb3\n"),
            "c.glsl" => Some("c1\n"),
            "bad.frag" => Some("ok\n#include b.glsl\n"),
            "cycle.glsl" => Some("#include \"cycle.glsl\"\nx\n"),
            _ => None,
        }
    }

    #[test]
    fn includes_are_spliced_once_with_line_directives() {
        let r = resolve("a.frag", &[("N".into(), "3".into())], &lookup).unwrap();
        assert_eq!(r.files, ["a.frag", "b.glsl", "c.glsl"]);
        let expected = "#version 330 core\n#define N 3\n#line 1 0\nline1\n#line 100001 1\nb1\n\
                        #line 200001 2\nc1\n#line 100003 1\nb3\n#line 3 0\nline3\n\nline5\n";
        assert_eq!(r.text, expected);
    }

    #[test]
    fn self_include_terminates() {
        let r = resolve("cycle.glsl", &[], &lookup).unwrap();
        assert_eq!(r.files, ["cycle.glsl"]);
    }

    #[test]
    fn missing_and_malformed_includes_are_errors() {
        assert!(matches!(
            resolve("nope.frag", &[], &lookup),
            Err(Error::MissingSource(p)) if p == "nope.frag"
        ));
        match resolve("bad.frag", &[], &lookup) {
            Err(Error::ShaderCompile { file, line, .. }) => {
                assert_eq!((file.as_str(), line), ("bad.frag", 2))
            }
            other => panic!("expected a compile error, got {other:?}"),
        }
    }

    #[test]
    fn driver_logs_are_mapped_to_files() {
        let files = vec!["sim/fire.frag".to_string(), "common/rng.glsl".to_string()];
        let mesa = "1:7(12): error: syntax error\n0:3(1): warning: x\n";
        let (log, first) = map_log(mesa, &files);
        assert_eq!(first, Some(("common/rng.glsl".into(), 7)));
        assert!(
            log.starts_with("glsl/common/rng.glsl:7(12): error"),
            "{log}"
        );
        assert!(log.contains("glsl/sim/fire.frag:3(1): warning"));
        let nvidia = "0(42) : error C0000: syntax error\n";
        let (log, first) = map_log(nvidia, &files);
        assert_eq!(first, Some(("sim/fire.frag".into(), 42)));
        assert!(log.starts_with("glsl/sim/fire.frag:42 : error"), "{log}");
        // The line carries the file: Mesa's source 0 inside an included function.
        let (log, first) = map_log("0:100007(3): error: x\n", &files);
        assert_eq!(first, Some(("common/rng.glsl".into(), 7)));
        assert!(log.starts_with("glsl/common/rng.glsl:7(3): error"), "{log}");
    }

    #[test]
    fn every_embedded_file_resolves() {
        // (Resolving checks includes only; the GPU tests compile them.)
        for (path, _) in EMBEDDED {
            resolve(path, &[], &embedded).unwrap();
        }
    }

    #[test]
    fn every_glsl_file_is_embedded() {
        // A shader that exists in glsl/ but not in EMBEDDED fails only at run time, in whatever
        // pass first needs it: list them all here instead.
        fn walk(dir: &std::path::Path, root: &std::path::Path, out: &mut Vec<String>) {
            for e in std::fs::read_dir(dir).unwrap() {
                let path = e.unwrap().path();
                if path.is_dir() {
                    walk(&path, root, out);
                } else {
                    let rel = path.strip_prefix(root).unwrap();
                    out.push(rel.to_string_lossy().replace('\\', "/"));
                }
            }
        }
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
        let mut on_disk = Vec::new();
        walk(&root, &root, &mut on_disk);
        on_disk.sort();
        let mut embedded: Vec<String> = EMBEDDED.iter().map(|(p, _)| p.to_string()).collect();
        embedded.sort();
        let missing: Vec<&String> = on_disk.iter().filter(|f| !embedded.contains(f)).collect();
        assert!(
            missing.is_empty(),
            "glsl/ files not in EMBEDDED (src/gl/source.rs): {missing:?}"
        );
        assert_eq!(
            on_disk, embedded,
            "EMBEDDED names files that are not in glsl/"
        );
    }
}
