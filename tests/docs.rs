//! The docs as a stranger reads them: no issue numbers, no paths outside the repository, no TODO;
//! every relative link points to a file in the repository; and every concrete `texflow ...`
//! command line of README.md and examples/README.md runs and exits 0 (at small sizes, its
//! outputs in a temporary folder).

use std::path::{Path, PathBuf};
use std::process::Command;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The Markdown files a reader sees: README.md, CHANGELOG.md, examples/README.md, docs/**.md.
fn markdown_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .collect();
        entries.sort();
        for p in entries {
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|e| e == "md") {
                out.push(p);
            }
        }
    }
    let root = Path::new(ROOT);
    let mut out: Vec<PathBuf> = ["README.md", "CHANGELOG.md", "examples/README.md"]
        .iter()
        .map(|f| root.join(f))
        .collect();
    walk(&root.join("docs"), &mut out);
    out
}

fn rel(p: &Path) -> String {
    p.strip_prefix(ROOT).unwrap_or(p).display().to_string()
}

/// "issue 12", "Issue 14", "issue #3": a reference to the project's tracker.
fn issue_number(line: &str) -> bool {
    let lower = line.to_lowercase();
    lower.match_indices("issue").any(|(i, m)| {
        let rest = lower[i + m.len()..].trim_start_matches('s');
        let rest = rest.trim_start_matches([' ', '#']);
        rest.starts_with(|c: char| c.is_ascii_digit())
    })
}

#[test]
fn docs_name_no_issue_numbers_outside_paths_or_todos() {
    let mut found = Vec::new();
    let mut files = markdown_files();
    files.push(Path::new(ROOT).join("docs/img/make.sh"));
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (n, line) in text.lines().enumerate() {
            let what = if issue_number(line) {
                "an issue number"
            } else if line.contains("../shared") {
                "a path outside the repository"
            } else if line.contains("TODO") {
                "a TODO"
            } else {
                continue;
            };
            found.push(format!("{}:{}: {what}: {}", rel(f), n + 1, line.trim()));
        }
    }
    assert!(found.is_empty(), "\n{}", found.join("\n"));
}

#[test]
fn the_checks_of_the_docs_find_what_they_look_for() {
    assert!(issue_number("as issue 12 asked"));
    assert!(issue_number("Issue #3"));
    assert!(issue_number("issues 4"));
    assert!(!issue_number("no issue here, 12 frames"));
    assert_eq!(
        links("see [a](docs/a.md#x), ![p](img/p.png) and [w](https://x.org) [t](#top)"),
        vec!["docs/a.md#x", "img/p.png", "https://x.org", "#top"]
    );
    let cmds = commands(
        "Run `texflow render fire --frames 9`.\n\n    texflow info   # devices\n    \
         texflow render [SCENE]\n\n```sh\ntexflow scene list\n```\n`texflow = { path }`",
    );
    assert_eq!(
        cmds,
        vec![
            "texflow info",
            "texflow scene list",
            "texflow render fire --frames 9"
        ]
    );
}

/// The targets of Markdown links and images: `[text](target)`.
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find("](") {
        let after = &rest[i + 2..];
        match after.find(')') {
            Some(j) => {
                let target = after[..j].trim();
                // A title after the target: `[a](b "title")`.
                let target = target.split_whitespace().next().unwrap_or("");
                out.push(target.to_owned());
                rest = &after[j..];
            }
            None => break,
        }
    }
    out
}

#[test]
fn every_relative_link_points_to_a_file_in_the_repository() {
    let mut broken = Vec::new();
    for f in markdown_files() {
        let text = std::fs::read_to_string(&f).unwrap();
        for target in links(&text) {
            if target.is_empty()
                || target.starts_with('#')
                || target.contains("://")
                || target.starts_with("mailto:")
            {
                continue;
            }
            let path = target.split('#').next().unwrap_or("");
            let resolved = f.parent().unwrap().join(path);
            let inside = resolved
                .canonicalize()
                .is_ok_and(|p| p.starts_with(Path::new(ROOT).canonicalize().unwrap()));
            if !resolved.exists() || !inside {
                broken.push(format!("{}: ({target})", rel(&f)));
            }
        }
    }
    assert!(
        broken.is_empty(),
        "links to no file:\n{}",
        broken.join("\n")
    );
}

/// The commands a reader would copy: `texflow ...` lines in code blocks (fenced or indented,
/// without their `# comment`) and in inline code, in that order. A synopsis (`[SCENE]`, `A|B`,
/// `...`, a placeholder in capitals such as `FILE` or `N`) is not a command and is left out, as
/// is anything whose second word is not a subcommand.
fn commands(md: &str) -> Vec<String> {
    let mut blocks = Vec::new();
    let mut prose = String::new();
    let mut fenced = false;
    for line in md.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced || line.starts_with("    ") {
            let code = line.split(" #").next().unwrap_or("").trim();
            if code.starts_with("texflow ") {
                blocks.push(code.to_owned());
            }
        } else {
            prose.push_str(line);
            prose.push('\n');
        }
    }
    let inline = prose
        .split('`')
        .skip(1)
        .step_by(2)
        .map(|s| s.split_whitespace().collect::<Vec<_>>().join(" "))
        .filter(|s| s.starts_with("texflow "));
    let subcommands = [
        "info",
        "render",
        "view",
        "sort",
        "collide-stats",
        "scene",
        "bench",
        "report",
    ];
    // FILE, N, SCENE, WxH; not E4 or 512x512.
    let placeholder = |w: &str| {
        let w = w.trim_matches(|c: char| !c.is_alphanumeric());
        w == "WxH" || (!w.is_empty() && w.chars().all(|c| c.is_ascii_uppercase()))
    };
    blocks
        .into_iter()
        .chain(inline)
        .filter(|c| {
            let words: Vec<&str> = c.split_whitespace().collect();
            words.len() > 1
                && subcommands.contains(&words[1])
                && !c.contains(['[', '|'])
                && !c.contains("...")
                && !words.iter().skip(1).any(|w| placeholder(w))
        })
        .collect()
}

/// `line` at small sizes, its outputs under `tmp` (`n` numbers them), scene files by absolute
/// path (the command runs in `tmp`).
fn small(line: &str, tmp: &Path, n: usize) -> Vec<String> {
    let words: Vec<&str> = line.split_whitespace().skip(1).collect();
    let value = |flag: &str| {
        words
            .iter()
            .position(|w| *w == flag)
            .and_then(|i| words.get(i + 1))
            .map(|v| v.to_string())
    };
    let number = |flag: &str, default: u64| {
        value(flag)
            .and_then(|v| v.parse::<u64>().ok())
            .unwrap_or(default)
    };
    let start = number("--start", 0);
    // Enough frames for what is written: three, or the frames a `--loop` fade needs.
    let frames = start + number("--every", 1) * (3 + 2 * number("--loop", 0));
    let out = |what: &str| tmp.join(format!("{n}_{what}")).display().to_string();
    let mut args: Vec<String> = Vec::new();
    let mut i = 0;
    while i < words.len() {
        let w = words[i];
        let next = words.get(i + 1).copied().unwrap_or("");
        let replaced = match w {
            "--particles" | "--resolution" => Some("32x32".to_owned()),
            "--frames" => Some(
                next.parse::<u64>()
                    .map_or(next.to_owned(), |f| f.min(frames).to_string()),
            ),
            "--sizes" => Some("16".to_owned()),
            "--steps" => Some("4".to_owned()),
            "--repeats" | "--runs" => Some("1".to_owned()),
            "--out" | "--dump-state" => Some(out(&w[2..])),
            "--video" | "--screenshot" => {
                let ext = Path::new(next)
                    .extension()
                    .map_or(String::new(), |e| format!(".{}", e.to_string_lossy()));
                Some(format!("{}{ext}", out(&w[2..])))
            }
            _ => None,
        };
        args.push(w.to_owned());
        if let Some(v) = replaced {
            args.push(v);
            i += 2;
            continue;
        }
        if w.ends_with(".toml") && Path::new(ROOT).join(w).exists() {
            args.pop();
            args.push(Path::new(ROOT).join(w).display().to_string());
        }
        i += 1;
    }
    let has = |args: &[String], f: &str| args.iter().any(|a| a == f);
    if matches!(args[0].as_str(), "render" | "view") {
        for (flag, v) in [("--particles", "32x32"), ("--resolution", "32x32")] {
            if !has(&args, flag) {
                args.extend([flag.to_owned(), v.to_owned()]);
            }
        }
        if !has(&args, "--frames") {
            args.extend(["--frames".to_owned(), frames.to_string()]);
        }
    }
    if args[0] == "render" && !has(&args, "--out") && !has(&args, "--video") {
        args.extend(["--out".to_owned(), out("out")]);
    }
    if args[0] == "view" && !has(&args, "--screenshot") {
        args.extend(["--screenshot".to_owned(), out("view.png")]);
    }
    args
}

#[test]
fn every_command_of_the_readmes_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let mut lines = Vec::new();
    for f in ["README.md", "examples/README.md"] {
        let text = std::fs::read_to_string(Path::new(ROOT).join(f)).unwrap();
        lines.extend(commands(&text).into_iter().map(|c| (f, c)));
    }
    assert!(
        lines.len() >= 5,
        "only {} commands found: {lines:?}",
        lines.len()
    );
    let mut failed = Vec::new();
    for (n, (file, line)) in lines.iter().enumerate() {
        let args = small(line, tmp.path(), n);
        eprintln!("{file}: texflow {}", args.join(" "));
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_texflow"));
        cmd.args(&args).current_dir(tmp.path());
        // `view` needs a display, which CI may not have: without one, a run that got past the
        // arguments and the scene ends with the clean no-display message and exit 2.
        let view = args[0] == "view";
        if view {
            cmd.env_remove("DISPLAY").env_remove("WAYLAND_DISPLAY");
        }
        let o = cmd.output().unwrap();
        let stderr = String::from_utf8_lossy(&o.stderr);
        let ok = if view {
            o.status.code() == Some(2)
                && stderr.contains("needs a display")
                && !stderr.contains(".rs:")
        } else {
            o.status.success()
        };
        if !ok {
            failed.push(format!(
                "{file}: `{line}` ran as `texflow {}`: {}\n{stderr}",
                args.join(" "),
                o.status
            ));
        }
    }
    assert!(failed.is_empty(), "\n{}", failed.join("\n"));
}

/// The `src/…` and `glsl/…` paths a text names: a token of path characters that starts with
/// `src/` or `glsl/` at a word boundary (not inside another path such as `fuzz/src/`), without
/// trailing punctuation. Patterns (`*`, `{`, `…`) are left out.
fn source_paths(text: &str) -> Vec<String> {
    let is_path = |c: char| c.is_ascii_alphanumeric() || matches!(c, '_' | '.' | '/' | '-');
    let mut out = Vec::new();
    for prefix in ["src/", "glsl/"] {
        for (i, _) in text.match_indices(prefix) {
            if text[..i]
                .chars()
                .next_back()
                .is_some_and(|c| is_path(c) || c == '\\')
            {
                continue;
            }
            let token: String = text[i..].chars().take_while(|&c| is_path(c)).collect();
            let after = text[i + token.len()..].chars().next();
            if matches!(after, Some('*' | '{' | '…' | '<')) {
                continue;
            }
            let token = token.trim_end_matches(['.', '-']);
            if token != prefix.trim_end_matches('/') && token.len() > prefix.len() {
                out.push(token.to_owned());
            }
        }
    }
    out
}

/// Every Rust and GLSL file under `src/`, `glsl/`, `tests/` and `examples/`.
fn code_files() -> Vec<PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                walk(&p, out);
            } else if p
                .extension()
                .is_some_and(|e| ["rs", "glsl", "frag", "vert"].contains(&&*e.to_string_lossy()))
            {
                out.push(p);
            }
        }
    }
    let mut out = Vec::new();
    for d in ["src", "glsl", "tests", "examples"] {
        walk(&Path::new(ROOT).join(d), &mut out);
    }
    out.sort();
    out
}

#[test]
fn every_source_path_named_in_docs_and_comments_exists() {
    let mut files = markdown_files();
    // This file's own scanner test names paths that must not exist.
    files.extend(
        code_files()
            .into_iter()
            .filter(|f| !f.ends_with("tests/docs.rs")),
    );
    let mut dead = Vec::new();
    for f in files {
        let text = std::fs::read_to_string(&f).unwrap();
        for (n, line) in text.lines().enumerate() {
            for p in source_paths(line) {
                if !Path::new(ROOT).join(&p).exists() {
                    dead.push(format!("{}:{}: {p}", rel(&f), n + 1));
                }
            }
        }
    }
    assert!(
        dead.is_empty(),
        "paths named that do not exist:\n{}",
        dead.join("\n")
    );
}

#[test]
fn the_source_path_scanner_finds_paths_and_skips_patterns() {
    assert_eq!(
        source_paths("see `src/sim/collide.rs`, glsl/sim/fire.frag. and fuzz/src/lib.rs"),
        ["src/sim/collide.rs", "glsl/sim/fire.frag"]
    );
    assert!(source_paths("glsl/sort/*.frag and src/{a,b}.rs and src/ alone").is_empty());
}
