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
//!
//! `bench scene` prices its render passes, which draw into a frame and not into the state, with
//! two constants more, measured into a frame target of the scene's resolution ([`FrameConstants`]):
//!
//! | constant | microbenchmark |
//! | --- | --- |
//! | time per blended fragment | eight full-frame triangles blended (additive) into the frame, less the clear and their draws' fixed cost, per fragment |
//! | time per point | the frame cleared, then as many one-pixel points as it has pixels, in its raster order (point k at pixel k) and blended, less the clear, the draw's fixed cost and their fragments |
//!
//! predicted ms = draws × fixed + bytes × per byte + points × per point + fragments × per
//! fragment, the fragments counted by a samples query around the pass. Triangles and lines (a
//! surface, strands, the colliders' geometry) are priced by their fragments alone: no probe
//! prices their vertices.

use super::{median, FixedCost, PassTimer, RenderFloor, WriteFloor};
use crate::error::Result;
use crate::gl::{
    Blend, Context, Defines, DrawState, DrawStats, Framebuffer, FullscreenPass, Program, Texture,
    TextureDesc, TextureFormat, Uniform, FULLSCREEN_VERTEX,
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
    /// Drawing into a frame (`bench scene`'s render passes); `None` where not measured.
    pub frame: Option<FrameConstants>,
}

/// The constants of drawing into a frame: a target of the scene's resolution and the renderer's
/// format, blended additively.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct FrameConstants {
    /// The frame measured into.
    pub resolution: [u32; 2],
    /// One million one-pixel points drawn over the frame in its raster order, their fragments
    /// apart.
    pub ms_per_m_points: f64,
    /// One million fragments blended into the frame.
    pub ms_per_m_fragments: f64,
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

    /// The model's time for a pass drawing into a frame that passed `fragments` (a samples
    /// query's count): its points and fragments at the frame's constants where measured, else
    /// as [`predict_drawn`](Self::predict_drawn).
    pub fn predict_frame(&self, d: &DrawStats, fragments: u64) -> f64 {
        match self.frame {
            Some(f) => {
                self.predict(d.draws, d.bytes_written, d.fetches, 0)
                    + d.points as f64 * 1e-6 * f.ms_per_m_points
                    + fragments as f64 * 1e-6 * f.ms_per_m_fragments
            }
            None => self.predict_drawn(d),
        }
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

/// The median of `repeats` (at least one) runs of `f`.
fn median_of(repeats: usize, f: &mut dyn FnMut() -> Result<f64>) -> Result<f64> {
    let mut t = Vec::new();
    for _ in 0..repeats.max(1) {
        t.push(f()?);
    }
    Ok(median(&t))
}

/// Measures the constants on `ctx` with side² targets (medians of `repeats`).
pub fn measure_constants(
    ctx: &Context,
    timer: &PassTimer,
    side: u32,
    repeats: usize,
) -> Result<Constants> {
    let med = |f: &mut dyn FnMut() -> Result<f64>| median_of(repeats, f);
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
        frame: None,
    })
}

/// Full-frame triangles drawn for the fragment probe: enough fragments to time well above a
/// timer's resolution at small frames.
const FRAGMENT_PROBE_DRAWS: usize = 8;

/// Measures the frame constants into `frame` (the scene's frame target: its size, format and
/// depth attachment, not tested), medians of `repeats`, less `fixed_ms` a draw (the fixed cost
/// of a pass measured in the same run, which the model charges each draw apart). Leaves `frame`
/// holding the probes' colours: a render clears it first.
pub fn measure_frame_constants(
    ctx: &Context,
    timer: &PassTimer,
    frame: &Framebuffer,
    fixed_ms: f64,
    repeats: usize,
) -> Result<FrameConstants> {
    let med = |f: &mut dyn FnMut() -> Result<f64>| median_of(repeats, f);
    let additive = Blend::SUM;
    let state = DrawState {
        blend: Some(additive),
        ..DrawState::REPLACE
    };
    let d: Defines = vec![("TARGETS".into(), "1".into())];
    let program = Program::new(ctx, FULLSCREEN_VERTEX, "common/write_floor.frag", &d)?;
    let pass = FullscreenPass::new(ctx)?;
    // A visible value, 5/255 or more in every channel of an RGBA8 frame (a blend that changes
    // nothing may be skipped: NVIDIA does), and eight of them do not saturate it.
    let value = [("u_value", Uniform::Vec4(glam::Vec4::splat(0.02)))];
    let clear = med(&mut || timer.time(|| frame.clear([0.0; 4])))?;
    let blended = med(&mut || {
        timer.time(|| {
            frame.clear([0.0; 4]);
            for _ in 0..FRAGMENT_PROBE_DRAWS {
                pass.draw_with(&program, &[], &value, frame, &state);
            }
        })
    })?;
    let pixels = frame.width() as f64 * frame.height() as f64;
    let draws = FRAGMENT_PROBE_DRAWS as f64;
    let fragment = (blended - clear - draws * fixed_ms).max(0.0) / (draws * pixels);
    let render = RenderFloor::new(ctx)?;
    let points = frame.width() as usize * frame.height() as usize;
    // In raster order: scattered uniformly over the frame, a million points took 2.54 ms on an
    // NVIDIA H100 where the renders of 1M particles into the same 512² frames took 0.64-0.99
    // (e1, e3, snow, collide): a render's particles come in clusters, its blends in cache.
    let drawn = med(&mut || {
        timer.time(|| render.draw_in_raster_order(frame, [0.0; 4], Some(additive), points))
    })?;
    let point = ((drawn - clear - fixed_ms) / pixels - fragment).max(0.0);
    Ok(FrameConstants {
        resolution: [frame.width(), frame.height()],
        ms_per_m_points: point * 1e6,
        ms_per_m_fragments: fragment * 1e6,
    })
}
