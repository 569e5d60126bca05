//! The layout promised in docs/architecture.md, checked on the source itself (no GPU):
//! layers one way (`gl ← scene ← sim, sort, render ← engine ← bench, report ← cli`), no import
//! cycle between modules, no GL call outside `src/gl/`, no attachment picked by index nor texture
//! unit bound above it, no file over 600 lines (tests included) nor function over 80 (100 in the
//! CLI), and a pipeline of fragment passes only (no compute shaders, storage buffers, image stores or transform
//! feedback). The scanners are in `tests/scan/`.

mod scan;

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

use scan::*;

/// Each top-level module's layer; a module may import its own layer's peers (acyclically) and
/// anything below. `error`, `input`, `npy` and `output` are plain utilities every layer may use,
/// and so is `test_rng`, the unit tests' random numbers.
fn layer(module: &str) -> Option<u32> {
    Some(match module {
        "error" | "input" | "npy" | "output" | "test_rng" => 0,
        "gl" => 1,
        "scene" => 2,
        "sim" | "sort" | "render" => 3,
        "engine" => 4,
        "bench" | "report" | "trace" => 5,
        _ => return None,
    })
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

/// Texture units are the gl layer's: a draw lists its textures (`Draw::textures`) and
/// `Context::draw` assigns the units. Above `src/gl/` no `bind(...)` takes an argument (a unit;
/// programs, framebuffers and vertex arrays bind with none), and `src/gl/` exports no method
/// that binds a texture to a unit.
#[test]
fn no_texture_unit_is_bound_above_the_gl_layer() {
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    let gl = src().join("gl");
    let mut offenders = Vec::new();
    for p in &files {
        let c = code(&fs::read_to_string(p).unwrap());
        if p.starts_with(&gl) {
            for sig in ["pub fn bind(&self, unit", "pub fn textures(&self, list"] {
                if c.contains(sig) {
                    offenders.push(format!("{}: `{sig}` is public", p.display()));
                }
            }
        } else if c
            .split(".bind(")
            .skip(1)
            .any(|rest| !rest.trim_start().starts_with(')'))
        {
            offenders.push(format!("{}: binds a texture unit", p.display()));
        }
    }
    assert!(
        offenders.is_empty(),
        "units bound outside Context::draw: {offenders:?}"
    );
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
    // The tests too: each integration test file is split by topic, its helpers in tests/common/.
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&src(), &mut files);
    rust_files(&manifest.join("tests"), &mut files);
    files.sort();
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
