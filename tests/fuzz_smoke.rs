//! The fuzz targets' checks (`fuzz/src/lib.rs`, included here: `.npy`, scenes, OBJ meshes,
//! custom-force and pair-force GLSL, field files, `--set` values) on stable Rust, for machines
//! without nightly and cargo-fuzz: the seed corpus `fuzz/corpus/`, then random mutations of it
//! (byte edits and splices of tokens that have broken readers before).
//!
//! The plain tests run the corpus and a fixed number of mutations; the ignored ones run for
//! `FUZZ_SMOKE_SECS` seconds (default 60):
//! `FUZZ_SMOKE_SECS=300 cargo test --release --test fuzz_smoke -- --ignored --nocapture`.

#[path = "../fuzz/src/lib.rs"]
mod checks;
mod common;

use common::scene::Rng;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::time::{Duration, Instant};

/// Tokens spliced into .npy files.
const NPY_TOKENS: &[&[u8]] = &[
    b"(4611686018427387904,)",
    b"(18446744073709551616,)",
    b"(4294967296, 4294967296, 2)",
    b"(-1,)",
    b"(0,)",
    b"'>f4'",
    b"[('a', '<f4')]",
    b"True",
    b"'shape': (2,), ",
    b"\x02\x00",
    b"\x03\x00",
    b"\xff\xff",
    b"[[[[[[[[",
];

/// Tokens spliced into scene files.
const SCENE_TOKENS: &[&[u8]] = &[
    b"1e30",
    b"-1e30",
    b"nan",
    b"inf",
    b"-inf",
    b"0",
    b"-1",
    b"1e-6",
    b"4294967296",
    b"[",
    b"]",
    b"\n[collisions]\n",
    b"\n[[emitters]]\n",
    b"\"\"",
    b" = ",
    b"true",
    b"{}",
    b"\xc3\xa9",
];

/// Tokens spliced into OBJ meshes.
const OBJ_TOKENS: &[&[u8]] = &[
    b"\nv 1e39 0 0\n",
    b"\nv nan 0 0\n",
    b"\nf 1 2 3\n",
    b"\nf -1 -2 -3\n",
    b"\nf 0 0 0\n",
    b"\nf 4294967296 1 2\n",
    b"/",
    b"//",
    b" -",
    b"\\\n",
    b"\nmtllib x.mtl\n",
    b"\no \n",
    b"\xff",
];

/// Tokens spliced into custom-force GLSL.
const GLSL_TOKENS: &[&[u8]] = &[
    b"\n#include \"common/rng.glsl\"\n",
    b"\n#line 9999\n",
    b"\n#version 450\n",
    b"\n  #  extension GL_ARB_compute_shader : enable\n",
    b"/*",
    b"*/",
    b"//",
    b"\\\n",
    b"\n#",
    b"\0",
    b"\r",
    b"\xef\xbb\xbf",
    b"for(;;)",
    b"while (true)",
    b"force",
    b"\xff",
];

/// Tokens spliced into field files (PNG height maps, `.npy` fields).
const FIELD_TOKENS: &[&[u8]] = &[
    b"IHDR",
    b"\x00\x00\xff\xff\x00\x00\xff\xff",
    b"\x10\x00",
    b"\x01\x00",
    b"IDAT",
    b"(2, 2, 2, 3)",
    b"(100000, 100000)",
    b"(1, 2)",
    b"\x00\x00\xc0\x7f",
    b"\x00\x00\x80\x7f",
    b"'<f8'",
    b"\xff",
];

/// Tokens spliced into `--set` lines.
const SET_TOKENS: &[&[u8]] = &[
    b"=",
    b".",
    b"\n",
    b"1e30",
    b"nan",
    b"-1",
    b"[",
    b"]",
    b"\"",
    b"{ a = 1 }",
    b"colliders.heightfield.0.image",
    b"forces.wind.0.field",
    b"emitters.child.0",
    b"4294967296",
    b"true",
    b"\xc3\xa9",
];

fn corpus(name: &str) -> Vec<Vec<u8>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(name);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let seeds: Vec<Vec<u8>> = files.iter().map(|p| std::fs::read(p).unwrap()).collect();
    assert!(
        seeds.len() >= 5,
        "{}: only {} seeds",
        dir.display(),
        seeds.len()
    );
    seeds
}

/// One to four edits of `b`: a byte set, flipped, inserted or removed, a cut, a token spliced
/// in or written over, or a chunk repeated.
fn mutate(rng: &mut Rng, mut b: Vec<u8>, tokens: &[&[u8]]) -> Vec<u8> {
    for _ in 0..1 + rng.below(4) {
        let at = rng.below(b.len() + 1);
        match rng.below(8) {
            0 if at < b.len() => b[at] = rng.next_u64() as u8,
            1 if at < b.len() => b[at] ^= 1 << rng.below(8),
            2 => b.insert(at, rng.next_u64() as u8),
            3 if at < b.len() => {
                b.remove(at);
            }
            4 => b.truncate(at),
            5 => {
                let t = tokens[rng.below(tokens.len())];
                b.splice(at..at, t.iter().copied());
            }
            6 => {
                let t = tokens[rng.below(tokens.len())];
                let end = (at + t.len()).min(b.len());
                b.splice(at..end, t.iter().copied());
            }
            _ => {
                let end = (at + 1 + rng.below(32)).min(b.len());
                let chunk = b[at..end].to_vec();
                b.splice(at..at, chunk);
            }
        }
    }
    b
}

/// Runs `check` on the seeds, then on mutations until `count` inputs or `time` have passed;
/// on a panic, prints the input and fails. Returns how many inputs ran.
fn run(
    name: &str,
    check: fn(&[u8]),
    tokens: &[&[u8]],
    count: usize,
    time: Duration,
    seed: u64,
) -> usize {
    let seeds = corpus(name);
    let start = Instant::now();
    let mut rng = Rng(seed);
    let mut ran = 0;
    for i in 0.. {
        let input = if i < seeds.len() {
            seeds[i].clone()
        } else if ran >= count || start.elapsed() >= time {
            break;
        } else {
            let s = seeds[rng.below(seeds.len())].clone();
            mutate(&mut rng, s, tokens)
        };
        if catch_unwind(AssertUnwindSafe(|| check(&input))).is_err() {
            panic!(
                "{name}: input {i} (seed {seed}) breaks the check: {:?}",
                String::from_utf8_lossy(&input)
            );
        }
        ran += 1;
    }
    ran
}

#[test]
fn npy_corpus_and_mutations_pass_the_checks() {
    run("npy", checks::npy, NPY_TOKENS, 20_000, Duration::MAX, 1);
}

#[test]
fn scene_corpus_and_mutations_pass_the_checks() {
    run(
        "scene",
        checks::scene,
        SCENE_TOKENS,
        2_000,
        Duration::MAX,
        1,
    );
}

#[test]
fn obj_corpus_and_mutations_pass_the_checks() {
    run("obj", checks::obj, OBJ_TOKENS, 2_000, Duration::MAX, 1);
}

#[test]
fn glsl_corpus_and_mutations_pass_the_checks() {
    run("glsl", checks::glsl, GLSL_TOKENS, 20_000, Duration::MAX, 1);
}

#[test]
fn field_corpus_and_mutations_pass_the_checks() {
    run(
        "field",
        checks::field,
        FIELD_TOKENS,
        5_000,
        Duration::MAX,
        1,
    );
}

#[test]
fn pair_corpus_and_mutations_pass_the_checks() {
    run("pair", checks::pair, GLSL_TOKENS, 20_000, Duration::MAX, 1);
}

#[test]
fn set_corpus_and_mutations_pass_the_checks() {
    run("set", checks::set, SET_TOKENS, 2_000, Duration::MAX, 1);
}

fn budget() -> Duration {
    let secs = std::env::var("FUZZ_SMOKE_SECS").map_or(60, |s| s.parse().unwrap());
    Duration::from_secs(secs)
}

fn seed() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_nanos() as u64
}

#[test]
#[ignore = "runs for FUZZ_SMOKE_SECS seconds"]
fn npy_fuzz_smoke() {
    let (t, s) = (budget(), seed());
    let n = run("npy", checks::npy, NPY_TOKENS, usize::MAX, t, s);
    eprintln!("npy: {n} inputs in {t:?} (seed {s}), no failure");
}

#[test]
#[ignore = "runs for FUZZ_SMOKE_SECS seconds"]
fn scene_fuzz_smoke() {
    let (t, s) = (budget(), seed());
    let n = run("scene", checks::scene, SCENE_TOKENS, usize::MAX, t, s);
    eprintln!("scene: {n} inputs in {t:?} (seed {s}), no failure");
}

#[test]
#[ignore = "runs for FUZZ_SMOKE_SECS seconds"]
fn obj_fuzz_smoke() {
    let (t, s) = (budget(), seed());
    let n = run("obj", checks::obj, OBJ_TOKENS, usize::MAX, t, s);
    eprintln!("obj: {n} inputs in {t:?} (seed {s}), no failure");
}

#[test]
#[ignore = "runs for FUZZ_SMOKE_SECS seconds"]
fn glsl_fuzz_smoke() {
    let (t, s) = (budget(), seed());
    let n = run("glsl", checks::glsl, GLSL_TOKENS, usize::MAX, t, s);
    eprintln!("glsl: {n} inputs in {t:?} (seed {s}), no failure");
}

#[test]
#[ignore = "runs for FUZZ_SMOKE_SECS seconds"]
fn field_fuzz_smoke() {
    let (t, s) = (budget(), seed());
    let n = run("field", checks::field, FIELD_TOKENS, usize::MAX, t, s);
    eprintln!("field: {n} inputs in {t:?} (seed {s}), no failure");
}

#[test]
#[ignore = "runs for FUZZ_SMOKE_SECS seconds"]
fn pair_fuzz_smoke() {
    let (t, s) = (budget(), seed());
    let n = run("pair", checks::pair, GLSL_TOKENS, usize::MAX, t, s);
    eprintln!("pair: {n} inputs in {t:?} (seed {s}), no failure");
}

#[test]
#[ignore = "runs for FUZZ_SMOKE_SECS seconds"]
fn set_fuzz_smoke() {
    let (t, s) = (budget(), seed());
    let n = run("set", checks::set, SET_TOKENS, usize::MAX, t, s);
    eprintln!("set: {n} inputs in {t:?} (seed {s}), no failure");
}
