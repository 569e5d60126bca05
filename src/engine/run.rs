//! The frame loop: `frames` frames of an [`Engine`], every `every`-th one drawn and handed to a
//! [`FrameSink`], every `dump_every`-th state dump handed to it too, and the non-finite census of
//! each written frame. The CLI's `render`, the examples and the tests all drive this one loop.

use std::ops::ControlFlow;
use std::path::{Path, PathBuf};

use super::{Engine, StateDump};
use crate::error::{Error, Result};
use crate::gl::{Clock, Context, PassTimer};
use crate::output::FrameWriter;
use crate::sim::nonfinite::{NonFiniteCount, NonFiniteCounter};

/// What the loop does with NaN or infinite state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NonFinitePolicy {
    /// Count it, report it through [`Event::NonFinite`] and in the summary, and go on.
    #[default]
    Report,
    /// Stop at the first written frame that has any, with [`Error::NonFinite`].
    Fail,
}

/// What to run and what to hand to the sink.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoopOptions {
    /// Frames to simulate.
    pub frames: u64,
    /// Draw and hand over every `every`-th frame from `start` on (`start` first).
    pub every: u64,
    /// The first frame drawn and handed over (and dumped): the frames before it are simulated
    /// only, so that a video can skip a scene's build-up. Frames keep their index.
    pub start: u64,
    /// Dump the live state every `n`-th frame, or never.
    pub dump_every: Option<u64>,
    /// What NaN or infinite state does to the run.
    pub non_finite: NonFinitePolicy,
    /// Time each frame's phases (simulate, sort, draw) with [`PassTimer`]: GPU timer queries on
    /// a GPU, `glFinish` wall time on llvmpipe. Off by default: the wall clock waits for the GPU.
    pub timing: bool,
}

impl Default for LoopOptions {
    fn default() -> Self {
        LoopOptions {
            frames: 60,
            every: 1,
            start: 0,
            dump_every: None,
            non_finite: NonFinitePolicy::Report,
            timing: false,
        }
    }
}

impl LoopOptions {
    /// Refuses options that would run or write nothing, naming the field.
    pub fn check(&self) -> Result<()> {
        match self.problem() {
            Some((field, reason)) => Err(Error::InvalidInput(format!(
                "LoopOptions::{field} = {}: {reason}",
                self.value_of(field)
            ))),
            None => Ok(()),
        }
    }

    /// What would make the loop run or write nothing: the field (`frames`, `every`,
    /// `dump_every`, `start`) and why, for a caller to name in its own terms (the CLI names its
    /// options).
    pub fn problem(&self) -> Option<(&'static str, String)> {
        if self.frames == 0 {
            return Some(("frames", "renders nothing: ask for at least 1 frame".into()));
        }
        if self.every == 0 {
            return Some(("every", "is meaningless: use 1 to write every frame".into()));
        }
        if self.dump_every == Some(0) {
            return Some((
                "dump_every",
                "is meaningless: use 1 to dump every frame".into(),
            ));
        }
        if self.start >= self.frames {
            return Some((
                "start",
                format!(
                    "is not before {} frames: nothing would be written; frames are numbered from \
                     0, so ask for more frames or an earlier start",
                    self.frames
                ),
            ));
        }
        None
    }

    /// The value of a field [`problem`](Self::problem) names.
    pub fn value_of(&self, field: &str) -> u64 {
        match field {
            "frames" => self.frames,
            "every" => self.every,
            "dump_every" => self.dump_every.unwrap_or(0),
            _ => self.start,
        }
    }

    /// Whether frame `index` is one to draw and hand over.
    pub fn writes(&self, index: u64) -> bool {
        index >= self.start && (index - self.start).is_multiple_of(self.every.max(1))
    }

    /// Frames the run hands over (all `frames` simulated): those from `start` on, every
    /// `every`-th.
    pub fn written_count(&self) -> u64 {
        self.frames
            .saturating_sub(self.start)
            .div_ceil(self.every.max(1))
    }
}

/// Where the loop's frames and dumps go.
pub trait FrameSink {
    /// Receives frame `index`.
    fn frame(&mut self, index: u64, image: &image::RgbImage) -> Result<()>;
    /// Receives the live state after frame `index`.
    fn dump(&mut self, _index: u64, _dump: &StateDump) -> Result<()> {
        Ok(())
    }
}

/// Something the loop tells its caller about while it runs.
#[derive(Debug, Clone, Copy)]
pub enum Event<'a> {
    /// Frame `index` is done (simulated, and written if it was due).
    Frame {
        /// The frame's index.
        index: u64,
    },
    /// The first frame after which births were dropped because the state texture was full.
    BirthsDropped {
        /// The frame's index.
        index: u64,
        /// Births dropped so far.
        total: u64,
    },
    /// The first written frame with constraints stretched past the scene's `stretch_bound`
    /// (later ones only count in the summary).
    Stretched {
        /// The frame's index.
        index: u64,
        /// The census of that frame.
        count: &'a crate::sim::Stretched,
    },
    /// The first written frame with NaN or infinite state (later ones only count in the summary).
    NonFinite {
        /// The frame's index.
        index: u64,
        /// The census of that frame.
        count: &'a NonFiniteCount,
    },
}

/// What a run did.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoopSummary {
    /// Frames simulated.
    pub frames: u64,
    /// Frames handed to the sink.
    pub written: u64,
    /// State dumps handed to the sink.
    pub dumps: u64,
    /// Simulation steps taken in all.
    pub steps: u64,
    /// The most live particles with NaN or infinite values in one written frame or dump.
    pub max_non_finite: u64,
    /// Written frames that had any.
    pub non_finite_frames: u64,
    /// Whether non-finite state was reported (once per run, from a written frame or a dump).
    pub non_finite_reported: bool,
    /// With distance constraints: the most constraints stretched past the scene's
    /// `stretch_bound` in one written frame.
    pub max_stretched: u64,
    /// Written frames that had any.
    pub stretched_frames: u64,
    /// With `[fluid]`: each written frame's index with its density error and energy.
    pub fluid: Vec<(u64, crate::sim::fluid::FluidStats)>,
    /// Whether the caller stopped the loop early (through its event callback).
    pub stopped: bool,
    /// Births the allocator dropped because the state texture was full.
    pub dropped_births: u64,
    /// Births that child emitters' texels could not take because their children still lived
    /// (read back once, at the end of the run).
    pub dropped_child_births: u64,
    /// Exact collision searches that walked past their bound of particles per run of cells
    /// (read back once, at the end of the run), summed over steps and iterations.
    pub truncated_searches: u64,
    /// Particle steps whose path still entered a collider after the bound on bounces per step
    /// (read back once, at the end of the run).
    pub truncated_bounces: u64,
    /// Live particles at the last written frame's census.
    pub live: u64,
    /// Per-frame phase times, when [`LoopOptions::timing`] asked for them.
    pub times: Option<FrameTimes>,
}

/// Milliseconds per phase of every frame (`render --stats`).
#[derive(Debug, Clone, PartialEq)]
pub struct FrameTimes {
    /// The clock the times come from.
    pub clock: Clock,
    /// The simulation steps of each frame.
    pub simulate: Vec<f64>,
    /// The sort stage of each frame (0 for scenes that do not sort).
    pub sort: Vec<f64>,
    /// Drawing and reading back each written frame.
    pub draw: Vec<f64>,
}

impl FrameTimes {
    /// The median of each phase, in milliseconds: simulate, sort, draw.
    pub fn medians(&self) -> [f64; 3] {
        let m = |v: &[f64]| {
            let mut s = v.to_vec();
            s.sort_by(f64::total_cmp);
            match s.len() {
                0 => f64::NAN,
                n if n % 2 == 1 => s[n / 2],
                n => 0.5 * (s[n / 2 - 1] + s[n / 2]),
            }
        };
        [m(&self.simulate), m(&self.sort), m(&self.draw)]
    }
}

/// Runs an [`Engine`] frame after frame.
///
/// ```
/// use std::ops::ControlFlow;
/// use texflow::engine::{FrameLoop, LoopOptions, MemorySink};
/// use texflow::{engine, gl::Context, scene};
/// let ctx = Context::new(0)?;
/// let mut s = scene::load("snow")?;
/// s.particles.size = [16, 16];
/// s.render.resolution = [24, 16];
/// let mut engine = engine::build(&ctx, &s, 1, engine::EngineKind::Gpu)?;
/// let options = LoopOptions { frames: 9, every: 4, ..LoopOptions::default() };
/// let run = FrameLoop::new(&ctx, engine.as_ref(), options)?;
/// let mut sink = MemorySink::default();
/// let summary = run.run(engine.as_mut(), &mut sink, |_| ControlFlow::Continue(()))?;
/// let written: Vec<u64> = sink.frames.iter().map(|(i, _)| *i).collect();
/// assert_eq!(written, [0, 4, 8]);
/// assert_eq!(summary.max_non_finite, 0);
/// # Ok::<(), texflow::Error>(())
/// ```
#[derive(Debug)]
pub struct FrameLoop {
    options: LoopOptions,
    counter: NonFiniteCounter,
    timer: Option<PassTimer>,
}

impl FrameLoop {
    /// Checks the options and builds the GPU census for `engine`'s state size.
    pub fn new(ctx: &Context, engine: &dyn Engine, options: LoopOptions) -> Result<Self> {
        options.check()?;
        let [w, h] = engine.state_size();
        let timer = match options.timing {
            true => Some(PassTimer::new(ctx, Clock::for_context(ctx))?),
            false => None,
        };
        Ok(FrameLoop {
            options,
            counter: NonFiniteCounter::new(ctx, w, h)?,
            timer,
        })
    }

    /// The options.
    pub fn options(&self) -> &LoopOptions {
        &self.options
    }

    /// Runs every frame. `on_event` may stop the loop between frames by returning
    /// `ControlFlow::Break(())`; what was handed to the sink so far stays there.
    pub fn run(
        &self,
        engine: &mut dyn Engine,
        sink: &mut dyn FrameSink,
        mut on_event: impl FnMut(Event<'_>) -> ControlFlow<()>,
    ) -> Result<LoopSummary> {
        let mut s = LoopSummary::default();
        let mut times = self.timer.as_ref().map(|t| FrameTimes {
            clock: t.clock(),
            simulate: Vec::new(),
            sort: Vec::new(),
            draw: Vec::new(),
        });
        for index in 0..self.options.frames {
            let step = self.frame(engine, sink, index, &mut s, &mut times, &mut on_event)?;
            if step.is_break() {
                s.stopped = true;
                break;
            }
        }
        s.steps = engine.steps();
        s.dropped_child_births = engine.dropped_child_births()?;
        s.truncated_searches = engine.truncated_searches()?;
        s.truncated_bounces = engine.truncated_bounces()?;
        s.times = times;
        Ok(s)
    }

    /// Runs `f`, timed into `into` when timing is on.
    fn timed(&self, f: &mut dyn FnMut() -> Result<()>, into: Option<&mut Vec<f64>>) -> Result<()> {
        match (&self.timer, into) {
            (Some(t), Some(v)) => {
                let mut r = Ok(());
                v.push(t.time(|| r = f())?);
                r
            }
            _ => f(),
        }
    }

    /// Frame `index`: its steps and sort, its census, picture and dump where it writes them;
    /// `Break` where the frame or `on_event` stops the run.
    fn frame(
        &self,
        engine: &mut dyn Engine,
        sink: &mut dyn FrameSink,
        index: u64,
        s: &mut LoopSummary,
        times: &mut Option<FrameTimes>,
        on_event: &mut impl FnMut(Event<'_>) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        let o = &self.options;
        self.timed(
            &mut || engine.advance_frame(),
            times.as_mut().map(|t| &mut t.simulate),
        )?;
        // The sort belongs to every frame, written or not: no option that chooses what is
        // written may change what a frame shows.
        self.timed(
            &mut || engine.order_for_drawing(),
            times.as_mut().map(|t| &mut t.sort),
        )?;
        s.frames += 1;
        let dropped = engine.dropped_births();
        let first_drop = dropped > 0 && s.dropped_births == 0;
        s.dropped_births = dropped;
        if first_drop
            && on_event(Event::BirthsDropped {
                index,
                total: dropped,
            })
            .is_break()
        {
            return Ok(ControlFlow::Break(()));
        }
        if o.writes(index) {
            // Garbage is reported, not rendered silently.
            if self.census(engine, index, s, on_event)?.is_break() {
                return Ok(ControlFlow::Break(()));
            }
            let mut image = None;
            self.timed(
                &mut || {
                    image = Some(engine.render()?);
                    Ok(())
                },
                times.as_mut().map(|t| &mut t.draw),
            )?;
            sink.frame(index, &image.expect("rendered"))?;
            s.written += 1;
        }
        let dumps =
            (o.dump_every).is_some_and(|n| index >= o.start && (index - o.start).is_multiple_of(n));
        if dumps && self.dump(engine, index, s, sink, on_event)?.is_break() {
            return Ok(ControlFlow::Break(()));
        }
        Ok(on_event(Event::Frame { index }))
    }

    /// The dump of frame `index`: checked like a frame (non-finite state is an error under
    /// [`NonFinitePolicy::Fail`], else reported once, and the caller may stop), then handed to
    /// `sink`.
    fn dump(
        &self,
        engine: &mut dyn Engine,
        index: u64,
        s: &mut LoopSummary,
        sink: &mut dyn FrameSink,
        on_event: &mut impl FnMut(Event<'_>) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        let d = engine.dump()?;
        if d.non_finite > 0 {
            let count = NonFiniteCount {
                non_finite: d.non_finite as u64,
                live: d.positions.len() as u64,
                ..NonFiniteCount::default()
            };
            if self.options.non_finite == NonFinitePolicy::Fail {
                return Err(Error::NonFinite {
                    origin: source_of(&d, &engine.emitter_keys()),
                    frame: index,
                    count: count.non_finite,
                    live: count.live,
                });
            }
            if !s.non_finite_reported {
                s.non_finite_reported = true;
                if on_event(Event::NonFinite {
                    index,
                    count: &count,
                })
                .is_break()
                {
                    return Ok(ControlFlow::Break(()));
                }
            }
        }
        s.max_non_finite = s.max_non_finite.max(d.non_finite as u64);
        sink.dump(index, &d)?;
        s.dumps += 1;
        Ok(ControlFlow::Continue(()))
    }

    /// The censuses of frame `index` before it is written: constraints stretched past their
    /// bound, counted into `s` and reported once; non-finite state, counted into `s`, an error
    /// under [`NonFinitePolicy::Fail`], else reported once (the caller may stop).
    fn census(
        &self,
        engine: &mut dyn Engine,
        index: u64,
        s: &mut LoopSummary,
        on_event: &mut impl FnMut(Event<'_>) -> ControlFlow<()>,
    ) -> Result<ControlFlow<()>> {
        let o = &self.options;
        if let Some(c) = engine.stretched()?.filter(|c| c.edges > 0) {
            if s.stretched_frames == 0 && on_event(Event::Stretched { index, count: &c }).is_break()
            {
                return Ok(ControlFlow::Break(()));
            }
            s.stretched_frames += 1;
            s.max_stretched = s.max_stretched.max(c.edges);
        }
        if let Some(f) = engine.fluid_stats()? {
            s.fluid.push((index, f));
        }
        let count = engine.non_finite(&self.counter)?;
        s.live = count.live;
        // A NaN life is lost state too (neither alive nor dead, so never drawn or dumped).
        if !count.is_clean() {
            if o.non_finite == NonFinitePolicy::Fail {
                let mut source = source_of(&engine.dump()?, &engine.emitter_keys());
                if count.nan_life > 0 {
                    source += &format!(
                        "; {} texel(s) have a NaN life (neither alive nor dead)",
                        count.nan_life
                    );
                }
                return Err(Error::NonFinite {
                    origin: source,
                    frame: index,
                    count: count.non_finite,
                    live: count.live,
                });
            }
            let first = !s.non_finite_reported;
            s.non_finite_reported = true;
            if first
                && on_event(Event::NonFinite {
                    index,
                    count: &count,
                })
                .is_break()
            {
                return Ok(ControlFlow::Break(()));
            }
            s.non_finite_frames += 1;
            s.max_non_finite = (s.max_non_finite).max(count.non_finite + count.nan_life);
        }
        Ok(ControlFlow::Continue(()))
    }
}

/// Where the non-finite particles of `d` came from, when its static array tells: the emitter
/// they all belong to (of `keys`, in type order), and the time stamp (birth time or phase) they
/// all share; empty when they are of several emitters or the dump has no statics.
pub fn source_of(d: &StateDump, keys: &[String]) -> String {
    let Some((_, statics)) = d.more.iter().find(|(n, _)| *n == "statics") else {
        return String::new();
    };
    let finite = |r: &[f32; 4]| r.iter().all(|x| x.is_finite());
    let bad: Vec<[f32; 4]> = (0..d.positions.len())
        .filter(|&i| {
            !(finite(&d.positions[i])
                && finite(&d.velocities[i])
                && d.more.iter().all(|(_, a)| a.get(i).is_none_or(finite)))
        })
        .filter_map(|i| statics.get(i).copied())
        .collect();
    let Some(first) = bad.first() else {
        return String::new();
    };
    if bad.iter().any(|s| s[1] != first[1]) {
        return "; they are particles of several emitters".to_owned();
    }
    let Some(key) = keys.get(first[1] as usize) else {
        return String::new();
    };
    let mut out = format!("; all are particles of `{key}`");
    if bad.iter().all(|s| s[0] == first[0]) {
        out += &format!(", all with birth time (or phase) {} s", first[0]);
    }
    out
}

/// Frames as `frame_00000.png, ...` in one folder, and dumps as `positions_00000.npy`,
/// `velocities_00000.npy` and the scene's other state arrays (`statics_00000.npy`, ...: see
/// [`DUMP_NAMES`](super::DUMP_NAMES); N×4 float32, live particles only, row i the same particle
/// in each) in another (or the same).
#[derive(Debug)]
pub struct FolderSink {
    frames: FrameWriter,
    dumps: Option<FrameWriter>,
    written: Vec<PathBuf>,
}

impl FolderSink {
    /// Creates the folders (and their parents) if needed.
    pub fn create(frames: &Path, dumps: Option<&Path>) -> Result<Self> {
        Self::create_named(frames, dumps, "the state-dump folder")
    }

    /// [`create`](Self::create), with the dump folder called `dumps_name` in errors (the CLI
    /// gives the option that named it).
    pub fn create_named(frames: &Path, dumps: Option<&Path>, dumps_name: &str) -> Result<Self> {
        Ok(FolderSink {
            frames: FrameWriter::create(frames)?,
            dumps: dumps
                .map(|d| FrameWriter::create_for(d, dumps_name))
                .transpose()?,
            written: Vec::new(),
        })
    }

    /// The files written so far, in order.
    pub fn written(&self) -> &[PathBuf] {
        &self.written
    }
}

impl FrameSink for FolderSink {
    fn frame(&mut self, index: u64, image: &image::RgbImage) -> Result<()> {
        let path = self.frames.write(index, image)?;
        self.written.push(path);
        Ok(())
    }

    fn dump(&mut self, index: u64, dump: &StateDump) -> Result<()> {
        let Some(w) = &self.dumps else {
            return Ok(());
        };
        let rows = |v: &[[f32; 4]]| v.iter().flatten().copied().collect::<Vec<f32>>();
        let n = dump.positions.len();
        let arrays = [
            ("positions", rows(&dump.positions)),
            ("velocities", rows(&dump.velocities)),
        ];
        let more = dump.more.iter().map(|(name, a)| (*name, rows(a)));
        for (what, data) in arrays.into_iter().chain(more) {
            let path = w.dir().join(format!("{what}_{index:05}.npy"));
            crate::npy::write_f32_shaped(&path, &[n, 4], &data)?;
            self.written.push(path);
        }
        Ok(())
    }
}

/// Keeps frames in memory (tests and examples that look at pixels rather than files).
#[derive(Debug, Default)]
pub struct MemorySink {
    /// The frames handed over, with their indices.
    pub frames: Vec<(u64, image::RgbImage)>,
    /// The dumps handed over, with their indices.
    pub dumps: Vec<(u64, StateDump)>,
}

impl FrameSink for MemorySink {
    fn frame(&mut self, index: u64, image: &image::RgbImage) -> Result<()> {
        self.frames.push((index, image.clone()));
        Ok(())
    }

    fn dump(&mut self, index: u64, dump: &StateDump) -> Result<()> {
        self.dumps.push((index, dump.clone()));
        Ok(())
    }
}
