//! The scanners `tests/layout.rs` checks the source with: files, comments and literals blanked,
//! module paths and their cycles, function lengths. Rough by design, and tested on known text
//! there.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

pub fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

pub fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// The library's files (the CLI, `src/cli/` and `src/main.rs`, sits on top and is left out).
pub fn library_files() -> Vec<(PathBuf, Vec<String>)> {
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
pub fn code(text: &str) -> String {
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
pub fn referenced(code: &str) -> BTreeSet<(String, Option<String>)> {
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

/// Where `code` reaches a framebuffer's attachment by position rather than by handle: a literal
/// index to `texture(` or `back_single(`, or the attachment list indexed (`textures()[`,
/// `textures().first()`, `.last()`, `.get(`). Whitespace inside the call is ignored.
pub fn attachment_indices(code: &str) -> Vec<String> {
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

/// The text with comments, string and character literals blanked to spaces (newlines kept), so
/// that braces and paths are counted only where they are code. Rough: raw strings with `#`s,
/// escapes and lifetimes are handled; nothing else of Rust's lexer is.
pub fn blank_literals(text: &str) -> String {
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
pub fn literal_end(c: &[char], i: usize) -> Option<usize> {
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
pub fn block_comment_end(c: &[char], mut i: usize) -> usize {
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
pub fn raw_string_end(c: &[char], i: usize) -> Option<usize> {
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
pub fn without_tests(code: &str) -> String {
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
pub fn modules() -> Vec<(Vec<String>, String)> {
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
pub fn paths_named(me: &[String], code: &str) -> Vec<Vec<String>> {
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
pub fn sibling_edges() -> BTreeMap<String, BTreeSet<String>> {
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
pub fn references() -> Vec<(Vec<String>, Vec<(Vec<String>, Vec<String>)>)> {
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
pub fn cycles(edges: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
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

/// Where a function's body opens: the first `{` outside brackets, before any `;` outside them
/// (a declaration has none). A `;` inside brackets belongs to a type (`[u32; 2]`), not to the end
/// of a declaration.
pub fn body_open(sig: &str) -> Option<usize> {
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
pub fn function_lengths(root: &Path) -> Vec<(String, String, usize)> {
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
pub fn line_limit(root: &str, file: &str) -> usize {
    if root == "src" && (file.starts_with("cli/") || file == "main.rs") {
        100
    } else {
        80
    }
}
