//! Benchmarks: time of passes, medians over many runs after warm-up, each pass next to its floor
//! measured in the same run (a write-only pass of the same size and formats: on a GPU whose
//! fragment path is bound by the bytes it writes, no pass that writes those targets can be
//! faster).
//!
//! Two clocks: on a hardware GPU, `GL_TIME_ELAPSED` timer queries; on Mesa's llvmpipe, wall time
//! between two `glFinish` calls. llvmpipe bins draws and rasterizes them only when the scene is
//! flushed (at the next framebuffer change, say), so its timer queries charge a pass's work to
//! whatever query is open at the flush; the CPU is its GPU, so finished wall time is exact there.

use std::time::Instant;

use glam::{Vec3, Vec4};

use crate::engine::Engine;
use crate::error::Result;
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, Program, TimerQuery, FULLSCREEN_VERTEX,
};
use crate::gl::{PingPong, TextureFormat};
use crate::scene::Scene;
use crate::sort::network::{key_order_bits, Entry};
use crate::sort::{KeyMode, SortOptions, Sorter, Variant};

/// A write-only pass into `targets` render targets: the floor of any pass writing them.
#[derive(Debug)]
pub struct WriteFloor {
    program: Program,
    pass: FullscreenPass,
}

impl WriteFloor {
    /// Builds the floor pass for framebuffers of `targets` attachments.
    pub fn new(ctx: &Context, targets: usize) -> Result<Self> {
        let defines: Defines = vec![("TARGETS".into(), targets.to_string())];
        Ok(WriteFloor {
            program: Program::new(ctx, FULLSCREEN_VERTEX, "common/write_floor.frag", &defines)?,
            pass: FullscreenPass::new(ctx)?,
        })
    }

    /// Writes a constant into every texel of every attachment of `fb`.
    pub fn draw(&self, fb: &Framebuffer) {
        self.program.bind();
        self.program
            .set_vec4("u_value", Vec4::new(0.25, 0.5, 0.75, 1.0));
        self.pass.draw(&self.program, fb);
    }
}

/// The median of `v` (mean of the two middle values for an even count); NaN for none.
pub fn median(v: &[f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    if n % 2 == 1 {
        s[n / 2]
    } else {
        0.5 * (s[n / 2 - 1] + s[n / 2])
    }
}

/// How passes are timed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Clock {
    /// `GL_TIME_ELAPSED` queries around the pass (hardware GPUs).
    Gpu,
    /// Wall time from one `glFinish` to another around the pass (software rasterizers).
    Wall,
}

impl Clock {
    /// The right clock for a context: wall time on software renderers, timer queries otherwise.
    pub fn for_context(ctx: &Context) -> Clock {
        let r = ctx.limits().renderer.to_ascii_lowercase();
        if r.contains("llvmpipe") || r.contains("softpipe") || r.contains("swrast") {
            Clock::Wall
        } else {
            Clock::Gpu
        }
    }

    /// The clock's name in tables.
    pub fn name(self) -> &'static str {
        match self {
            Clock::Gpu => "GPU timer query",
            Clock::Wall => "glFinish wall time",
        }
    }
}

/// Times GL work with one [`Clock`].
#[derive(Debug)]
pub struct PassTimer {
    ctx: Context,
    clock: Clock,
    query: TimerQuery,
}

impl PassTimer {
    /// A timer on `ctx` using `clock`.
    pub fn new(ctx: &Context, clock: Clock) -> Result<Self> {
        Ok(PassTimer {
            ctx: ctx.clone(),
            clock,
            query: TimerQuery::new(ctx)?,
        })
    }

    /// The clock in use.
    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// Milliseconds the GL commands issued by `f` take.
    pub fn time(&self, f: impl FnOnce()) -> Result<f64> {
        match self.clock {
            Clock::Gpu => Ok(self.query.time(f)?.1),
            Clock::Wall => {
                self.ctx.finish();
                let t0 = Instant::now();
                f();
                self.ctx.finish();
                Ok(t0.elapsed().as_secs_f64() * 1e3)
            }
        }
    }
}

/// One row of `texflow bench step`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StepRecord {
    /// Scene name.
    pub scene: String,
    /// State texture side (size × size particles).
    pub size: u32,
    /// Number of particles.
    pub particles: u64,
    /// Median GPU time of one simulation pass, ms.
    pub sim_ms: f64,
    /// Median GPU time of a write-only pass into the same targets, ms.
    pub sim_floor_ms: f64,
    /// sim_ms / sim_floor_ms.
    pub sim_ratio: f64,
    /// Simulated particles per second (particles / sim_ms).
    pub particles_per_s: f64,
    /// Median GPU time of one render pass (clear + points), ms.
    pub render_ms: f64,
    /// Median GPU time of a write-only full-screen pass into the frame target, ms.
    pub render_floor_ms: f64,
    /// render_ms / render_floor_ms.
    pub render_ratio: f64,
    /// Frame size the render pass drew.
    pub resolution: [u32; 2],
    /// Timed repetitions behind each median.
    pub repeats: usize,
    /// The clock the times come from.
    pub clock: Clock,
}

/// The records of [`bench_step`] as a markdown table.
pub fn step_markdown(records: &[StepRecord]) -> String {
    let mut out = format!(
        "| state | particles | sim ms | floor ms | sim/floor | Mparticles/s | render ms ({}) | \
         render floor ms | render/floor |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        records
            .first()
            .map(|r| format!("{}x{}", r.resolution[0], r.resolution[1]))
            .unwrap_or_default()
    );
    for r in records {
        out.push_str(&format!(
            "| {0}x{0} | {1} | {2:.3} | {3:.3} | {4:.2} | {5:.1} | {6:.3} | {7:.3} | {8:.2} |\n",
            r.size,
            r.particles,
            r.sim_ms,
            r.sim_floor_ms,
            r.sim_ratio,
            r.particles_per_s * 1e-6,
            r.render_ms,
            r.render_floor_ms,
            r.render_ratio
        ));
    }
    out
}

/// Options of [`bench_step`].
#[derive(Debug, Clone)]
pub struct StepOptions {
    /// Timed repetitions per size.
    pub repeats: usize,
    /// Simulation steps before timing, so that the state is in its steady state.
    pub warmup_steps: usize,
    /// The clock; `None` picks [`Clock::for_context`].
    pub clock: Option<Clock>,
}

impl Default for StepOptions {
    fn default() -> Self {
        StepOptions {
            repeats: 21,
            warmup_steps: 120,
            clock: None,
        }
    }
}

/// Times the simulation and render passes of `scene` at each square state size.
pub fn bench_step(
    ctx: &Context,
    scene: &Scene,
    sizes: &[u32],
    opts: &StepOptions,
    mut progress: impl FnMut(u32),
) -> Result<Vec<StepRecord>> {
    let sim_floor = WriteFloor::new(ctx, 2)?;
    let render_floor = WriteFloor::new(ctx, 1)?;
    let timer = PassTimer::new(ctx, opts.clock.unwrap_or_else(|| Clock::for_context(ctx)))?;
    let mut records = Vec::new();
    for &size in sizes {
        let mut s = scene.clone();
        s.particles = [size, size];
        let mut engine = Engine::new(ctx, s, 1)?;
        let dt = scene.dt;
        for _ in 0..opts.warmup_steps {
            engine.advance_frame();
        }
        let mut t = [vec![], vec![], vec![], vec![]];
        for _ in 0..opts.repeats {
            let sim = engine.sim();
            t[0].push(timer.time(|| sim_floor.draw(sim.state().back()))?);
            sim.bind_step(dt);
            t[1].push(timer.time(|| sim.draw_step_only())?);
            // The timed pass wrote the back without swapping; advancing redoes it and swaps, so
            // the state keeps evolving between repetitions.
            engine.advance_frame();
            t[2].push(timer.time(|| render_floor.draw(engine.target().framebuffer()))?);
            t[3].push(timer.time(|| engine.draw())?);
        }
        ctx.check_error("benchmark")?;
        let [floor, sim_ms, rfloor, render] = t.map(|v| median(&v));
        let particles = size as u64 * size as u64;
        records.push(StepRecord {
            scene: scene.name.clone(),
            size,
            particles,
            sim_ms,
            sim_floor_ms: floor,
            sim_ratio: sim_ms / floor,
            particles_per_s: particles as f64 / (sim_ms * 1e-3),
            render_ms: render,
            render_floor_ms: rfloor,
            render_ratio: render / rfloor,
            resolution: scene.resolution,
            repeats: opts.repeats,
            clock: timer.clock(),
        });
        progress(size);
    }
    Ok(records)
}

/// UberFlow's Table 1 (fps on an ATI 9800 Pro, 2004) for a variant and texture side, if the paper
/// has it.
pub fn paper_table1_fps(variant: Variant, size: u32) -> Option<f64> {
    let row: &[f64; 4] = match variant {
        Variant::Fp => &[22.0, 3.5, 1.0, 0.2],
        Variant::GpFp => &[40.0, 10.0, 3.0, 0.4],
        Variant::Packed => &[148.0, 43.0, 10.0, 2.0],
        _ => return None,
    };
    let col = match size {
        128 => 0,
        256 => 1,
        512 => 2,
        1024 => 3,
        _ => return None,
    };
    Some(row[col])
}

/// One row of `texflow bench sort`: a full sort of size × size entries including the key pass and
/// the rearrangement of two RGBA32F state textures, or a CPU baseline on the same keys.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SortRecord {
    /// `fp`, `gpfp`, `packed`, `oddeven`, `multistep`, or `cpu-sort_unstable_by`,
    /// `cpu-par_sort_unstable_by`.
    pub variant: String,
    /// Texture side (size × size entries).
    pub size: u32,
    /// Median milliseconds of one full sort.
    pub ms: f64,
    /// Full sorts per second (the paper's fps).
    pub fps: f64,
    /// Millions of entries sorted per second.
    pub mtexels_per_s: f64,
    /// Passes: key pass + sort passes + rearrangement (0 for the CPU).
    pub passes: usize,
    /// The floor: write-only passes of the same formats and sizes, as many as the sort has.
    pub floor_ms: Option<f64>,
    /// ms / floor_ms.
    pub ratio: Option<f64>,
    /// UberFlow Table 1 fps, where the paper has the variant and size.
    pub paper_fps: Option<f64>,
    /// The clock (CPU baselines: wall time).
    pub clock: Clock,
    /// Timed runs behind the median.
    pub repeats: usize,
}

/// The records of [`bench_sort`] as a markdown table (UberFlow's Table 1 beside them).
pub fn sort_markdown(records: &[SortRecord]) -> String {
    let mut out = String::from(
        "| variant | size | ms | fps | paper fps (9800 Pro) | M entries/s | passes | floor ms | \
         ms / floor |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let opt = |v: Option<f64>, digits: usize| {
        v.map(|x| format!("{x:.digits$}"))
            .unwrap_or_else(|| "–".into())
    };
    for r in records {
        out.push_str(&format!(
            "| {} | {}² | {:.3} | {:.1} | {} | {:.1} | {} | {} | {} |\n",
            r.variant,
            r.size,
            r.ms,
            r.fps,
            opt(r.paper_fps, 1),
            r.mtexels_per_s,
            if r.passes == 0 {
                "–".to_string()
            } else {
                r.passes.to_string()
            },
            opt(r.floor_ms, 3),
            opt(r.ratio, 2)
        ));
    }
    out
}

/// Options of [`bench_sort`].
#[derive(Debug, Clone)]
pub struct SortBenchOptions {
    /// Timed repetitions per variant and size.
    pub repeats: usize,
    /// Clock; `None` picks [`Clock::for_context`].
    pub clock: Option<Clock>,
    /// Also time the CPU baselines.
    pub cpu: bool,
    /// Steps per pass of the multistep variant.
    pub steps_per_pass: usize,
}

fn lcg(state: &mut u64) -> f32 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    ((*state >> 40) as f32) / (1u64 << 24) as f32
}

/// Times full sorts (key pass, network, rearrangement) of each variant at each size, with
/// floors, and the CPU sorting the same keys.
pub fn bench_sort(
    ctx: &Context,
    sizes: &[u32],
    variants: &[Variant],
    opts: &SortBenchOptions,
    mut progress: impl FnMut(&str, u32),
) -> Result<Vec<SortRecord>> {
    let clock = opts.clock.unwrap_or_else(|| Clock::for_context(ctx));
    let timer = PassTimer::new(ctx, clock)?;
    let floor1 = WriteFloor::new(ctx, 1)?;
    let floor2 = WriteFloor::new(ctx, 2)?;
    let mut records = Vec::new();
    for &n in sizes {
        let count = (n * n) as usize;
        let mut seed = 0x5eed_u64 + n as u64;
        let pos: Vec<f32> = (0..count)
            .flat_map(|_| {
                let mut c = || lcg(&mut seed) * 20.0 - 10.0;
                [c(), c(), c(), 1.0]
            })
            .collect();
        let state = PingPong::new(
            ctx,
            "bench state",
            &["position", "velocity"],
            &[TextureFormat::Rgba32F, TextureFormat::Rgba32F],
            n,
            n,
        )?;
        state.front().texture(0).upload_f32(&pos)?;
        state.front().texture(1).upload_f32(&pos)?;
        let mode = KeyMode::ViewerDistance {
            eye: Vec3::new(0.0, 0.0, 40.0),
            back_to_front: true,
        };
        let median_of = |f: &mut dyn FnMut() -> Result<f64>| -> Result<f64> {
            let mut t = Vec::with_capacity(opts.repeats);
            for _ in 0..opts.repeats {
                t.push(f()?);
            }
            Ok(median(&t))
        };
        let rearrange_floor = median_of(&mut || timer.time(|| floor2.draw(state.back())))?;
        let mut keys_for_cpu = None;
        for &variant in variants {
            let options = SortOptions {
                steps_per_pass: opts.steps_per_pass,
                ..SortOptions::default()
            };
            let mut sorter = Sorter::new(ctx, variant, n, n, options)?;
            let full = |s: &mut Sorter| -> Result<()> {
                s.write_keys(state.front().texture(0), count, &mode, false)?;
                s.sort();
                s.rearrange(state.front(), state.back())
            };
            full(&mut sorter)?; // warm-up: compiles lazily built programs, touches every buffer
            if keys_for_cpu.is_none() {
                sorter.write_keys(state.front().texture(0), count, &mode, false)?;
                keys_for_cpu = Some(sorter.read()?);
            }
            let ms = median_of(&mut || {
                let mut r = Ok(());
                let t = timer.time(|| r = full(&mut sorter))?;
                r.map(|_| t)
            })?;
            let sort_floor = median_of(&mut || timer.time(|| floor1.draw(sorter.target())))?;
            ctx.check_error("sort benchmark")?;
            let passes = sorter.pass_count() + 2;
            let floor = sort_floor * (passes - 1) as f64 + rearrange_floor;
            records.push(SortRecord {
                variant: variant.name().into(),
                size: n,
                ms,
                fps: 1e3 / ms,
                mtexels_per_s: count as f64 / ms * 1e-3,
                passes,
                floor_ms: Some(floor),
                ratio: Some(ms / floor),
                paper_fps: paper_table1_fps(variant, n),
                clock,
                repeats: opts.repeats,
            });
            progress(variant.name(), n);
        }
        if let (true, Some(keys)) = (opts.cpu, keys_for_cpu) {
            fn order(a: &Entry, b: &Entry) -> std::cmp::Ordering {
                (key_order_bits(a[0]), a[1].to_bits()).cmp(&(key_order_bits(b[0]), b[1].to_bits()))
            }
            type CpuSort = fn(&mut [Entry]);
            let baselines: [(&str, CpuSort); 2] = [
                ("cpu-sort_unstable_by", |v| v.sort_unstable_by(order)),
                ("cpu-par_sort_unstable_by", |v| {
                    use rayon::slice::ParallelSliceMut;
                    v.par_sort_unstable_by(order)
                }),
            ];
            for (name, sort) in baselines {
                let mut t = Vec::new();
                for _ in 0..opts.repeats {
                    let mut v = keys.clone();
                    let t0 = Instant::now();
                    sort(&mut v);
                    t.push(t0.elapsed().as_secs_f64() * 1e3);
                    std::hint::black_box(&v);
                }
                let ms = median(&t);
                records.push(SortRecord {
                    variant: name.into(),
                    size: n,
                    ms,
                    fps: 1e3 / ms,
                    mtexels_per_s: count as f64 / ms * 1e-3,
                    passes: 0,
                    floor_ms: None,
                    ratio: None,
                    paper_fps: None,
                    clock: Clock::Wall,
                    repeats: opts.repeats,
                });
            }
            progress("cpu", n);
        }
    }
    Ok(records)
}
