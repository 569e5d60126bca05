//! UberFlow's Table 2 (§5): frames per second of whole frames of the paper's experiments at
//! 256², 512² and 1024² particles, next to the paper's numbers (ATI 9800 Pro and a Pentium 4 at
//! 2.0 GHz, 2004), with the GPU engine's speed over the CPU engine's as the paper compares them.
//!
//! | experiment | what | engine | a frame |
//! | --- | --- | --- | --- |
//! | E1 | collisionless motion (`examples/scenes/e1.toml`) | GPU | integration pass, points (vertex texture fetch, additive) |
//! | E2 | height-field collisions (`e2.toml`) | GPU | integration pass with the height field, points |
//! | E3 | collisionless motion, front-to-back sorting and rendering (`e3.toml`) | GPU | integration pass, key pass, our blocked bitonic sort (fragment passes), gather, points under the under operator |
//! | E3p | E3 with the paper's sort | GPU | the same with the GP/FP-packed bitonic sort (`e3.toml` as written) |
//! | E4 | inter-particle collisions, rows-only sort, 8 neighbours each side | GPU | integration, two rows-only cell sorts on our blocked network (lattice and staggered lattice), detection, response ([`e4`]: one release per row, density held) |
//! | E4p | E4 with the paper's sort | GPU | the same with the GP/FP-packed bitonic sort (`collisions.sort = "packed"`) |
//! | E5 | E3 on the CPU: the same scene, physics and spawns | CPU ([`crate::engine::cpu`]) | steps on all cores, quicksort by viewer distance, upload of the vertices, point draw |
//!
//! Every experiment runs at each size with the scene's `particles.size` set to size × size. The
//! state is first advanced by `warmup_frames` frames of simulation only (default: one full
//! emission cycle, after which every time-stamped particle has been born: the steady state the
//! paper's animations run in), then two whole frames are run untimed (lazily built programs, first
//! use of buffers), then `repeats` whole frames are timed one by one and the median is reported;
//! fps = 1000 / median ms.
//!
//! Clocks: GPU experiments with [`PassTimer`] (timer queries on a hardware GPU, `glFinish` wall
//! time on llvmpipe, where the GPU is the CPU); the wall time around each of their frames (from a
//! `glFinish` to the end of the frame's commands) is recorded too. E5 with the wall clock only: its
//! frame is CPU work, the upload and the draw, ended by `glFinish`.

use std::time::Instant;

pub mod e4;
mod source;
mod table;

pub use source::{cpu_scene, gpu_scene, sized};
use table::add_ratios;
pub use table::markdown;

use crate::bench::{median, Clock, PassTimer};
use crate::engine::{timed, Engine};
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::scene::SceneFile;

/// The state sizes of the paper's Table 2.
pub const PAPER_SIZES: [u32; 3] = [256, 512, 1024];

/// A function that makes an experiment's scene at a state side (E1-E3 and E5 ignore it).
pub type SceneFn = fn(u32) -> Result<SceneFile>;

/// Makes an experiment's frame source at a size.
pub type BuildFn = fn(&Context, u32, &ScenesOptions) -> Result<Box<dyn Engine>>;

/// One column of Table 2.
#[derive(Clone, Copy)]
pub struct Experiment {
    /// `E1` ... `E5`.
    pub name: &'static str,
    /// What it simulates and draws.
    pub what: &'static str,
    /// Whether it runs on the CPU (E5): timed with the wall clock.
    pub cpu: bool,
    /// The paper's fps at 256², 512², 1024².
    pub paper_fps: [f64; 3],
    /// The scene whose emission cycle sets the default warm-up.
    pub scene: Option<SceneFn>,
    /// How to build it; `None`: listed, not run.
    pub build: Option<BuildFn>,
}

impl std::fmt::Debug for Experiment {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Experiment({}: {})", self.name, self.what)
    }
}

impl Experiment {
    /// The paper's fps at `size`, if Table 2 has the size.
    pub fn paper(&self, size: u32) -> Option<f64> {
        PAPER_SIZES
            .iter()
            .position(|&s| s == size)
            .map(|i| self.paper_fps[i])
    }
}

fn e1(_: u32) -> Result<SceneFile> {
    crate::scene::load("e1")
}
fn e2(_: u32) -> Result<SceneFile> {
    crate::scene::load("e2")
}
/// E3 as this machine runs it best: the e3 scene with our blocked sort (fragment passes only).
fn e3(_: u32) -> Result<SceneFile> {
    let mut s = crate::scene::load("e3")?;
    s.render.sort.variant = Some(crate::sort::Variant::Blocked);
    Ok(s)
}
/// E3 as the paper runs it: the e3 scene's own GP/FP packed bitonic sort.
fn e3_paper(_: u32) -> Result<SceneFile> {
    crate::scene::load("e3")
}

/// E4 as the paper runs it: its collision sorts on the GP/FP packed bitonic network.
fn e4_paper(size: u32) -> Result<SceneFile> {
    let mut s = e4::scene(size)?;
    if let Some(c) = &mut s.collisions {
        c.sort = crate::scene::CollisionSort::Packed;
    }
    Ok(s)
}

/// The experiments of Table 2, in the paper's order.
pub fn experiments() -> Vec<Experiment> {
    vec![
        Experiment {
            name: "E1",
            what: "collisionless motion",
            cpu: false,
            paper_fps: [640.0, 320.0, 120.0],
            scene: Some(e1),
            build: Some(|ctx, n, o| gpu_scene(ctx, e1(n)?, n, o)),
        },
        Experiment {
            name: "E2",
            what: "height-field collisions",
            cpu: false,
            paper_fps: [155.0, 96.0, 42.0],
            scene: Some(e2),
            build: Some(|ctx, n, o| gpu_scene(ctx, e2(n)?, n, o)),
        },
        Experiment {
            name: "E3",
            what: "collisionless motion, front-to-back sorting (our blocked sort) and rendering",
            cpu: false,
            paper_fps: [39.0, 8.0, 1.4],
            scene: Some(e3),
            build: Some(|ctx, n, o| gpu_scene(ctx, e3(n)?, n, o)),
        },
        Experiment {
            name: "E3p",
            what: "E3 with the paper's sort (GP/FP packed bitonic)",
            cpu: false,
            paper_fps: [39.0, 8.0, 1.4],
            scene: Some(e3_paper),
            build: Some(|ctx, n, o| gpu_scene(ctx, e3_paper(n)?, n, o)),
        },
        Experiment {
            name: "E4",
            what: "inter-particle collisions (rows-only sort on our blocked network, 8 neighbours)",
            cpu: false,
            paper_fps: [133.0, 31.0, 7.0],
            scene: Some(e4::scene),
            build: Some(|ctx, n, o| gpu_scene(ctx, e4::scene(n)?, n, o)),
        },
        Experiment {
            name: "E4p",
            what: "E4 with the paper's sort (GP/FP packed bitonic)",
            cpu: false,
            paper_fps: [133.0, 31.0, 7.0],
            scene: Some(e4_paper),
            build: Some(|ctx, n, o| gpu_scene(ctx, e4_paper(n)?, n, o)),
        },
        Experiment {
            name: "E5",
            what: "E3 on the CPU: all cores, quicksort by viewer distance, vertex upload",
            cpu: true,
            paper_fps: [7.0, 2.0, 0.4],
            scene: Some(e3),
            build: Some(|ctx, n, o| cpu_scene(ctx, e3(n)?, n, o)),
        },
    ]
}

/// Options of [`bench_scenes`].
#[derive(Debug, Clone)]
pub struct ScenesOptions {
    /// Timed frames per experiment and size (the median is reported).
    pub repeats: usize,
    /// Frames of simulation before timing; `None`: one full emission cycle of the scene.
    pub warmup_frames: Option<usize>,
    /// Clock of the GPU experiments; `None` picks [`Clock::for_context`].
    pub clock: Option<Clock>,
    /// Frame size; `None` keeps the scenes' (512×512).
    pub resolution: Option<[u32; 2]>,
    /// Seed of every experiment (the same spawns on the GPU and the CPU).
    pub seed: u64,
    /// Experiments to run by name (`E1` ... `E5`, any case); empty: all.
    pub experiments: Vec<String>,
}

impl Default for ScenesOptions {
    fn default() -> Self {
        ScenesOptions {
            repeats: 11,
            warmup_frames: None,
            clock: None,
            resolution: None,
            seed: 1,
            experiments: Vec::new(),
        }
    }
}

/// Frames of simulation until every time-stamped particle has been born (the longest cycle,
/// plus one frame); one second of simulation for scenes without time stamps.
pub fn default_warmup_frames(scene: &SceneFile) -> usize {
    let frame = scene.time.dt as f64 * scene.time.substeps.max(1) as f64;
    let cycle = scene
        .emitters
        .timestamp
        .iter()
        .filter_map(|e| e.cycle)
        .fold(0.0f32, f32::max) as f64;
    let span = if cycle > 0.0 { cycle } else { 1.0 };
    (span / frame).ceil() as usize + 1
}

/// One cell of Table 2: an experiment at a size.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SceneRecord {
    /// `E1` ... `E5`.
    pub experiment: String,
    /// What it simulates and draws.
    pub what: String,
    /// `gpu` or `cpu`.
    pub engine: String,
    /// State side: size × size particles.
    pub size: u32,
    /// Particles (size²).
    pub particles: u64,
    /// Frames per second (1000 / ms); `None`: not run.
    pub fps: Option<f64>,
    /// Median milliseconds of one whole frame with `clock`; `None`: not run.
    pub ms: Option<f64>,
    /// Median wall milliseconds of one whole frame (`glFinish` to `glFinish`).
    pub wall_ms: Option<f64>,
    /// UberFlow Table 2's fps, where the paper has the size.
    pub paper_fps: Option<f64>,
    /// GPU/CPU: this experiment's fps over E5's at the same size (E3's is the paper's
    /// comparison).
    pub vs_e5: Option<f64>,
    /// The same ratio in the paper.
    pub paper_vs_e5: Option<f64>,
    /// Particles alive when the timing ended.
    pub live: Option<u64>,
    /// Where the time of a frame goes: medians of as many frames again, each run in parts with
    /// the GPU finished between them (E5: wall clock; others: `clock`).
    pub phases: Vec<Phase>,
    /// Frame size drawn.
    pub resolution: [u32; 2],
    /// Frames simulated before timing.
    pub warmup_frames: usize,
    /// Timed frames behind the median.
    pub repeats: usize,
    /// Clock of `ms` (E5: wall).
    pub clock: Option<Clock>,
    /// Collision experiments (E4): the fraction of overlapping pairs the last timed frame's
    /// detection found (what its fps buys), and the pairs it was measured on.
    pub pairs_found: Option<f64>,
    /// Overlapping pairs behind `pairs_found`.
    pub pairs_true: Option<usize>,
    /// Overlapping partners per live particle (2 × pairs / live): the density the found share
    /// was measured at, held as the state grows.
    pub overlaps_per_particle: Option<f64>,
    /// Why it was not run.
    pub note: Option<String>,
    /// What one whole frame drew, as the GL layer counted it (GPU experiments).
    pub frame_draws: Option<crate::gl::DrawStats>,
}

/// A part of a frame and its median time.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Phase {
    /// What the part does.
    pub name: String,
    /// Median milliseconds.
    pub ms: f64,
}

/// Runs the experiments of Table 2 at each size; `progress(experiment, size)` after each.
pub fn bench_scenes(
    ctx: &Context,
    sizes: &[u32],
    opts: &ScenesOptions,
    mut progress: impl FnMut(&str, u32),
) -> Result<Vec<SceneRecord>> {
    let all = experiments();
    let wanted: Vec<Experiment> = if opts.experiments.is_empty() {
        all
    } else {
        let mut v = Vec::new();
        for name in &opts.experiments {
            match all
                .iter()
                .find(|e| e.name.eq_ignore_ascii_case(name.trim()))
            {
                Some(e) => v.push(*e),
                None => {
                    return Err(Error::InvalidInput(format!(
                    "unknown experiment `{name}`: the experiments are E1, E2, E3, E3p, E4, E4p, E5"
                )))
                }
            }
        }
        v
    };
    if opts.repeats == 0 {
        return Err(Error::InvalidInput("repeats must be at least 1".into()));
    }
    let clock = opts.clock.unwrap_or_else(|| Clock::for_context(ctx));
    let timer = PassTimer::new(ctx, clock)?;
    let mut records = Vec::new();
    for &size in sizes {
        for e in &wanted {
            records.push(run_one(ctx, &timer, e, size, opts)?);
            progress(e.name, size);
        }
    }
    add_ratios(&mut records);
    Ok(records)
}

/// One whole frame, issued without waiting: the frame's steps, then its drawing (with whatever
/// sorting the scene's rendering needs).
fn frame(e: &mut dyn Engine) -> Result<()> {
    e.advance_frame()?;
    e.draw()
}

fn run_one(
    ctx: &Context,
    timer: &PassTimer,
    e: &Experiment,
    size: u32,
    opts: &ScenesOptions,
) -> Result<SceneRecord> {
    let scene = e.scene.map(|f| f(size)).transpose()?;
    let resolution = opts
        .resolution
        .or(scene.as_ref().map(|s| s.render.resolution))
        .unwrap_or([512, 512]);
    let warmup = opts
        .warmup_frames
        .unwrap_or_else(|| scene.as_ref().map_or(0, default_warmup_frames));
    let mut r = unmeasured(e, size, opts, resolution, warmup);
    let Some(build) = e.build else {
        r.note = Some("not run".into());
        return Ok(r);
    };
    let mut src = build(ctx, size, opts)?;
    // E4's collision stage would make the warm-up of a million particles on llvmpipe take most
    // of an hour; its sorts and detection are data-oblivious, so the timed frames (full steps)
    // cost the same after a collisionless warm-up. Births follow time stamps either way, so the
    // same particles are alive.
    for _ in 0..warmup {
        src.warm_up_frame()?;
    }
    for _ in 0..2 {
        frame(src.as_mut())?;
    }
    ctx.finish();
    let mut ms = Vec::with_capacity(opts.repeats);
    let mut wall = Vec::with_capacity(opts.repeats);
    for _ in 0..opts.repeats {
        ctx.finish();
        let t0 = Instant::now();
        if e.cpu {
            frame(src.as_mut())?;
            ctx.finish();
            let t = t0.elapsed().as_secs_f64() * 1e3;
            ms.push(t);
            wall.push(t);
        } else {
            let t = timed(timer, || frame(src.as_mut()))?;
            ctx.finish();
            ms.push(t);
            wall.push(t0.elapsed().as_secs_f64() * 1e3);
        }
    }
    if !e.cpu {
        ctx.take_draw_stats();
        frame(src.as_mut())?;
        r.frame_draws = Some(ctx.take_draw_stats());
    }
    r.phases = phase_medians(src.as_mut(), timer, opts.repeats)?;
    ctx.check_error(&format!("experiment {} at {size}²", e.name))?;
    let m = median(&ms);
    r.ms = Some(m);
    r.fps = Some(1e3 / m);
    r.wall_ms = Some(median(&wall));
    r.clock = Some(if e.cpu { Clock::Wall } else { timer.clock() });
    r.live = Some(src.live()?);
    if let Some(c) = src.census()? {
        r.pairs_found = Some(c.fraction());
        r.pairs_true = Some(c.pairs);
        let live = r.live.unwrap_or(0).max(1) as f64;
        r.overlaps_per_particle = Some(2.0 * c.pairs as f64 / live);
    }
    Ok(r)
}

/// Each phase of a frame timed alone, `repeats` times, as medians in the frame's order.
fn phase_medians(src: &mut dyn Engine, timer: &PassTimer, repeats: usize) -> Result<Vec<Phase>> {
    let mut parts: Vec<(&'static str, Vec<f64>)> = Vec::new();
    for _ in 0..repeats {
        for (k, (name, t)) in src.timed_frame(timer)?.into_iter().enumerate() {
            match parts.get_mut(k) {
                Some(p) => p.1.push(t),
                None => parts.push((name, vec![t])),
            }
        }
    }
    Ok(parts
        .into_iter()
        .map(|(name, t)| Phase {
            name: name.into(),
            ms: median(&t),
        })
        .collect())
}

/// The record of `e` at `size` before anything is measured.
fn unmeasured(
    e: &Experiment,
    size: u32,
    opts: &ScenesOptions,
    resolution: [u32; 2],
    warmup: usize,
) -> SceneRecord {
    SceneRecord {
        experiment: e.name.into(),
        what: e.what.into(),
        engine: if e.cpu { "cpu" } else { "gpu" }.into(),
        size,
        particles: size as u64 * size as u64,
        fps: None,
        ms: None,
        wall_ms: None,
        paper_fps: e.paper(size),
        vs_e5: None,
        paper_vs_e5: None,
        live: None,
        phases: Vec::new(),
        resolution,
        warmup_frames: warmup,
        repeats: opts.repeats,
        clock: None,
        note: None,
        pairs_found: None,
        pairs_true: None,
        overlaps_per_particle: None,
        frame_draws: None,
    }
}
