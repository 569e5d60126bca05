//! Scene files: `tests/scenes/good.toml` parses, and every `tests/scenes/bad_*.toml` fails with
//! the error its first line announces: `# expect: LINE:COLUMN substring-of-the-message`.
//!
//! A mismatch prints the actual error with the source line and a caret under the column, so that
//! a wrong location shows at a glance.

mod common;

use common::scene::scene_error;

use std::path::{Path, PathBuf};

use texflow::scene::{self, Blending, DrawMode, Integrator, Precision, RenderPath};
use texflow::Error;

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/scenes")
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The expectation on a bad scene's first line.
struct Expect {
    line: usize,
    column: usize,
    substring: String,
}

fn expectation(path: &Path, src: &str) -> Expect {
    let first = src.lines().next().unwrap_or_default();
    let rest = first.strip_prefix("# expect: ").unwrap_or_else(|| {
        panic!(
            "{}: the first line must be `# expect: LINE:COLUMN substring`",
            path.display()
        )
    });
    let (at, substring) = rest.split_once(' ').unwrap_or((rest, ""));
    let (line, column) = at
        .split_once(':')
        .and_then(|(l, c)| Some((l.parse().ok()?, c.parse().ok()?)))
        .unwrap_or_else(|| panic!("{}: bad location `{at}`", path.display()));
    assert!(
        !substring.trim().is_empty(),
        "{}: the expectation needs a substring of the message",
        path.display()
    );
    Expect {
        line,
        column,
        substring: substring.trim().to_owned(),
    }
}

/// The source line with a caret under `column`.
fn caret(src: &str, line: usize, column: usize) -> String {
    let text = src
        .lines()
        .nth(line.wrapping_sub(1))
        .unwrap_or("<no such line>");
    format!(
        "{line:>4} | {text}\n     | {}^",
        " ".repeat(column.saturating_sub(1))
    )
}

fn bad_scenes() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(scenes())
        .expect("tests/scenes")
        .map(|e| e.expect("directory entry").path())
        .filter(|p| {
            p.extension().is_some_and(|x| x == "toml")
                && p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with("bad_"))
        })
        .collect();
    files.sort();
    files
}

#[test]
fn good_scene_parses() {
    let path = scenes().join("good.toml");
    let scene = scene::parse("good.toml", &read(&path)).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.name, "fountain");
    assert_eq!(scene.particles.size, [64, 64]);
    assert_eq!(scene.particles.precision, Precision::Fp24);
    assert_eq!(scene.integrator, Integrator::Verlet);
    assert_eq!(scene.time.substeps, 2);
    assert_eq!(scene.emitters.allocator.len(), 1);
    assert_eq!(scene.emitters.len(), 1);
    assert_eq!(scene.forces.gravity.len(), 1);
    assert_eq!(scene.forces.attractor.len(), 1);
    assert_eq!(scene.colliders.plane.len(), 1);
    assert_eq!(scene.colliders.sphere.len(), 1);
    assert_eq!(scene.render.mode, DrawMode::Sprites);
    assert_eq!(scene.render.path, RenderPath::VertexBuffer);
    assert_eq!(scene.render.blending, Blending::Alpha);
    assert_eq!(scene.render.keyframes.len(), 4);
    assert_eq!(
        scene.render.sort.variant,
        Some(texflow::sort::Variant::OddEven)
    );
}

#[test]
fn defaults_fill_a_minimal_scene() {
    let src = "name = \"m\"\n[particles]\nsize = [2, 2]\n[[emitters.initial]]\n\
               direction = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n";
    let scene = scene::parse("minimal.toml", src).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.time.dt, 1.0 / 60.0);
    assert_eq!(scene.time.substeps, 1);
    assert_eq!(scene.particles.mass, 1.0);
    assert_eq!(scene.integrator, Integrator::Euler);
    assert_eq!(scene.render.resolution, [512, 512]);
    assert_eq!(scene.render.blending, Blending::Additive);
}

#[test]
fn every_bad_scene_reports_its_line_column_and_message() {
    let files = bad_scenes();
    assert!(files.len() >= 15, "only {} bad scenes", files.len());
    let mut failures = Vec::new();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let src = read(path);
        let want = expectation(path, &src);
        match scene::parse(&name, &src) {
            Ok(_) => failures.push(format!("{name}: parsed, but should fail")),
            Err(Error::Scene {
                path: p,
                line,
                column,
                message,
            }) => {
                let ok = p == name
                    && line == want.line
                    && column == want.column
                    && message.contains(&want.substring);
                if !ok {
                    failures.push(format!(
                        "{name}: want {}:{} `{}`, got {p}:{line}:{column}: {message}\n{}",
                        want.line,
                        want.column,
                        want.substring,
                        caret(&src, line, column)
                    ));
                }
            }
            Err(other) => failures.push(format!("{name}: not a scene error: {other}")),
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n\n"));
}

#[test]
fn the_error_reads_path_line_column_message() {
    let err = scene::parse(
        "x.toml",
        "name = \"x\"\n[particles]\nsize = [8, 8]\nbogus = 1\n",
    )
    .unwrap_err();
    let text = err.to_string();
    assert!(text.starts_with("x.toml:4:1: "), "{text}");
    assert!(err.is_bad_input());
}

fn location(src: &str) -> (usize, usize, String) {
    scene_error(scene::parse("t.toml", src))
}

#[test]
fn columns_count_characters_and_crlf_ends_lines() {
    let line = "sort = { variant = \"日本\", passes_per_frame = nan }";
    let src = format!("name = \"p\"\n[particles]\nsize = [8, 8]\n[render]\n{line}\n");
    let column = line[..line.rfind("nan").unwrap()].chars().count() + 1;
    let (l, c, m) = location(&src);
    assert_eq!((l, c), (5, column), "{m}");
    assert!(
        column < line.rfind("nan").unwrap() + 1,
        "the line has multi-byte characters"
    );
    let (l, c, m) = location("name = \"p\"\r\n[particles]\r\nsize = [8, 0]\r\n");
    assert_eq!((l, c), (3, 12), "{m}");
}

#[test]
fn a_missing_section_points_at_the_start() {
    let (l, c, m) = location("name = \"p\"\n");
    assert_eq!((l, c), (1, 1));
    assert!(m.contains("missing field `particles`"), "{m}");
    let (l, c, m) = location("");
    assert_eq!((l, c), (1, 1));
    assert!(m.contains("missing field `name`"), "{m}");
}

#[test]
fn the_example_in_the_docs_parses() {
    let doc = read(&Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes.md"));
    let start = doc
        .find("```toml\n")
        .expect("a ```toml block in docs/scenes.md")
        + 8;
    let len = doc[start..].find("```").expect("the end of the block");
    scene::parse("docs/scenes.md", &doc[start..start + len]).unwrap_or_else(|e| panic!("{e}"));
}

/// A scene file that is not UTF-8 is refused at the line and column of its first bad byte, with
/// a message that says so (the file is read as bytes, not as a string).
#[test]
fn a_file_that_is_not_utf8_is_located() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("latin1.toml");
    std::fs::write(&path, b"name = \"fire\"\n# caf\xe9\n").unwrap();
    match scene::load(path.to_str().unwrap()) {
        Err(Error::Scene {
            line,
            column,
            message,
            ..
        }) => {
            assert_eq!((line, column), (2, 6), "{message}");
            assert!(message.contains("must be UTF-8"), "{message}");
        }
        other => panic!("want a scene error, got {other:?}"),
    }
}

/// The value ranges the mutation test (`tests/scene_mutations.rs`) found missing, one class per
/// key: each refused at its own line and column with the range in the message (issue 13, item 3).
#[test]
fn values_that_overflow_the_state_are_refused_at_their_key() {
    let base = "name = \"x\"\nparticles = { size = [8, 8] }\n";
    let initial = "[[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 1.0]\n";
    let fire = "[fire]\nemitter_center = [0.0, 0.0, 0.0]\nemitter_radius = 0.3\nspeed = 0.8\n\
                spread = 0.15\nconverge = 1.1\nbuoyancy = [0.0, 2.5, 0.0]\nturbulence = 4.0\n\
                damping = 0.7\nlife = [0.6, 1.4]\nmax_age = 1.6\n";
    // Every fire magnitude is bounded like the emitters' (the first mutant found was damping).
    for (key, bad, message) in [
        ("damping = 0.7", "damping = -1e30", "must not be negative"),
        (
            "damping = 0.7",
            "damping = 1e6",
            "|damping × dt| must be at most 4",
        ),
        ("speed = 0.8", "speed = 1e30", "is outside [-1e6, 1e6]"),
        ("spread = 0.15", "spread = 1e30", "is outside [-1e6, 1e6]"),
        (
            "converge = 1.1",
            "converge = -1e30",
            "is outside [-1e6, 1e6]",
        ),
        (
            "turbulence = 4.0",
            "turbulence = 1e38",
            "is outside [-1e6, 1e6]",
        ),
        (
            "emitter_radius = 0.3",
            "emitter_radius = 1e30",
            "is outside [-1e6, 1e6]",
        ),
        (
            "[0.0, 0.0, 0.0]",
            "[1e30, 0.0, 0.0]",
            "is outside [-1e6, 1e6]",
        ),
    ] {
        let src = format!("{base}{}", fire.replace(key, bad));
        let (l, c, m) = location(&src);
        let want = src.lines().position(|x| x.contains(bad)).unwrap() + 1;
        assert_eq!(l, want, "{bad}: {m}");
        assert!(c > 1 && m.contains(message), "{bad}: {l}:{c}: {m}");
    }
    // Time steps, masses and a mass-divided drag.
    let (l, c, m) = location(&format!("{base}{initial}[time]\ndt = 1.5\n"));
    assert_eq!((l, c), (7, 6), "{m}");
    assert!(m.contains("is above 1 s"), "{m}");
    for mass in ["1e-30", "2e6"] {
        let src = format!("{base}{initial}mass_range = [{mass}, {mass}]\n");
        let (l, _, m) = location(&src);
        assert_eq!(l, 6, "{m}");
        assert!(m.contains("is outside [1e-6, 1e6]"), "{m}");
    }
    // Height fields and distance fields are coordinates too.
    for (line, message) in [
        (
            "[[colliders.heightfield]]\nextent = [-1.0, -1.0, 1e30, 1.0]\nresolution = 4\n\
             amplitude = 0.1\nfrequency = 1.0\n",
            "extent component",
        ),
        (
            "[[colliders.heightfield]]\nextent = [-1.0, -1.0, 1.0, 1.0]\nresolution = 4\n\
             amplitude = 0.1\nfrequency = 1e30\n",
            "frequency component",
        ),
        (
            "[[colliders.sdf]]\nbounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\nresolution = 4\n\
             spheres = [[0.0, 0.0, 0.0, 1e30]]\n",
            "sphere component",
        ),
    ] {
        let src = format!("{base}{initial}{line}");
        let (_, c, m) = location(&src);
        assert!(c > 1 && m.contains(message), "{line}: {m}");
    }
}
