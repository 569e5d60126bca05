//! Mutated built-in scenes (issue 13, items 3 and 9): every input is either refused with a line
//! and a column, or it validates and then runs 10 frames of a tiny state with no NaN or infinite
//! value.
//!
//! The mutants are deterministic: in the TOML source of every built-in scene (and of two seeds
//! in `tests/scenes/` with the forces, colliders and emitters they lack), each numeric
//! literal replaced in turn by each of [`EXTREMES`], each `key = value` statement deleted, and
//! each array emptied. Every mutant is parsed (CPU, all of them). A fixed, seeded sample of the
//! accepted ones (at most [`GPU_RUNS`]) is shrunk to a 16×16 state drawn at 16×16 pixels and run
//! for 10 frames through `engine::FrameLoop`; the GPU census (`LoopSummary::max_non_finite`) and
//! a CPU read of the state must both find no NaN or infinity. The ignored test runs every
//! accepted mutant: `cargo test --release --test scene_mutations -- --ignored --nocapture`.

mod common;

use common::scene::Rng;

use std::ops::{ControlFlow, Range};
use std::time::Instant;

use texflow::engine::{FrameLoop, LoopOptions, MemorySink, NonFinitePolicy};
use texflow::{engine, scene, EngineKind, Error};

/// What each numeric literal is replaced by, in turn: zero, a negative, the tiny and the huge of
/// both signs, the edge of f32, and an integer no TOML integer holds.
const EXTREMES: &[&str] = &[
    "0",
    "-1",
    "1e-30",
    "1e30",
    "-1e30",
    "1e6",
    "-1e6",
    "1e38",
    "123456789012345678901234567890",
];

/// Most accepted mutants the plain test runs on the GPU (about 0.3 s each on llvmpipe).
const GPU_RUNS: usize = 150;

/// Frames each accepted mutant runs.
const FRAMES: u64 = 10;

/// One mutated scene.
struct Mutant {
    /// The built-in scene it came from.
    scene: &'static str,
    /// What was changed, for messages.
    what: String,
    /// The mutated TOML source.
    src: String,
}

/// The byte ranges of a TOML source's pieces, found by one pass that skips comments, strings
/// and table headers.
#[derive(Default)]
struct Pieces {
    /// Numeric literals.
    numbers: Vec<Range<usize>>,
    /// Arrays that are values (`[...]`, nested ones too).
    arrays: Vec<Range<usize>>,
    /// Whole `key = value` statements, from the start of their line to the end of the line where
    /// the value ends (multi-line arrays included).
    statements: Vec<Range<usize>>,
}

fn pieces(src: &str) -> Pieces {
    let b = src.as_bytes();
    let mut p = Pieces::default();
    let mut open: Vec<usize> = Vec::new();
    let mut statement: Option<usize> = None;
    let mut line_start = 0;
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let first_on_line = src[line_start..i].trim().is_empty();
        match c {
            b'\n' => {
                if open.is_empty() {
                    if let Some(s) = statement.take() {
                        p.statements.push(s..i + 1);
                    }
                }
                line_start = i + 1;
            }
            b'#' => {
                while i + 1 < b.len() && b[i + 1] != b'\n' {
                    i += 1;
                }
            }
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
            }
            b'[' if open.is_empty() && first_on_line => {
                // A table header: `[name]` or `[[name]]`.
                while i + 1 < b.len() && b[i + 1] != b'\n' {
                    i += 1;
                }
            }
            b'[' => open.push(i),
            b']' => {
                if let Some(s) = open.pop() {
                    p.arrays.push(s..i + 1);
                }
            }
            b'=' if open.is_empty() && statement.is_none() => statement = Some(line_start),
            b'0'..=b'9' | b'+' | b'-'
                if i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b"_.".contains(&b[i - 1])) =>
            {
                let start = i;
                while i + 1 < b.len() {
                    let n = b[i + 1];
                    let exponent_sign = b"+-".contains(&n) && b"eE".contains(&b[i]);
                    if n.is_ascii_alphanumeric() || b"_.".contains(&n) || exponent_sign {
                        i += 1;
                    } else {
                        break;
                    }
                }
                if b[start..=i].iter().any(u8::is_ascii_digit) {
                    p.numbers.push(start..i + 1);
                }
            }
            _ => {}
        }
        i += 1;
    }
    if let Some(s) = statement {
        p.statements.push(s..b.len());
    }
    p
}

/// The line of byte `at`, for messages.
fn line_of(src: &str, at: usize) -> usize {
    src[..at].matches('\n').count() + 1
}

/// Seeds beyond the built-in scenes: the forces, colliders and emitters they do not have.
const EXTRA_SEEDS: &[(&str, &str)] = &[
    ("tests/scenes/good.toml", include_str!("scenes/good.toml")),
    (
        "tests/scenes/mutation_seed.toml",
        include_str!("scenes/mutation_seed.toml"),
    ),
];

/// The label a seed's errors use: a built-in's (which finds its meshes), or the file's path.
fn label(seed: &str) -> String {
    if seed.ends_with(".toml") {
        seed.to_owned()
    } else {
        format!("{seed} (built-in)")
    }
}

/// Every mutant of every built-in scene and extra seed, in a fixed order.
fn mutants() -> Vec<Mutant> {
    let mut out = Vec::new();
    let builtin = scene::BUILTIN
        .iter()
        .map(|&name| (name, scene::builtin_source(name).unwrap()));
    for (name, src) in builtin.chain(EXTRA_SEEDS.iter().copied()) {
        let p = pieces(src);
        assert!(
            p.numbers.len() > 5 && !p.statements.is_empty(),
            "{name}: the scanner found {} numbers and {} statements",
            p.numbers.len(),
            p.statements.len()
        );
        let splice =
            |r: &Range<usize>, with: &str| format!("{}{with}{}", &src[..r.start], &src[r.end..]);
        for r in &p.numbers {
            for v in EXTREMES {
                out.push(Mutant {
                    scene: name,
                    what: format!("line {}: {} -> {v}", line_of(src, r.start), &src[r.clone()]),
                    src: splice(r, v),
                });
            }
        }
        for r in &p.statements {
            out.push(Mutant {
                scene: name,
                what: format!(
                    "line {}: deleted `{}`",
                    line_of(src, r.start),
                    src[r.clone()].trim()
                ),
                src: splice(r, ""),
            });
        }
        for r in &p.arrays {
            out.push(Mutant {
                scene: name,
                what: format!(
                    "line {}: emptied {}",
                    line_of(src, r.start),
                    &src[r.clone()]
                ),
                src: splice(r, "[]"),
            });
        }
    }
    out
}

/// A parsed mutant, ready to run.
struct Accepted {
    mutant: Mutant,
    file: scene::SceneFile,
}

/// Parses every mutant; each must be refused with a line and a column, or validate. Returns the
/// accepted ones and the number refused.
fn parse_all(mutants: Vec<Mutant>) -> (Vec<Accepted>, usize) {
    let mut accepted = Vec::new();
    let mut refused = 0;
    for m in mutants {
        match scene::parse(&label(m.scene), &m.src) {
            Ok(file) => {
                if let Err(e) = file.validate() {
                    panic!(
                        "{} {}: parsed, but validate refuses it: {e:?}",
                        m.scene, m.what
                    );
                }
                accepted.push(Accepted { mutant: m, file });
            }
            Err(Error::Scene { line, column, .. }) if line >= 1 && column >= 1 => refused += 1,
            Err(e) => panic!(
                "{} {}: refused without a line and column: {e}",
                m.scene, m.what
            ),
        }
    }
    (accepted, refused)
}

/// What the GPU part did.
#[derive(Debug, Default)]
struct Runs {
    /// Mutants run for [`FRAMES`] frames.
    ran: usize,
    /// Mutants refused once shrunk to the tiny state (births per step over its particle count,
    /// say) by validation or by the engine, with a bad-input error.
    skipped: usize,
    /// Mutants whose state turned NaN or infinite: what was changed, and the counts.
    holes: Vec<String>,
}

/// Shrinks each scene to a 16×16 state drawn at 16×16 pixels and runs it for [`FRAMES`] frames in
/// one context, recording every run whose state is not finite.
fn run_all(accepted: &[&Accepted]) -> Runs {
    let ctx = common::context();
    let mut runs = Runs::default();
    for a in accepted {
        let mut s = a.file.clone();
        s.particles.size = [16, 16];
        s.render.resolution = [16, 16];
        let label = format!("{} {}", a.mutant.scene, a.mutant.what);
        if s.validate().is_err() {
            runs.skipped += 1;
            continue;
        }
        let mut engine = match engine::build(&ctx, &s, 7, EngineKind::Gpu) {
            Ok(e) => e,
            Err(e) if e.is_bad_input() => {
                runs.skipped += 1;
                continue;
            }
            Err(e) => panic!("{label}: the engine failed: {e}"),
        };
        let options = LoopOptions {
            frames: FRAMES,
            every: 1,
            start: 0,
            dump_every: Some(FRAMES - 1),
            non_finite: NonFinitePolicy::Report,
            timing: false,
        };
        let frame_loop = FrameLoop::new(&ctx, engine.as_ref(), options).unwrap();
        let mut sink = MemorySink::default();
        let summary = frame_loop
            .run(engine.as_mut(), &mut sink, |_| ControlFlow::Continue(()))
            .unwrap_or_else(|e| panic!("{label}: the run failed: {e}"));
        assert_eq!(summary.frames, FRAMES, "{label}");
        assert_eq!(summary.written, FRAMES, "{label}");
        // The dumps are a CPU read of the same state: an independent count.
        let cpu: usize = sink.dumps.iter().map(|(_, d)| d.non_finite).sum();
        if summary.max_non_finite > 0 || cpu > 0 {
            runs.holes.push(format!(
                "{label}: {} non-finite particles (GPU census, most in a frame), {cpu} in the \
                 dumps",
                summary.max_non_finite
            ));
        }
        runs.ran += 1;
    }
    common::no_gl_error(&ctx);
    runs
}

/// Generates, parses, samples at most `limit` accepted mutants (seeded), runs them, and fails
/// listing every hole.
fn check(limit: usize) {
    let start = Instant::now();
    let all = mutants();
    let generated = all.len();
    let (accepted, refused) = parse_all(all);
    let parsed_in = start.elapsed();
    let mut sample: Vec<&Accepted> = accepted.iter().collect();
    if sample.len() > limit {
        // A partial Fisher-Yates shuffle with a fixed seed: the same sample every run.
        let mut rng = Rng(13);
        for i in 0..limit {
            let j = i + (rng.next_u64() % (sample.len() - i) as u64) as usize;
            sample.swap(i, j);
        }
        sample.truncate(limit);
    }
    let runs = run_all(&sample);
    eprintln!(
        "scene mutations: {generated} generated, {refused} refused with a location, {} \
         accepted (parsed in {parsed_in:.1?}); {} sampled: {} ran {FRAMES} frames, {} refused at \
         16x16; {} with non-finite state; {:.1?} in all",
        accepted.len(),
        sample.len(),
        runs.ran,
        runs.skipped,
        runs.holes.len(),
        start.elapsed()
    );
    assert!(generated > 1000, "only {generated} mutants");
    assert!(runs.ran > sample.len() / 2, "{runs:?}");
    assert!(
        runs.holes.is_empty(),
        "validated, yet not finite after {FRAMES} frames:\n{}",
        runs.holes.join("\n")
    );
}

#[test]
fn mutated_builtin_scenes_are_refused_with_a_location_or_stay_finite() {
    check(GPU_RUNS);
}

#[test]
#[ignore = "runs every accepted mutant on the GPU (minutes on llvmpipe)"]
fn every_accepted_mutant_stays_finite() {
    check(usize::MAX);
}

#[test]
fn the_scanner_finds_numbers_statements_and_arrays() {
    let src = "# 1 2\nname = \"e1 2\"\n[[forces.gravity]]\nacceleration = [0.0, -9.81, 1e-3]\n\
               k = [\n  { a = 1 },\n]\n";
    let p = pieces(src);
    let text = |rs: &[Range<usize>]| rs.iter().map(|r| &src[r.clone()]).collect::<Vec<_>>();
    assert_eq!(text(&p.numbers), ["0.0", "-9.81", "1e-3", "1"]);
    assert_eq!(
        text(&p.arrays),
        ["[0.0, -9.81, 1e-3]", "[\n  { a = 1 },\n]"]
    );
    assert_eq!(
        text(&p.statements),
        [
            "name = \"e1 2\"\n",
            "acceleration = [0.0, -9.81, 1e-3]\n",
            "k = [\n  { a = 1 },\n]\n"
        ]
    );
}
