//! The layout promised in docs/architecture.md, checked on the source itself (no GPU):
//! layers one way (`gl ← scene ← sim, sort, render ← engine ← bench, report ← cli`), no import
//! cycle between modules, no GL call outside `src/gl/`, no attachment picked by index above it,
//! no file over 600 lines nor function over 100, and a pipeline of fragment passes only (no
//! compute shaders, storage buffers, image stores or transform feedback).

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

/// Where `code` reaches a framebuffer's attachment by position rather than by handle: a literal
/// index to `texture(` or `back_single(`, or the attachment list indexed (`textures()[`,
/// `textures().first()`, `.last()`, `.get(`). Whitespace inside the call is ignored.
fn attachment_indices(code: &str) -> Vec<String> {
    let squeezed: String = code.chars().filter(|c| !c.is_whitespace()).collect();
    let mut found = Vec::new();
    for call in [".texture(", ".back_single("] {
        for (i, _) in squeezed.match_indices(call) {
            let arg = &squeezed[i + call.len()..];
            if arg.starts_with(|c: char| c.is_ascii_digit()) {
                let end = arg.find(')').unwrap_or(arg.len());
                found.push(format!("{call}{})", &arg[..end]));
            }
        }
    }
    for indexed in [
        ".textures()[",
        ".textures().first()",
        ".textures().last()",
        ".textures().get(",
    ] {
        found.extend(squeezed.matches(indexed).map(str::to_owned));
    }
    found
}

/// Files above `src/gl/` allowed to pick attachments by position: none. Every framebuffer above
/// the gl layer is reached through handles (`gl::Attachment`, `Framebuffer::only_texture`). A
/// listed file must still have such a use, and no other file may have one.
const ATTACHMENT_INDEX_NOT_YET_NAMED: &[&str] = &[];

#[test]
fn no_attachment_index_above_the_gl_layer() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.sort();
    let gl = src().join("gl");
    let mut offenders = Vec::new();
    let mut named = Vec::new();
    for p in files.iter().filter(|p| !p.starts_with(&gl)) {
        let rel = p.strip_prefix(src()).unwrap().display().to_string();
        let found = attachment_indices(&code(&fs::read_to_string(p).unwrap()));
        let allowed = ATTACHMENT_INDEX_NOT_YET_NAMED.contains(&rel.as_str());
        if !found.is_empty() && !allowed {
            offenders.push(format!("src/{rel}: {}", found.join(", ")));
        }
        if found.is_empty() && allowed {
            named.push(format!("src/{rel}"));
        }
    }
    assert!(
        offenders.is_empty(),
        "attachments picked by index above src/gl (name them: gl::Attachment handles, or \
         Framebuffer::only_texture for a framebuffer of one):\n{}",
        offenders.join("\n")
    );
    assert!(
        named.is_empty(),
        "no attachment index left (take them off ATTACHMENT_INDEX_NOT_YET_NAMED):\n{}",
        named.join("\n")
    );
}

#[test]
fn the_attachment_index_scanner_finds_indices_not_handles() {
    let code = "a.texture(0).read(); b.front().texture( 2 ); pp.back_single(1);\n\
                s.textures().last(); t.textures()[3]; a.texture(POSITION); a.texture(i);\n\
                a.only_texture(); s.textures().len(); a.texture3d(0);";
    assert_eq!(
        attachment_indices(code),
        [
            ".texture(0)",
            ".texture(2)",
            ".back_single(1)",
            ".textures()[",
            ".textures().last()"
        ]
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
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    walk(&root.join("glsl"), &mut shaders);
    assert!(shaders.len() > 20, "glsl/ holds the passes");
    walk(&root.join("tests/glsl"), &mut shaders);
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

/// The text with comments, string and character literals blanked to spaces (newlines kept), so
/// that braces and paths are counted only where they are code. Rough: raw strings with `#`s,
/// escapes and lifetimes are handled; nothing else of Rust's lexer is.
fn blank_literals(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < c.len() {
        match literal_end(&c, i) {
            Some(end) => {
                let end = end.min(c.len());
                out.extend(
                    c[i..end]
                        .iter()
                        .map(|&ch| if ch == '\n' { '\n' } else { ' ' }),
                );
                i = end;
            }
            None => {
                out.push(c[i]);
                i += 1;
            }
        }
    }
    out
}

/// Where the comment or literal that starts at `i` ends (one past its last character), or
/// `None` where none starts there.
fn literal_end(c: &[char], i: usize) -> Option<usize> {
    let at = |k: usize| c.get(k).copied().unwrap_or('\0');
    match (c[i], at(i + 1)) {
        ('/', '/') => Some((i..c.len()).find(|&k| c[k] == '\n').unwrap_or(c.len())),
        ('/', '*') => Some(block_comment_end(c, i)),
        ('r', '"' | '#')
            if !(at(i + 1) == '#' && at(i + 2) == '[')
                && !(i > 0 && (c[i - 1].is_alphanumeric() || c[i - 1] == '_')) =>
        {
            raw_string_end(c, i)
        }
        ('"', _) => {
            let mut j = i + 1;
            while j < c.len() && c[j] != '"' {
                j += if c[j] == '\\' { 2 } else { 1 };
            }
            Some(j + 1)
        }
        // A character literal ('{', '\n', '\u{7f}'), not a lifetime.
        ('\'', _) if at(i + 1) == '\\' || at(i + 2) == '\'' => {
            let mut j = i + if at(i + 1) == '\\' { 3 } else { 2 };
            while j < c.len() && c[j] != '\'' {
                j += 1;
            }
            Some(j + 1)
        }
        _ => None,
    }
}

/// The end of a (nested) block comment that opens at `i`.
fn block_comment_end(c: &[char], mut i: usize) -> usize {
    let at = |k: usize| c.get(k).copied().unwrap_or('\0');
    let mut depth = 0;
    while i < c.len() {
        if c[i] == '/' && at(i + 1) == '*' {
            depth += 1;
            i += 2;
        } else if c[i] == '*' && at(i + 1) == '/' {
            depth -= 1;
            i += 2;
            if depth == 0 {
                break;
            }
        } else {
            i += 1;
        }
    }
    i
}

/// The end of a raw string `r"…"` or `r#"…"#` that opens at `i`, or `None` where the `r` starts
/// no raw string.
fn raw_string_end(c: &[char], i: usize) -> Option<usize> {
    let at = |k: usize| c.get(k).copied().unwrap_or('\0');
    let mut j = i + 1;
    let mut hashes = 0;
    while at(j) == '#' {
        hashes += 1;
        j += 1;
    }
    if at(j) != '"' {
        return None;
    }
    let close: String = std::iter::once('"')
        .chain(std::iter::repeat_n('#', hashes))
        .collect();
    let rest: String = c[j + 1..].iter().collect();
    let len = rest
        .find(&close)
        .map_or(rest.len(), |k| rest[..k].chars().count());
    Some(j + 1 + len + 1 + hashes)
}

/// The code of a file without its test modules (`#[cfg(test)] mod x { ... }` or `mod x;`).
fn without_tests(code: &str) -> String {
    let mut out = code.to_owned();
    while let Some(i) = out.find("#[cfg(test)]") {
        let after = &out[i..];
        let Some(m) = after.find("mod ") else { break };
        let body = &after[m..];
        let end = match (body.find('{'), body.find(';')) {
            (Some(b), s) if s.is_none_or(|s| b < s) => {
                let mut depth = 0;
                let mut end = body.len();
                for (k, ch) in body.char_indices().skip(b) {
                    depth += match ch {
                        '{' => 1,
                        '}' => -1,
                        _ => 0,
                    };
                    if depth == 0 {
                        end = k + 1;
                        break;
                    }
                }
                end
            }
            (_, Some(s)) => s + 1,
            _ => body.len(),
        };
        out.replace_range(i..i + m + end, "");
    }
    out
}

/// Every Rust file under `src/` (library and CLI) as its module path (`["report", "stability",
/// "extremes"]`; a folder's `mod.rs` is the folder) and its code without comments, literals and
/// test modules. The crate roots (`lib.rs`, `main.rs`) are left out.
fn modules() -> Vec<(Vec<String>, String)> {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    files.sort();
    files
        .into_iter()
        .filter_map(|p| {
            let mut rel: Vec<String> = p
                .strip_prefix(src())
                .unwrap()
                .with_extension("")
                .iter()
                .map(|c| c.to_string_lossy().into_owned())
                .collect();
            if rel.last().is_some_and(|l| l == "mod") {
                rel.pop();
            }
            let root = rel.len() == 1 && (rel[0] == "lib" || rel[0] == "main");
            let code = without_tests(&blank_literals(&fs::read_to_string(&p).unwrap()));
            (!root).then_some((rel, code))
        })
        .collect()
}

/// The paths a module's code names from `crate::`, `super::` and `self::` (use trees expanded),
/// as absolute module paths (`["scene", "sources", "builtin_mesh"]`; `[]` is the crate root).
fn paths_named(me: &[String], code: &str) -> Vec<Vec<String>> {
    fn ident(s: &str) -> &str {
        let n = s
            .find(|c: char| !(c.is_alphanumeric() || c == '_'))
            .unwrap_or(s.len());
        &s[..n]
    }
    // `rest` starts after `prefix::`; expands `a::b`, `a::{b, c::d}`, `a::*`.
    fn tree(prefix: Vec<String>, rest: &str, out: &mut Vec<Vec<String>>) {
        let rest = rest.trim_start();
        if let Some(group) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut start = 0;
            for (k, ch) in group.char_indices() {
                match ch {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        tree(prefix.clone(), &group[start..k], out);
                        return;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        tree(prefix.clone(), &group[start..k], out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            return;
        }
        let id = ident(rest);
        if id.is_empty() || id == "self" {
            out.push(prefix);
            return;
        }
        let mut p = prefix;
        p.push(id.to_owned());
        match rest[id.len()..].trim_start().strip_prefix("::") {
            Some(more) => tree(p, more, out),
            None => out.push(p),
        }
    }
    let mut out = Vec::new();
    let bytes = code.as_bytes();
    for start in ["crate::", "super::", "self::"] {
        for (i, _) in code.match_indices(start) {
            if i > 0
                && (bytes[i - 1].is_ascii_alphanumeric()
                    || bytes[i - 1] == b'_'
                    || bytes[i - 1] == b':')
            {
                continue;
            }
            // The module `self` is: the file's module; `super` climbs from there.
            let mut base: Vec<String> = match start {
                "crate::" => Vec::new(),
                _ => me.to_vec(),
            };
            let mut rest = &code[i + start.len()..];
            if start == "super::" {
                base.pop();
                while let Some(r) = rest.strip_prefix("super::") {
                    base.pop();
                    rest = r;
                }
            }
            tree(base, rest, &mut out);
        }
    }
    out
}

/// Edges between modules that are siblings (children of one folder, at any depth): a file's
/// reference to another module counts between the two children of their deepest common folder,
/// so `report/stability/extremes.rs` naming `report::stability::sort_cases` is an edge
/// `extremes -> sort_cases`, and naming `report::convergence` is `stability -> convergence`.
/// References to a module's own ancestors or descendants (a folder and its files) are not edges.
fn sibling_edges() -> BTreeMap<String, BTreeSet<String>> {
    let mut edges: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (me, refs) in references() {
        for (_, target) in refs {
            let common = me.iter().zip(&target).take_while(|(a, b)| a == b).count();
            if common < me.len() && common < target.len() {
                edges
                    .entry(me[..=common].join("::"))
                    .or_default()
                    .insert(target[..=common].join("::"));
            }
        }
    }
    edges
}

/// Each module with the paths it names, each beside the module it resolves into: the longest
/// prefix that is a module (`[]`, the crate root, when none is).
#[allow(clippy::type_complexity)]
fn references() -> Vec<(Vec<String>, Vec<(Vec<String>, Vec<String>)>)> {
    let mods = modules();
    let known: BTreeSet<Vec<String>> = mods.iter().map(|(m, _)| m.clone()).collect();
    mods.iter()
        .map(|(me, code)| {
            let refs = paths_named(me, code)
                .into_iter()
                .map(|path| {
                    let owner = (0..=path.len())
                        .rev()
                        .map(|n| path[..n].to_vec())
                        .find(|p| known.contains(p))
                        .unwrap_or_default();
                    (path, owner)
                })
                .collect();
            (me.clone(), refs)
        })
        .collect()
}

/// The strongly connected components with more than one node (Tarjan's algorithm).
fn cycles(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        edges: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<String, usize>,
        low: BTreeMap<String, usize>,
        stack: Vec<String>,
        on: BTreeSet<String>,
        out: Vec<Vec<String>>,
    }
    fn go(t: &mut T, v: &str) {
        let n = t.index.len();
        t.index.insert(v.to_owned(), n);
        t.low.insert(v.to_owned(), n);
        t.stack.push(v.to_owned());
        t.on.insert(v.to_owned());
        for w in t.edges.get(v).into_iter().flatten() {
            if !t.index.contains_key(w) {
                go(t, w);
                let l = t.low[v].min(t.low[w]);
                t.low.insert(v.to_owned(), l);
            } else if t.on.contains(w) {
                let l = t.low[v].min(t.index[w]);
                t.low.insert(v.to_owned(), l);
            }
        }
        if t.low[v] == t.index[v] {
            let mut scc = Vec::new();
            loop {
                let w = t.stack.pop().unwrap();
                t.on.remove(&w);
                scc.push(w.clone());
                if w == v {
                    break;
                }
            }
            if scc.len() > 1 {
                scc.sort();
                t.out.push(scc);
            }
        }
    }
    let mut t = T {
        edges,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in edges.keys() {
        if !t.index.contains_key(v) {
            go(&mut t, v);
        }
    }
    t.out
}

#[test]
fn no_import_cycle_between_the_files_of_a_folder() {
    let found = cycles(&sibling_edges());
    let text: Vec<String> = found.iter().map(|c| c.join(" <-> ")).collect();
    assert!(found.is_empty(), "import cycles:\n{}", text.join("\n"));
}

#[test]
fn nothing_is_imported_from_the_crate_root_and_gl_only_from_below() {
    // The crate root re-exports for users (`texflow::Error`); inside the crate every path names
    // the module that owns the item, so no module depends on `lib.rs` and through it on all.
    let mut bad = Vec::new();
    for (me, refs) in references() {
        for (path, owner) in refs {
            let name = path.join("::");
            if owner.is_empty() && !path.is_empty() && me[0] != "cli" {
                bad.push(format!("{}: crate::{name} (the crate root)", me.join("::")));
            } else if me[0] == "gl"
                && !owner.is_empty()
                && owner[0] != "gl"
                && layer(&owner[0]) != Some(0)
            {
                bad.push(format!("{}: crate::{name} (above gl)", me.join("::")));
            }
        }
    }
    assert!(bad.is_empty(), "imports back up:\n{}", bad.join("\n"));
}

#[test]
fn the_module_scanner_resolves_paths_and_finds_cycles() {
    let me = vec![
        "report".to_owned(),
        "stability".to_owned(),
        "extremes".to_owned(),
    ];
    let code =
        "use super::sort_cases::{ids, one};\nuse super::{case, Outcome};\nlet e = crate::Error::X;";
    let p = paths_named(&me, code);
    assert!(
        p.contains(&vec![
            "report".into(),
            "stability".into(),
            "sort_cases".into(),
            "one".into()
        ]),
        "{p:?}"
    );
    assert!(
        p.contains(&vec!["report".into(), "stability".into(), "case".into()]),
        "{p:?}"
    );
    assert!(p.contains(&vec!["Error".into(), "X".into()]), "{p:?}");
    let code = blank_literals("let s = \"crate::x { \"; // crate::y {\nlet c = '{'; fn f<'a>() {}");
    assert!(
        !code.contains("crate::") && code.matches('{').count() == 1,
        "{code}"
    );
    assert_eq!(
        without_tests("a\n#[cfg(test)]\nmod tests {\n fn x() { }\n}\nb"),
        "a\n\nb"
    );
    let mut e: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    e.entry("a".into()).or_default().insert("b".into());
    e.entry("b".into()).or_default().insert("c".into());
    assert!(cycles(&e).is_empty());
    e.entry("c".into()).or_default().insert("a".into());
    assert_eq!(
        cycles(&e),
        vec![vec!["a".to_owned(), "b".into(), "c".into()]]
    );
}

/// Where a function's body opens: the first `{` outside brackets, before any `;` outside them
/// (a declaration has none). A `;` inside brackets belongs to a type (`[u32; 2]`), not to the end
/// of a declaration.
fn body_open(sig: &str) -> Option<usize> {
    let mut depth = 0i32;
    for (k, ch) in sig.char_indices() {
        match ch {
            '(' | '[' => depth += 1,
            ')' | ']' => depth -= 1,
            '{' if depth == 0 => return Some(k),
            ';' if depth == 0 => return None,
            _ => {}
        }
    }
    None
}

/// Every function under `root` with a body: (file, name, lines from the `fn` line to the line of
/// its closing brace). Braces are matched on the code with comments and literals blanked.
fn function_lengths(root: &Path) -> Vec<(String, String, usize)> {
    let mut files = Vec::new();
    rust_files(root, &mut files);
    files.sort();
    let mut out = Vec::new();
    for p in files {
        let code = blank_literals(&fs::read_to_string(&p).unwrap());
        let rel = p.strip_prefix(root).unwrap().display().to_string();
        let b = code.as_bytes();
        for (i, _) in code.match_indices("fn ") {
            let word_start = i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
            let name: String = code[i + 3..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !word_start || name.is_empty() {
                continue;
            }
            let rest = &code[i..];
            let Some(open) = body_open(rest) else {
                continue;
            };
            let mut depth = 0i32;
            let mut close = None;
            for (k, ch) in rest[open..].char_indices() {
                depth += match ch {
                    '{' => 1,
                    '}' => -1,
                    _ => 0,
                };
                if depth == 0 {
                    close = Some(open + k);
                    break;
                }
            }
            let Some(close) = close else { continue };
            let lines = rest[..close].matches('\n').count() + 1;
            out.push((rel.clone(), name, lines));
        }
    }
    out
}

/// The longest a function may be: 100 lines in the CLI (`src/cli/`, `src/main.rs`, where a
/// command's options are read in one place), 80 everywhere else, tests included.
fn line_limit(root: &str, file: &str) -> usize {
    if root == "src" && (file.starts_with("cli/") || file == "main.rs") {
        100
    } else {
        80
    }
}

#[test]
fn no_function_over_its_line_limit() {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut long = Vec::new();
    for root in ["src", "tests"] {
        let all = function_lengths(&manifest.join(root));
        for limit in [60, 80, 100] {
            let n = all.iter().filter(|f| f.2 > limit).count();
            eprintln!("{root}: functions over {limit} lines: {n}");
        }
        let mut over: Vec<_> = all
            .iter()
            .filter(|(f, _, l)| *l > line_limit(root, f))
            .map(|(f, n, l)| format!("{root}/{f}: fn {n} ({l} lines)"))
            .collect();
        over.sort();
        long.extend(over);
    }
    assert!(
        long.is_empty(),
        "functions over their limit (100 lines in src/cli, 80 elsewhere):\n{}",
        long.join("\n")
    );
}

#[test]
fn the_function_counter_reads_signatures_with_brackets() {
    let sig = "fn f(a: [u32; 2]) -> [f32; 4] {\n    x\n}\nfn g(&self);\n";
    assert_eq!(body_open(sig), Some(sig.find('{').unwrap()));
    assert_eq!(body_open("fn g(&self);\nfn h() {}"), None);
}

#[test]
fn function_lengths_count_from_fn_to_its_closing_brace() {
    let text = "fn a() {\n    let s = \"}\";\n    if x { y }\n}\ntrait T { fn d(&self); }\nfn b<'a>(c: char) -> u8 { '{' as u8 }\n";
    let code = blank_literals(text);
    assert_eq!(
        code.matches('{').count(),
        code.matches('}').count(),
        "{code}"
    );
    assert_eq!(code.lines().count(), text.lines().count());
}
