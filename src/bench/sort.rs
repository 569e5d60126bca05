//! `texflow bench sort`: UberFlow's Table 1, full sorts per variant and size with floors and CPU
//! baselines.

use std::time::Instant;

use glam::Vec3;

use super::stats::{load_average, Clock, PassTimer, Spread, WriteFloor};
use crate::error::Result;
use crate::gl::{Context, PingPong, TextureFormat};
use crate::sim::state::{POSITION, VELOCITY};
use crate::sort::network::Entry;
use crate::sort::{BlockedShape, KeyMode, SortOptions, Sorter, Variant};

/// UberFlow's Table 1 (fps on an ATI 9800 Pro, 2004) for a variant and texture side, if the paper
/// has it.
pub fn paper_table1_fps(variant: Variant, size: u32) -> Option<f64> {
    let row: &[f64; 4] = match variant {
        Variant::Fp => &[22.0, 3.5, 1.0, 0.2],
        Variant::GpFp => &[40.0, 10.0, 3.0, 0.4],
        Variant::Packed => &[148.0, 43.0, 10.0, 2.0],
        Variant::OddEven | Variant::Multistep | Variant::Blocked => return None,
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
    /// `fp`, `gpfp`, `packed`, `oddeven`, `multistep`, `blocked` (`blocked-b3`, `blocked-b4p`:
    /// 2^b entries per fragment, `p` with the pinned lane, when several shapes are run), or
    /// `cpu-sort_unstable_by`, `cpu-par_sort_unstable_by`.
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
    /// Count, min, median and max of the timed runs (ms).
    pub spread: Spread,
    /// The floor's own spread (ms), for GPU rows.
    pub floor_spread: Option<Spread>,
    /// The machine's one-minute load average when the cell started and ended.
    pub load: [Option<f64>; 2],
    /// Whether the cell is unreliable at a glance: runs spread over 1.5× (min to max), or the
    /// sort ran under its floor (a floor that failed).
    pub flagged: bool,
    /// What one full sort drew, as the GL layer counted it (passes, bytes written), for GPU rows.
    pub draws: Option<crate::gl::DrawStats>,
    /// Texel fetches of one full sort: the key pass (1 per entry), the network, and the
    /// rearrangement (the sorted entry and one texel per state texture).
    pub fetches: Option<u64>,
}

/// The records of [`bench_sort`] as a markdown table (UberFlow's Table 1 beside them).
pub fn sort_markdown(records: &[SortRecord]) -> String {
    let mut out = String::from(
        "| variant | size | ms | min–max (n) | fps | paper fps (9800 Pro) | M entries/s | passes | \
         floor ms | ms / floor |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let opt = |v: Option<f64>, digits: usize| {
        v.map(|x| format!("{x:.digits$}"))
            .unwrap_or_else(|| "–".into())
    };
    for r in records {
        out.push_str(&format!(
            "| {} | {}² | {:.3}{} | {:.3}–{:.3} ({}) | {:.1} | {} | {:.1} | {} | {} | {} |\n",
            r.variant,
            r.size,
            r.ms,
            if r.flagged { " ⚠" } else { "" },
            r.spread.min,
            r.spread.max,
            r.spread.count,
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
    /// Shapes of the blocked variant to run (one row each); empty: the default shape.
    pub blocked_shapes: Vec<BlockedShape>,
}

/// The row name of a blocked shape: `blocked` alone for the default shape when it is the only
/// one, else `blocked-b<bits>` with `p` for the pinned lane, `c` for compact entries and `m`
/// for merge passes.
fn blocked_name(shape: BlockedShape, several: bool) -> String {
    if !several && shape == BlockedShape::default() {
        "blocked".into()
    } else {
        format!("blocked-b{}", shape.label())
    }
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
        let state = bench_state(ctx, n)?;
        let rearrange_floor = runs_of(opts.repeats, &mut || {
            timer.time(|| floor2.draw(state.back()))
        })?
        .median;
        let size = SizeRun {
            ctx,
            timer: &timer,
            floor1: &floor1,
            clock,
            repeats: opts.repeats,
            n,
            state,
            mode: KeyMode::ViewerDistance {
                eye: Vec3::new(0.0, 0.0, 40.0),
                back_to_front: true,
            },
            rearrange_floor,
        };
        let mut keys_for_cpu = None;
        let runs = named_runs(variants, opts);
        for (variant, options, name) in runs {
            records.push(size.record(variant, options, &name, &mut keys_for_cpu)?);
            progress(&name, n);
        }
        if let (true, Some(keys)) = (opts.cpu, keys_for_cpu) {
            records.extend(cpu_baselines(&keys, n, opts.repeats));
            progress("cpu", n);
        }
    }
    Ok(records)
}

/// The spread of `repeats` timed runs of `f`.
fn runs_of(repeats: usize, f: &mut dyn FnMut() -> Result<f64>) -> Result<Spread> {
    let mut t = Vec::with_capacity(repeats);
    for _ in 0..repeats {
        t.push(f()?);
    }
    Ok(Spread::of(&t))
}

/// What every sort of one size shares: the clock and floors, the state it rearranges, the key
/// mode, and the rearrangement's floor.
struct SizeRun<'a> {
    ctx: &'a Context,
    timer: &'a PassTimer,
    floor1: &'a WriteFloor,
    clock: Clock,
    repeats: usize,
    n: u32,
    state: PingPong,
    mode: KeyMode,
    rearrange_floor: f64,
}

impl SizeRun<'_> {
    /// The spread of the timed runs of `f`.
    fn runs(&self, f: &mut dyn FnMut() -> Result<f64>) -> Result<Spread> {
        runs_of(self.repeats, f)
    }

    /// One full sort: the key pass, the network, the rearrangement.
    fn full(&self, s: &mut Sorter) -> Result<()> {
        let count = (self.n * self.n) as usize;
        s.write_keys(
            self.state.front().texture(POSITION),
            count,
            &self.mode,
            false,
        )?;
        s.sort();
        s.rearrange(self.state.front(), self.state.back())
    }

    /// Times one sort (a variant with its options) against its floor; the first sort to run
    /// also leaves its keys in `keys_for_cpu` for the CPU baselines.
    fn record(
        &self,
        variant: Variant,
        options: SortOptions,
        name: &str,
        keys_for_cpu: &mut Option<Vec<Entry>>,
    ) -> Result<SortRecord> {
        let (ctx, n) = (self.ctx, self.n);
        let count = (n * n) as usize;
        let load_start = load_average();
        let mut sorter = bench_sorter(ctx, variant, n, options)?;
        self.full(&mut sorter)?; // warm-up: compiles lazily built programs, touches every buffer
        ctx.take_draw_stats();
        self.full(&mut sorter)?;
        let draws = ctx.take_draw_stats();
        // As the passes declared them: the key pass, the network, the rearrangement.
        let fetches = draws.fetches;
        if keys_for_cpu.is_none() {
            sorter.write_keys(
                self.state.front().texture(POSITION),
                count,
                &self.mode,
                false,
            )?;
            *keys_for_cpu = Some(sorter.read()?);
        }
        let spread = self.runs(&mut || {
            let mut r = Ok(());
            let t = self.timer.time(|| r = self.full(&mut sorter))?;
            r.map(|_| t)
        })?;
        let (natural, network_floor, partition_floor) = self.floors(&sorter)?;
        ctx.check_error("sort benchmark")?;
        self.check(&mut sorter, name)?;
        let passes = sorter.pass_count() + 2;
        let network = sorter.network_pass_count();
        let partitions = sorter.partition_pass_count();
        let floor = network_floor.median * network as f64
            + partition_floor * partitions as f64
            + natural.median * (passes - 1 - network - partitions) as f64
            + self.rearrange_floor;
        let ms = spread.median;
        Ok(SortRecord {
            variant: name.to_owned(),
            size: n,
            ms,
            fps: 1e3 / ms,
            mtexels_per_s: count as f64 / ms * 1e-3,
            passes,
            floor_ms: Some(floor),
            ratio: Some(ms / floor),
            paper_fps: paper_table1_fps(variant, n),
            clock: self.clock,
            repeats: self.repeats,
            spread,
            floor_spread: Some(network_floor),
            load: [load_start, load_average()],
            flagged: spread.unreliable() || ms < 0.95 * floor,
            draws: Some(draws),
            fetches: Some(fetches),
        })
    }

    /// Sorts once more and checks the result against the CPU's order of the same keys.
    fn check(&self, sorter: &mut Sorter, name: &str) -> Result<()> {
        let count = (self.n * self.n) as usize;
        let position = self.state.front().texture(POSITION);
        sorter.write_keys(position, count, &self.mode, false)?;
        let keys = sorter.read()?;
        sorter.sort();
        let got = sorter.read()?;
        super::sort_check::check_sorted(name, self.n, &keys, &got, sorter.quantiser())
    }

    /// The floors of one sort's passes: (the row-major sort texture's, the network's, the
    /// partition passes' median ms: 0 without them).
    fn floors(&self, sorter: &Sorter) -> Result<(Spread, Spread, f64)> {
        // The network's passes write the sorter's target (for the blocked variant, its
        // layers through MRT); the key pass and the blocked unpack pass write the row-major
        // sort texture; the partition passes their splits; the rearrangement writes the two
        // state textures.
        let timer = self.timer;
        let natural = self.runs(&mut || timer.time(|| self.floor1.draw(sorter.keys_target())))?;
        let target = sorter.target();
        let network_floor = if target.attachments() > 1 || target.integer() {
            let f = WriteFloor::for_target(self.ctx, target)?;
            // Drawn once untimed: a new program's first draw pays for its code.
            f.draw(target);
            self.runs(&mut || timer.time(|| f.draw(sorter.target())))?
        } else {
            natural
        };
        let partition = match sorter.partition_target() {
            Some(t) => {
                self.runs(&mut || timer.time(|| self.floor1.draw(t)))?
                    .median
            }
            None => 0.0,
        };
        Ok((natural, network_floor, partition))
    }
}

/// An n×n state of random positions (also as velocities) for the sort to rearrange.
fn bench_state(ctx: &Context, n: u32) -> Result<PingPong> {
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
        &[POSITION, VELOCITY],
        &[TextureFormat::Rgba32F, TextureFormat::Rgba32F],
        n,
        n,
    )?;
    state.front().texture(POSITION).upload_f32(&pos)?;
    state.front().texture(VELOCITY).upload_f32(&pos)?;
    Ok(state)
}

/// The sorts to run, named: each variant, the blocked one once per shape asked for.
/// A sorter of `n`×`n` entries; compact entries get the range of the benchmark's keys.
fn bench_sorter(ctx: &Context, variant: Variant, n: u32, options: SortOptions) -> Result<Sorter> {
    let mut sorter = Sorter::new(ctx, variant, n, n, options)?;
    if options.blocked.compact && variant == Variant::Blocked {
        // The CPU knows the bounds of what it placed (a cube of side 20 around the origin, seen
        // from 40 along z, keys negated), as a renderer knows its scene's.
        sorter.set_key_range(-2700f32.sqrt(), -30.0)?;
    }
    Ok(sorter)
}

fn named_runs(
    variants: &[Variant],
    opts: &SortBenchOptions,
) -> Vec<(Variant, SortOptions, String)> {
    let mut runs: Vec<(Variant, SortOptions, String)> = Vec::new();
    for &variant in variants {
        let options = SortOptions {
            steps_per_pass: opts.steps_per_pass,
            ..SortOptions::default()
        };
        if variant == Variant::Blocked && !opts.blocked_shapes.is_empty() {
            let several = opts.blocked_shapes.len() > 1;
            for &shape in &opts.blocked_shapes {
                let o = SortOptions {
                    blocked: shape,
                    ..options
                };
                runs.push((variant, o, blocked_name(shape, several)));
            }
        } else {
            runs.push((variant, options, variant.name().to_string()));
        }
    }
    runs
}

/// The CPU baselines on the same keys: the standard library's unstable sort and rayon's
/// parallel one (wall time).
fn cpu_baselines(keys: &[Entry], n: u32, repeats: usize) -> Vec<SortRecord> {
    use crate::sort::network::entry_order as order;
    type CpuSort = fn(&mut [Entry]);
    let baselines: [(&str, CpuSort); 2] = [
        ("cpu-sort_unstable_by", |v| v.sort_unstable_by(order)),
        ("cpu-par_sort_unstable_by", |v| {
            use rayon::slice::ParallelSliceMut;
            v.par_sort_unstable_by(order)
        }),
    ];
    let count = (n * n) as usize;
    let mut records = Vec::new();
    for (name, sort) in baselines {
        let load_start = load_average();
        let mut t = Vec::new();
        for _ in 0..repeats {
            let mut v = keys.to_vec();
            let t0 = Instant::now();
            sort(&mut v);
            t.push(t0.elapsed().as_secs_f64() * 1e3);
            std::hint::black_box(&v);
        }
        let spread = Spread::of(&t);
        let ms = spread.median;
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
            repeats,
            spread,
            floor_spread: None,
            load: [load_start, load_average()],
            flagged: spread.unreliable(),
            draws: None,
            fetches: None,
        });
    }
    records
}
