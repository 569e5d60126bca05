//! `texflow bench scene NAME|FILE`: every phase of any scene's pass plan
//! ([`crate::engine::plan`]) timed alone, next to its floor measured in the same run, and the
//! whole frame's fps and particles per second.
//!
//! The phases, for any scene, from the engine [`crate::engine::build_gpu`] makes (the one
//! `render` runs), taken apart through its [`Stages`]: each stage of a step, from the
//! simulation's own pass list ([`Simulation::passes`], each run alone by
//! [`Simulation::run`]: births, integration, relaxation, the collision stage, or the fire's one
//! pass), for alpha blending the engine's own sort stage in its parts (key pass, network, and
//! the gather of what the renderer draws), and the render pass (clear and points, or sprites).
//! The floors:
//!
//! - a state-writing pass: [`WriteFloor`] into a framebuffer of the same formats and size (over
//!   the live rows where the pass is restricted to them);
//! - the births (the allocator's emit pass, one-pixel points): as many one-pixel points as it
//!   drew, in as many draws, into one RGBA32F texture of the state's size, drawn after it;
//! - the collision stage: its passes (counted by the GL layer) times the fixed cost of a
//!   dependent pass ([`FixedCost`](crate::bench::FixedCost)), plus its bytes written at the
//!   state's write rate;
//! - the sort network: a write into what each pass writes (the sort texture, or the blocked
//!   sort's layers) times the passes run;
//! - the render pass, two bounds, reported against the larger (`src/bench/scene/floors.rs`):
//!   [`PlacedRenderFloor`](crate::bench::PlacedRenderFloor), as many particles as the pass draws
//!   where they are, at the pass's point size and blend, fetching nothing; and the fill floor,
//!   the renderer's own vertex stage (the same points or sprites) with a constant fragment
//!   that leaves the frame unchanged under the pass's blend (`glsl/bench/fill_floor.frag`), no
//!   atlas fetch; and on a GPU clock, points or sprites, the shading floor: the pass's own vertex
//!   and fragment stages, every fetch and computation, each colour then made one its blend
//!   leaves unchanged (what the pass costs but for the blends its colours make);
//! - a lit render (half-angle slices, `src/bench/scene/lit.rs`): beside the placed points, the
//!   slices' chain (as many eye and light passes of one pixel each, in the same order into the
//!   same targets, each eye pass fetching the light buffer) and the slices' fill floor; its
//!   light and eye passes timed apart, each beside the fill floor's passes of its kind;
//! - every other phase, a second bound: the fetch floor (`src/bench/scene/fetch.rs`), for each
//!   full-screen draw the phase made a pass into the same targets and viewport that fetches each
//!   texture the draw bound once at the fragment's texel and writes their sum.
//!
//! Where a floor is drawn, what it drew and what its phase drew (draws, points, bytes, and for
//! the render pass the fragments of a samples query) are kept in the record ([`Drawn`]): a
//! floor is a lower bound by construction only if it draws no more than its phase.
//!
//! Each repetition first times a whole frame (`substeps` steps, then the frame's drawing), then
//! each phase once, each finished before the next (a phase's time is one step's, not a frame's).

use super::cost::{measure_constants, measure_frame_constants, Constants, FrameConstants};
use super::scenes::default_warmup_frames;
use super::stats::{median, Clock, PassTimer, WriteFloor};
use crate::engine::{timed, Stages};
use crate::error::{Error, Result};
use crate::gl::{Context, Framebuffer, SamplesQuery, Texture, TextureDesc};
use crate::scene::SceneFile;
#[cfg(doc)]
use crate::sim::Simulation;

mod fetch;
mod floors;
mod lit;
mod phases;
mod text;
mod walk;
use floors::{render_phase, RenderFloors};
pub use floors::{Bound, Drawn};
use phases::{sort_phases, SortFloors, StateFloors};
pub use text::{run_summary, scene_markdown, summary};

/// One phase of a frame and its floor.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PhaseRecord {
    /// The phase, in the pass plan's words.
    pub phase: String,
    /// Median milliseconds of one run of the phase.
    pub ms: f64,
    /// Median milliseconds of its floor, measured in the same run: the larger of its
    /// [`bounds`](Self::bounds).
    pub floor_ms: f64,
    /// ms / floor_ms.
    pub ratio: f64,
    /// What the floor is (the larger bound).
    pub floor: String,
    /// Every bound measured for the phase in the same run, the first floor first (render
    /// phases: the placed points, then the fill floor; the others: their first floor, then the
    /// fetch floor).
    pub bounds: Vec<Bound>,
    /// What the phase drew in the last repetition, where its floors are drawn passes.
    pub drawn: Option<Drawn>,
    /// The cost model's time for what the phase drew ([`Constants::predict_drawn`] with the
    /// record's [`constants`](SceneBenchRecord::constants); [`Constants::predict_frame`] for
    /// the render pass, whose fragments were counted); `None` where nothing was counted.
    pub predicted_ms: Option<f64>,
}

/// One state size of `texflow bench scene`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SceneBenchRecord {
    /// Scene name.
    pub scene: String,
    /// `fire` or `particles`.
    pub engine: String,
    /// State side: size × size particles.
    pub size: u32,
    /// Particles of the state (size²).
    pub particles: u64,
    /// Particles alive when the timing ended.
    pub live: u64,
    /// Simulation steps per frame.
    pub substeps: u32,
    /// Every phase with its floor.
    pub phases: Vec<PhaseRecord>,
    /// Median milliseconds of one whole frame.
    pub frame_ms: f64,
    /// 1000 / frame_ms.
    pub fps: f64,
    /// Particles of the state simulated and drawn per second (particles × fps).
    pub particles_per_s: f64,
    /// Frame size drawn.
    pub resolution: [u32; 2],
    /// Frames simulated before timing.
    pub warmup_frames: usize,
    /// Timed repetitions behind each median.
    pub repeats: usize,
    /// The clock.
    pub clock: Clock,
    /// The cost model's constants, measured in the same run with targets of the state's size
    /// (1024² at least on a GPU clock, 256² on a wall clock).
    pub constants: Constants,
}

/// Options of [`bench_scene`].
#[derive(Debug, Clone)]
pub struct SceneBenchOptions {
    /// Timed repetitions per size (the medians are reported).
    pub repeats: usize,
    /// Frames of simulation before timing; `None`: one emission cycle (as `bench scenes`).
    pub warmup_frames: Option<usize>,
    /// The clock; `None` picks [`Clock::for_context`].
    pub clock: Option<Clock>,
    /// Frame size; `None` keeps the scene's.
    pub resolution: Option<[u32; 2]>,
    /// Seed of the engine.
    pub seed: u64,
}

impl Default for SceneBenchOptions {
    fn default() -> Self {
        SceneBenchOptions {
            repeats: 11,
            warmup_frames: None,
            clock: None,
            resolution: None,
            seed: 1,
        }
    }
}

/// One phase's times over the repetitions: its own, each bound's, and the last draw counts.
struct PhaseTimes {
    name: String,
    ms: Vec<f64>,
    bounds: Vec<(String, Vec<f64>, Option<Drawn>)>,
    drawn: Option<Drawn>,
}

/// One bound of one repetition: what it is, its milliseconds, what it drew.
type BoundRun<'a> = (&'a str, f64, Option<Drawn>);

/// Collects the times of named phases over repetitions, in first-seen order. The first
/// repetition is a warm-up and is not kept: drivers build programs' variants for a draw state at
/// its first draw (llvmpipe compiles them then), and that would be charged to the phase.
#[derive(Default)]
struct Phases {
    list: Vec<PhaseTimes>,
    warm: bool,
}

impl Phases {
    /// Ends a repetition: from now on, times are kept.
    fn next_repetition(&mut self) {
        self.warm = true;
    }

    /// A phase's time, what it drew, and its bounds (one or more) measured in the same run.
    fn push_bounds(&mut self, name: &str, ms: f64, drawn: Option<Drawn>, bounds: &[BoundRun]) {
        if !self.warm {
            return;
        }
        let i = match self.list.iter().position(|p| p.name == name) {
            Some(i) => i,
            None => {
                self.list.push(PhaseTimes {
                    name: name.into(),
                    ms: Vec::new(),
                    bounds: bounds
                        .iter()
                        .map(|b| (b.0.to_owned(), Vec::new(), None))
                        .collect(),
                    drawn: None,
                });
                self.list.len() - 1
            }
        };
        let p = &mut self.list[i];
        p.ms.push(ms);
        p.drawn = drawn;
        for (kept, b) in p.bounds.iter_mut().zip(bounds) {
            kept.1.push(b.1);
            kept.2 = b.2;
        }
    }

    fn records(self, c: &Constants) -> Vec<PhaseRecord> {
        self.list
            .into_iter()
            .map(|p| {
                let ms = median(&p.ms);
                let bounds: Vec<Bound> = (p.bounds.into_iter())
                    .map(|(floor, t, drawn)| Bound {
                        floor,
                        ms: median(&t),
                        drawn,
                    })
                    .collect();
                let top = bounds
                    .iter()
                    .max_by(|a, b| a.ms.total_cmp(&b.ms))
                    .cloned()
                    .unwrap_or(Bound {
                        floor: String::new(),
                        ms: f64::NAN,
                        drawn: None,
                    });
                PhaseRecord {
                    phase: p.name,
                    ms,
                    floor_ms: top.ms,
                    ratio: ms / top.ms,
                    floor: top.floor,
                    bounds,
                    drawn: p.drawn,
                    // A pass whose fragments were counted draws into the frame.
                    predicted_ms: p.drawn.map(|d| match d.fragments {
                        Some(f) => c.predict_frame(&d.stats, f),
                        None => c.predict_drawn(&d.stats),
                    }),
                }
            })
            .collect()
    }
}

/// A framebuffer of the same size and formats as `fb`: where floors of passes writing `fb` go,
/// so that they leave the state alone.
pub(crate) fn scratch_like(ctx: &Context, fb: &Framebuffer) -> Result<Framebuffer> {
    let textures = fb
        .textures()
        .iter()
        .enumerate()
        .map(|(k, t)| {
            Texture::new(
                ctx,
                TextureDesc {
                    width: t.width(),
                    height: t.height(),
                    format: t.format(),
                    label: &format!("floor scratch {k}"),
                },
            )
        })
        .collect::<Result<Vec<_>>>()?;
    Framebuffer::new(ctx, "floor scratch", textures)
}

/// Runs `f` (a timed range) counting what it drew: the GL layer's draw counts and the fragments.
fn counted(
    ctx: &Context,
    samples: &SamplesQuery,
    f: impl FnOnce() -> Result<f64>,
) -> Result<(f64, Drawn)> {
    ctx.take_draw_stats();
    let (t, fragments) = samples.count(f)?;
    let stats = ctx.take_draw_stats();
    Ok((
        t?,
        Drawn {
            stats,
            fragments: Some(fragments),
            walked: 0,
        },
    ))
}

/// The side of the targets the cost model's constants are measured with for a state of
/// `size`²: on a GPU clock at least 1024², where the write probe's time is its bytes' and not
/// its fixed cost's (on an NVIDIA H100 at 256², the probe less a chained pass's fixed cost gave
/// 0.010-0.014 ms per MB, where the 256² states' own write-only passes wrote 2.1 MB in 40.8 µs,
/// 0.019, and every probe at 1024² or more 0.0174); on a wall clock at least 256², which keeps
/// llvmpipe's probes short.
fn constants_side(size: u32, timer: &PassTimer) -> u32 {
    match timer.clock() {
        Clock::Gpu => size.max(1024),
        Clock::Wall => size.max(256),
    }
}

/// Times every phase of `scene` at each square state size; `progress(size)` after each.
pub fn bench_scene(
    ctx: &Context,
    scene: &SceneFile,
    sizes: &[u32],
    opts: &SceneBenchOptions,
    mut progress: impl FnMut(u32),
) -> Result<Vec<SceneBenchRecord>> {
    if opts.repeats == 0 {
        return Err(Error::InvalidInput("repeats must be at least 1".into()));
    }
    let timer = PassTimer::new(ctx, opts.clock.unwrap_or_else(|| Clock::for_context(ctx)))?;
    prime(ctx, scene, sizes, &timer, opts)?;
    let mut records = Vec::new();
    for &size in sizes {
        let s = at_size(scene, size, opts);
        let warmup = warmup_frames(&s, opts.warmup_frames)?;
        let constants = measure_constants(ctx, &timer, constants_side(size, &timer), opts.repeats)?;
        let (phases, frame, live, model, frame_constants) =
            measure(ctx, &s, warmup, &timer, &constants, opts)?;
        let constants = Constants {
            frame: Some(frame_constants),
            ..constants
        };
        if live.live == 0 && live.non_finite > 0 {
            return Err(Error::InvalidInput(format!(
                "scene {} at {size}x{size}: after {warmup} warm-up frame(s) and the timed ones, \
                 {} particle(s) hold NaN or infinite values and none is live: the state blew up, \
                 and a benchmark of it measures nothing; lower time.dt or the forces \
                 (`texflow render` stops at the first such frame and names it)",
                s.name, live.non_finite
            )));
        }
        let live = live.live;
        if live == 0 {
            return Err(Error::InvalidInput(format!(
                "scene {} at {size}x{size} has no live particle after {warmup} warm-up frame(s) \
                 and the timed ones: a benchmark of an empty state measures nothing; give a \
                 longer --warmup, or emitters that keep particles alive",
                s.name
            )));
        }
        ctx.check_error(&format!("benchmarking scene {} at {size}²", s.name))?;
        let particles = size as u64 * size as u64;
        records.push(SceneBenchRecord {
            scene: s.name.clone(),
            engine: model.into(),
            size,
            particles,
            live,
            substeps: s.time.substeps,
            phases: phases.records(&constants),
            frame_ms: frame,
            fps: 1e3 / frame,
            particles_per_s: particles as f64 * 1e3 / frame,
            resolution: s.render.resolution,
            warmup_frames: warmup,
            repeats: opts.repeats,
            clock: timer.clock(),
            constants,
        });
        progress(size);
    }
    Ok(records)
}

/// `scene` with a `size` × `size` state and the frame size asked.
fn at_size(scene: &SceneFile, size: u32, opts: &SceneBenchOptions) -> SceneFile {
    let mut s = scene.clone();
    s.particles.size = [size, size];
    if let Some(r) = opts.resolution {
        s.render.resolution = r;
    }
    s
}

/// Repetitions of [`prime`]'s untimed measurement.
const PRIME_REPEATS: usize = 10;

/// On a GPU clock, the measurement of the smallest size asked, run untimed over
/// [`PRIME_REPEATS`] repetitions and discarded. On an NVIDIA H100 (driver 580) the floors of
/// the first repetitions a process measured took 5-9 µs longer than the same floors later in
/// the process, at steady clocks (1980 MHz throughout, `nvidia-smi`): `smoke` at 256² measured
/// five times over in one process had its births, integration and key floors at 14.8, 13.3
/// and 22.2 µs in the first measurement (after one untimed repetition) and 5.9, 4.0 and 13.1
/// in every later one, and with 20 repetitions in the first its medians were the later ones:
/// the effect lasts some repetitions, not some sizes. Wall time on llvmpipe shows no such
/// effect and skips this.
fn prime(
    ctx: &Context,
    scene: &SceneFile,
    sizes: &[u32],
    timer: &PassTimer,
    opts: &SceneBenchOptions,
) -> Result<()> {
    let Some(&size) = sizes.iter().min() else {
        return Ok(());
    };
    if timer.clock() != Clock::Gpu {
        return Ok(());
    }
    let s = at_size(scene, size, opts);
    let warmup = warmup_frames(&s, opts.warmup_frames)?;
    let untimed = SceneBenchOptions {
        repeats: PRIME_REPEATS,
        ..opts.clone()
    };
    measure(ctx, &s, warmup, timer, &Constants::NONE, &untimed).map(|_| ())
}

/// Most warm-up frames: the default (one emission cycle) is capped here, and a `--warmup`
/// above it is refused, so that no cycle length or time step makes the warm-up run for hours.
pub const MAX_WARMUP_FRAMES: usize = 10_000;

/// The warm-up of scene `s`: `asked` (at most [`MAX_WARMUP_FRAMES`]), or one emission cycle
/// capped at [`MAX_WARMUP_FRAMES`] (computed in floating point first: a long cycle at a tiny
/// time step would overflow the count, or wrap it to nothing).
pub fn warmup_frames(s: &SceneFile, asked: Option<usize>) -> Result<usize> {
    if let Some(n) = asked {
        if n > MAX_WARMUP_FRAMES {
            return Err(Error::InvalidInput(format!(
                "a warm-up of {n} frames: at most {MAX_WARMUP_FRAMES} frames of warm-up"
            )));
        }
        return Ok(n);
    }
    let frame = s.time.dt as f64 * s.time.substeps.max(1) as f64;
    let cycle = s
        .emitters
        .timestamp
        .iter()
        .filter_map(|e| e.cycle)
        .fold(0.0f32, f32::max) as f64;
    let frames = if cycle > 0.0 { cycle } else { 1.0 } / frame;
    Ok(if frames.is_finite() && frames < MAX_WARMUP_FRAMES as f64 {
        default_warmup_frames(s).min(MAX_WARMUP_FRAMES)
    } else {
        MAX_WARMUP_FRAMES
    })
}

/// Particles alive when the timing ended, and texels whose state is NaN or infinite.
struct Alive {
    live: u64,
    non_finite: u64,
}

/// What `engine` holds at the end: with no live particle, whether the state blew up (NaN or
/// infinite texels, which are neither alive nor drawn) rather than emptied.
fn alive(ctx: &Context, engine: &dyn Stages, s: &SceneFile) -> Result<Alive> {
    let live = engine.live()?;
    let non_finite = match live {
        0 => {
            let [w, h] = s.particles.size;
            let counter = crate::sim::nonfinite::NonFiniteCounter::new(ctx, w, h)?;
            let c = engine.non_finite(&counter)?;
            c.non_finite + c.nan_life
        }
        _ => 0,
    };
    Ok(Alive { live, non_finite })
}

/// Every phase of `s`'s frame over the repetitions, the whole frame's median ms, what is
/// alive at the end, the engine's model, and the constants of its frame (`c`: the constants
/// measured in the same run).
fn measure(
    ctx: &Context,
    s: &SceneFile,
    warmup: usize,
    timer: &PassTimer,
    c: &Constants,
    opts: &SceneBenchOptions,
) -> Result<(Phases, f64, Alive, &'static str, FrameConstants)> {
    let mut engine = crate::engine::build_gpu(ctx, s, opts.seed)?;
    let e = engine.as_mut();
    for _ in 0..warmup {
        e.warm_up_frame()?;
    }
    for _ in 0..2 {
        e.advance_frame()?;
        e.draw()?;
    }
    let state_floors = StateFloors::new(ctx, e.sim())?;
    // The render's constants, into its own frame (the render clears it first).
    let frame_constants =
        measure_frame_constants(ctx, timer, e.target().framebuffer(), c, opts.repeats)?;
    let floor1 = WriteFloor::new(ctx, 1)?;
    let gather = match e.sorted() {
        Some(sorted) => Some(WriteFloor::for_target(ctx, sorted)?),
        None => None,
    };
    let render = RenderFloors::new(ctx, timer, e)?;
    // The sort's layers or integer entries, where they are not one float target.
    let layers = match e.sorter().map(|s| s.target()) {
        Some(t) if t.attachments() > 1 || t.integer() => Some(WriteFloor::for_target(ctx, t)?),
        _ => None,
    };
    let sort_floors = SortFloors {
        timer,
        floor1: &floor1,
        layers: layers.as_ref(),
        gather: gather.as_ref(),
        fetch: &state_floors.fetch,
    };
    let mut phases = Phases::default();
    let mut frames = Vec::new();
    for _ in 0..=opts.repeats {
        frames.push(timed(timer, || {
            e.advance_frame()?;
            e.draw()
        })?);
        // One step, in its phases.
        state_floors.step_phases(ctx, timer, e.sim_mut(), &mut phases)?;
        // The frame's sorting, then its drawing.
        let sorted = sort_phases(ctx, &sort_floors, &mut phases, e)?;
        render_phase(ctx, &render, &mut phases, e, s, sorted)?;
        lit::lit_phases(
            ctx,
            (timer, &render.samples),
            render.lit.as_ref(),
            &mut phases,
            e,
        )?;
        phases.next_repetition();
    }
    let live = alive(ctx, e, s)?;
    Ok((
        phases,
        median(&frames[1..]),
        live,
        e.model(),
        frame_constants,
    ))
}
