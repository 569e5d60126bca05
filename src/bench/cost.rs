//! The cost model's constants of a device, each measured by a microbenchmark in the same run
//! as what they predict (`texflow report all --only cost` for the papers' tables, `texflow bench
//! scene` for every phase):
//!
//! | constant | microbenchmark |
//! | --- | --- |
//! | fixed cost of a pass | [`FixedCost`]: 200 write-only passes into 1×1, divided by 200 |
//! | time per byte written | a write-only pass into a side² RGBA32F target, less the fixed cost |
//! | time per texel fetched | `bench/fetch_probe.frag` (8 scattered RGBA32F fetches a fragment) less the write-only pass, per fetch |
//! | time per point | the target cleared, then `side²` one-pixel points through `bench/render_floor.vert` (uniformly scattered), less the write-only pass |
//!
//! predicted ms = passes × fixed + bytes × per byte + fetches × per fetch + points × per point,
//! of the passes, bytes, declared fetches and points the GL layer counted ([`DrawStats`]).

use super::{median, FixedCost, PassTimer, RenderFloor, WriteFloor};
use crate::error::Result;
use crate::gl::{
    Context, Defines, DrawStats, Framebuffer, FullscreenPass, Program, Texture, TextureDesc,
    TextureFormat, Uniform, FULLSCREEN_VERTEX,
};

/// The device's constants, in milliseconds.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Constants {
    /// One pass, however little it writes.
    pub fixed_ms: f64,
    /// One megabyte written into colour attachments.
    pub ms_per_mb_written: f64,
    /// One million texel fetches (RGBA32F, scattered).
    pub ms_per_m_fetches: f64,
    /// One million one-pixel points.
    pub ms_per_m_points: f64,
}

impl Constants {
    /// The model's time for a piece of work.
    pub fn predict(&self, passes: u64, bytes: u64, fetches: u64, points: u64) -> f64 {
        passes as f64 * self.fixed_ms
            + bytes as f64 * 1e-6 * self.ms_per_mb_written
            + fetches as f64 * 1e-6 * self.ms_per_m_fetches
            + points as f64 * 1e-6 * self.ms_per_m_points
    }

    /// The model's time for what the GL layer counted (`draws` as passes).
    pub fn predict_drawn(&self, d: &DrawStats) -> f64 {
        self.predict(d.draws, d.bytes_written, d.fetches, d.points)
    }
}

fn texture(ctx: &Context, side: u32, label: &str) -> Result<Texture> {
    Texture::new(
        ctx,
        TextureDesc {
            width: side,
            height: side,
            format: TextureFormat::Rgba32F,
            label,
        },
    )
}

/// GPU time of full-screen writes drawn before the probes (ms), and the most draws it takes.
const WARM_UP_MS: f64 = 200.0;
const WARM_UP_DRAWS: usize = 2000;

/// Measures the constants on `ctx` with side² targets (medians of `repeats`).
pub fn measure_constants(
    ctx: &Context,
    timer: &PassTimer,
    side: u32,
    repeats: usize,
) -> Result<Constants> {
    let med = |f: &mut dyn FnMut() -> Result<f64>| -> Result<f64> {
        let mut t = Vec::new();
        for _ in 0..repeats.max(1) {
            t.push(f()?);
        }
        Ok(median(&t))
    };
    let target = Framebuffer::new(
        ctx,
        "cost model target",
        vec![texture(ctx, side, "cost target")?],
    )?;
    let source = texture(ctx, side, "cost source")?;
    let floor = WriteFloor::new(ctx, 1)?;
    // A GPU leaves its idle clocks only under load, and the report reaches these probes after
    // minutes of CPU work: timed cold, an H100 wrote at 38 GB/s here against 57 in the bench
    // passes of the same job. So the probes run after WARM_UP_MS of full-screen writes.
    let mut warm = 0.0;
    for _ in 0..WARM_UP_DRAWS {
        warm += timer.time(|| floor.draw(&target))?;
        if warm >= WARM_UP_MS {
            break;
        }
    }
    let fixed = FixedCost::new(ctx)?;
    let fixed_ms = med(&mut || fixed.measure(timer))?;
    let write = med(&mut || timer.time(|| floor.draw(&target)))?;
    let bytes = side as f64 * side as f64 * 16.0;
    let fetches = 8u32;
    let d: Defines = vec![("FETCHES".into(), fetches.to_string())];
    let probe = Program::new(ctx, FULLSCREEN_VERTEX, "bench/fetch_probe.frag", &d)?;
    let pass = FullscreenPass::new(ctx)?;
    let fetch = med(&mut || {
        timer.time(|| {
            let log_w = [("u_log_w", Uniform::I32(side.trailing_zeros() as i32))];
            pass.draw(&probe, &[("u_source", (&source).into())], &log_w, &target);
        })
    })?;
    let points = side as usize * side as usize;
    let render = RenderFloor::new(ctx)?;
    let drawn = med(&mut || timer.time(|| render.draw(&target, [0.0; 4], None, points)))?;
    let per_m = |t: f64, n: f64| (t.max(0.0) / n) * 1e6;
    Ok(Constants {
        fixed_ms,
        ms_per_mb_written: per_m(write - fixed_ms, bytes),
        ms_per_m_fetches: per_m(fetch - write, fetches as f64 * points as f64),
        ms_per_m_points: per_m(drawn - write, points as f64),
    })
}
