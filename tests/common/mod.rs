//! Helpers shared by the tests, each written once: `cli` runs the built binary (`bad_input` with
//! a hang guard), `scene` writes
//! scenes, random states and their CPU references, `image` probes and counts pixels; the GPU
//! tests' context and state are here. Every GPU test makes its own context on its own thread (GL
//! contexts are bound to a thread) and ends with `no_gl_error`.
//!
//! Mesa 22.3's llvmpipe crashed (SIGSEGV inside `swrast_dri.so`, about one run in eight of
//! `tests/particles.rs`) when several test threads drew in their own contexts at once, so a test
//! holds a process-wide lock for as long as its context lives: the GPU tests of one binary run
//! one after another (llvmpipe still rasterizes on every core), the CPU-only tests in parallel.

#![allow(dead_code)]

pub mod bad_input;
pub mod cli;
pub mod fluid;
pub mod image;
pub mod scene;

use std::ops::Deref;
use std::sync::{Mutex, MutexGuard};

use texflow::gl::Context;

static GPU: Mutex<()> = Mutex::new(());

/// A context that holds the test lock until it is dropped (the context first).
pub struct TestContext {
    ctx: Context,
    _lock: MutexGuard<'static, ()>,
}

impl Deref for TestContext {
    type Target = Context;
    fn deref(&self) -> &Context {
        &self.ctx
    }
}

/// A context on the first EGL device (llvmpipe in CI), once no other test of this process holds
/// one.
pub fn context() -> TestContext {
    // A test that panicked while holding the lock poisons it; the next one may still run.
    let lock = GPU.lock().unwrap_or_else(|e| e.into_inner());
    TestContext {
        ctx: Context::new(0).expect("an EGL device (install libegl1 libegl-mesa0 libgl1-mesa-dri)"),
        _lock: lock,
    }
}

/// Asserts that no GL error is pending.
pub fn no_gl_error(ctx: &Context) {
    ctx.check_error("the test").expect("no pending GL error");
}

/// Uploads particles (position, velocity) as type 0, permanent, the rest of the texture dead;
/// `random(i, n)` is particle i's static random number (statics.w) of n texels.
pub fn set_particles(
    sim: &mut texflow::sim::ParticleSim,
    particles: &[([f32; 3], [f32; 3])],
    random: impl Fn(usize, usize) -> f32,
) {
    let n = (sim.size().x * sim.size().y) as usize;
    assert!(particles.len() <= n);
    let mut pos = vec![f32::INFINITY; n * 4];
    let mut vel = vec![0.0; n * 4];
    let mut st = vec![0.0; n * 4];
    for i in 0..n {
        pos[i * 4 + 3] = 0.0;
    }
    for (i, (x, v)) in particles.iter().enumerate() {
        pos[i * 4..i * 4 + 4].copy_from_slice(&[x[0], x[1], x[2], 1.0]);
        vel[i * 4..i * 4 + 3].copy_from_slice(v);
        st[i * 4 + 3] = random(i, n);
    }
    sim.set_state(&pos, &vel, &st).unwrap();
}

/// A shader only the tests draw (`tests/glsl/NAME`, kept out of the library), registered as a
/// run-time source under the path it returns: `Program::new` finds it there, its `#include`s
/// resolve to the library's files, and compile errors name that path.
pub fn test_shader(name: &str) -> String {
    let text = match name {
        "broken.frag" => include_str!("../glsl/broken.frag"),
        "broken_include.frag" => include_str!("../glsl/broken_include.frag"),
        "broken_helper.glsl" => include_str!("../glsl/broken_helper.glsl"),
        "fields.frag" => include_str!("../glsl/fields.frag"),
        "increment.frag" => include_str!("../glsl/increment.frag"),
        "write8.frag" => include_str!("../glsl/write8.frag"),
        _ => panic!("no test shader tests/glsl/{name}"),
    };
    let path = format!("tests/glsl/{name}");
    texflow::gl::source::add_runtime_source(&path, text);
    path
}

/// The passes of the engine built for `scene` (what `texflow scene passes` prints), at 16×16
/// particles so that building it is quick; the list does not depend on the size but for the
/// sort's entry and pass counts.
pub fn plan_of(ctx: &Context, scene: &texflow::scene::SceneFile) -> texflow::engine::plan::Plan {
    let mut s = scene.clone();
    s.particles.size = [16, 16];
    texflow::engine::build(ctx, &s, 1, texflow::EngineKind::Gpu)
        .unwrap_or_else(|e| panic!("{}: {e}", s.name))
        .plan()
}

/// One step of a 64-bit linear congruential generator (Knuth's MMIX constants), its high 31 bits
/// out: the sort tests' keys.
pub fn lcg(s: &mut u64) -> u32 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*s >> 33) as u32
}

/// `n` sort entries whose keys are whole numbers in `0..range` plus `offset`, their ids their
/// indices (ties among equal keys fall to the ids).
pub fn keyed_entries(n: u32, seed: u64, range: u32, offset: f32) -> Vec<texflow::sort::Entry> {
    let mut s = seed;
    (0..n)
        .map(|i| [(lcg(&mut s) % range) as f32 + offset, i as f32])
        .collect()
}
