//! The layout promised in docs/architecture.md, checked on the source itself (no GPU):
//! layers one way (`gl ← scene ← sim, sort, render ← engine ← bench, report ← cli`), no import
//! cycle between modules, no GL call outside `src/gl/`, no file over 600 lines, and a pipeline
//! of fragment passes only (no compute shaders, storage buffers, image stores or transform
//! feedback).

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// Each top-level module's layer; a module may import its own layer's peers (acyclically) and
/// anything below. `error`, `input`, `npy` and `output` are plain utilities every layer may use.
fn layer(module: &str) -> Option<u32> {
    Some(match module {
        "error" | "input" | "npy" | "output" => 0,
        "gl" => 1,
        "scene" => 2,
        "sim" | "sort" | "render" => 3,
        "engine" => 4,
        "bench" | "report" | "trace" => 5,
        _ => return None,
    })
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The library's files (the CLI, `src/cli/` and `src/main.rs`, sits on top and is left out).
fn library_files() -> Vec<(PathBuf, Vec<String>)> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.sort();
    files
        .into_iter()
        .filter_map(|p| {
            let rel: Vec<String> = p
                .strip_prefix(src())
                .unwrap()
                .with_extension("")
                .iter()
                .map(|c| c.to_string_lossy().into_owned())
                .collect();
            (rel[0] != "cli" && rel[0] != "main" && rel[0] != "lib").then_some((p, rel))
        })
        .collect()
}

/// Code without comments: `//` to the end of the line (doc links may name any module).
fn code(text: &str) -> String {
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) if !l[..i].contains('"') => &l[..i],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The modules a file names through `crate::a::b` (also inside `use crate::{a::b, c}`), as
/// `a` and `a::b`.
fn referenced(code: &str) -> BTreeSet<(String, Option<String>)> {
    let mut out = BTreeSet::new();
    let ident = |s: &str| -> String {
        s.chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut rest = code;
    while let Some(i) = rest.find("crate::") {
        let after = &rest[i + 7..];
        if let Some(group) = after.strip_prefix('{') {
            let end = group.find('}').unwrap_or(group.len());
            for part in group[..end].split(',') {
                let part = part.trim();
                let a = ident(part);
                let b = part
                    .strip_prefix(&format!("{a}::"))
                    .map(ident)
                    .filter(|b| !b.is_empty() && b.chars().next().unwrap().is_lowercase());
                if !a.is_empty() && a != "self" {
                    out.insert((a, b));
                }
            }
        } else {
            let a = ident(after);
            let b = after
                .strip_prefix(&format!("{a}::"))
                .map(ident)
                .filter(|b| !b.is_empty() && b.chars().next().unwrap().is_lowercase());
            out.insert((a, b));
        }
        rest = &rest[i + 7..];
    }
    out
}

#[test]
fn layers_are_imported_one_way() {
    let mut upward = Vec::new();
    for (path, rel) in library_files() {
        let me = &rel[0];
        let Some(mine) = layer(me) else {
            upward.push(format!("{}: module `{me}` has no layer", path.display()));
            continue;
        };
        for (a, _) in referenced(&code(&fs::read_to_string(&path).unwrap())) {
            match layer(&a) {
                Some(l) if l > mine => upward.push(format!(
                    "{} (layer {mine}) imports crate::{a} (layer {l})",
                    path.display()
                )),
                None if a != "Error" && a != "Result" => upward.push(format!(
                    "{} imports crate::{a}, which has no layer",
                    path.display()
                )),
                _ => {}
            }
        }
    }
    assert!(upward.is_empty(), "upward imports:\n{}", upward.join("\n"));
}

#[test]
fn no_import_cycle_between_modules() {
    // Nodes: top-level modules and their direct submodules (`sim`, `sim::collide`, ...).
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (path, rel) in library_files() {
        let from_top = rel[0].clone();
        let from_sub = rel
            .get(1)
            .filter(|s| *s != "mod")
            .map(|s| format!("{from_top}::{s}"));
        let text = code(&fs::read_to_string(&path).unwrap());
        for (a, b) in referenced(&text) {
            if a != from_top {
                edges.entry(from_top.clone()).or_default().insert(a.clone());
            }
            // Between sibling submodules of one module (not parent and child).
            if let (Some(fs), Some(b)) = (&from_sub, b) {
                let to = format!("{a}::{b}");
                if a == from_top && &to != fs {
                    edges.entry(fs.clone()).or_default().insert(to);
                }
            }
        }
    }
    // Depth-first search for a back edge.
    fn visit(
        n: &str,
        edges: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        match state.get(n) {
            Some(1) => {
                let i = stack.iter().position(|s| s == n).unwrap();
                let mut cycle = stack[i..].to_vec();
                cycle.push(n.to_owned());
                return Some(cycle);
            }
            Some(2) => return None,
            _ => {}
        }
        state.insert(n.to_owned(), 1);
        stack.push(n.to_owned());
        for m in edges.get(n).into_iter().flatten() {
            if let Some(c) = visit(m, edges, state, stack) {
                return Some(c);
            }
        }
        stack.pop();
        state.insert(n.to_owned(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in edges.keys() {
        if let Some(c) = visit(n, &edges, &mut state, &mut Vec::new()) {
            panic!("import cycle: {}", c.join(" -> "));
        }
    }
}

#[test]
fn no_gl_call_outside_the_gl_layer() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let gl = src().join("gl");
    let offenders: Vec<String> = files
        .iter()
        .filter(|p| !p.starts_with(&gl))
        .filter(|p| {
            let c = code(&fs::read_to_string(p).unwrap());
            c.contains("glow::") || c.contains("unsafe")
        })
        .map(|p| p.display().to_string())
        .collect();
    assert!(
        offenders.is_empty(),
        "GL or unsafe code outside src/gl/: {offenders:?}"
    );
}

#[test]
fn no_source_file_over_600_lines() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let long: Vec<String> = files
        .iter()
        .filter_map(|p| {
            let n = fs::read_to_string(p).unwrap().lines().count();
            (n > 600).then(|| format!("{} ({n} lines)", p.display()))
        })
        .collect();
    assert!(long.is_empty(), "files over 600 lines: {long:?}");
}

#[test]
fn the_pipeline_is_fragment_passes_only() {
    // GLSL: no compute stage, storage blocks, image stores or atomics.
    let mut shaders = Vec::new();
    fn walk(d: &Path, out: &mut Vec<PathBuf>) {
        for e in fs::read_dir(d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out)
            } else {
                out.push(p)
            }
        }
    }
    walk(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl"),
        &mut shaders,
    );
    assert!(shaders.len() > 20, "glsl/ holds the passes");
    for p in &shaders {
        let text = code(&fs::read_to_string(p).unwrap());
        for banned in [
            "local_size_x",
            "imageStore",
            "imageLoad",
            "atomicAdd",
            "atomicCounter",
            "buffer ",
            "shared ",
        ] {
            assert!(
                !text.contains(banned),
                "{} uses `{banned}`: the pipeline is fragment passes only",
                p.display()
            );
        }
    }
    // GL: no compute dispatch, storage buffers or transform feedback anywhere.
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    for p in files {
        let text = code(&fs::read_to_string(&p).unwrap());
        for banned in [
            "dispatch_compute",
            "COMPUTE_SHADER",
            "SHADER_STORAGE",
            "TRANSFORM_FEEDBACK",
            "begin_transform_feedback",
            "bind_image_texture",
        ] {
            assert!(
                !text.contains(banned),
                "{} uses `{banned}`: the pipeline is fragment passes only",
                p.display()
            );
        }
    }
}

#[test]
fn the_scanner_finds_what_it_looks_for() {
    // The checks above are only as good as the parsing: test it on known text.
    let r = referenced("use crate::{gl::Context, scene};\nlet x = crate::sim::fire::X;");
    assert!(r.contains(&("gl".into(), None)), "{r:?}");
    assert!(r.iter().any(|(a, _)| a == "scene"));
    assert!(r.contains(&("sim".into(), Some("fire".into()))));
    assert_eq!(code("let a = 1; // crate::engine"), "let a = 1; ");
    assert_eq!(layer("engine"), Some(4));
    assert!(layer("engine") > layer("sim"));
}
