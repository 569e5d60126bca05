//! The cost model's constants of a device, each measured by a microbenchmark in the same run
//! as what they predict (`texflow report all --only cost` for the papers' tables, `texflow bench
//! scene` for every phase):
//!
//! | constant | microbenchmark |
//! | --- | --- |
//! | fixed cost of a pass | [`FixedCost`]: 200 passes of one texel, each reading what the one before wrote, divided by 200 |
//! | fixed cost of a follow-on draw | 200 one-texel draws into one target, none reading it, divided by 200 |
//! | fixed cost of a concurrent draw | a one-texel pass, then a draw into a second target, both reading a texel neither writes, less the pass alone |
//! | time per byte written | a write-only pass into a side² RGBA32F target, less the fixed cost |
//! | time per texel fetched | `bench/fetch_probe.frag` (8 scattered RGBA32F fetches a fragment) less the write-only pass, per fetch |
//! | time per point | the target cleared, then `side²` one-pixel points through `bench/render_floor.vert` (uniformly scattered), less the write-only pass |
//! | time per vertex | `side²` vertices of triangles that the clipper drops, each fetching one texel (`bench/vertex_probe.vert`), less a draw's fixed cost |
//!
//! predicted ms = passes × fixed + follow-ons × follow-on + concurrent × concurrent + bytes ×
//! per byte + fetches × per fetch + points × per point + other vertices × per vertex, of the
//! draws, bytes, declared fetches, points and vertices the GL layer counted ([`DrawStats`]): a
//! follow-on is a draw into the target that the draw before it drew into, a concurrent draw one
//! that waits on no earlier draw (it reads nothing they wrote and writes nothing they read), the
//! passes are the other draws (the first, and those of a chain), and the other vertices are
//! those of triangles and lines (a point's vertex is in its point's time).
//!
//! `bench scene` prices its render passes, which draw into a frame and not into the state, with
//! two constants more, measured into a frame target of the scene's resolution ([`FrameConstants`]):
//!
//! | constant | microbenchmark |
//! | --- | --- |
//! | time per blended fragment | eight full-frame triangles blended (additive) into the frame, less the clear and their draws' fixed cost, per fragment |
//! | time per point | the frame cleared, then as many one-pixel points as it has pixels, in its raster order (point k at pixel k) and blended, less the clear, the draw's fixed cost and their fragments |
//! | time per texel cleared | the frame cleared, timed alone, less a pass's fixed cost, per texel |
//!
//! predicted ms = texels cleared × per texel cleared + passes × fixed + follow-ons × follow-on +
//! concurrent × concurrent + fetches × per fetch + points × per point + other vertices × per
//! vertex + fragments × per fragment, the texels cleared and the draws counted by the GL layer
//! (a render pass clears its frame first), the fragments by a samples query around the pass: a
//! fragment's time holds its write, so the bytes that the GL layer counts for a triangle draw
//! (its whole viewport, where a surface or the slices' quads cover a part) are not charged
//! again.

use super::{median, FixedCost, PassTimer, RenderFloor, WriteFloor};
use crate::error::Result;
use crate::gl::{
    Blend, Context, Defines, Draw, DrawState, DrawStats, Framebuffer, FullscreenPass, Primitive,
    Program, Texture, TextureDesc, TextureFormat, Uniform, VertexArray, FULLSCREEN_VERTEX,
};

/// The device's constants, in milliseconds.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Constants {
    /// One pass, however little it writes.
    pub fixed_ms: f64,
    /// One draw into the target the draw before it drew into, however little it writes.
    pub follow_on_ms: f64,
    /// One draw that waits on no earlier draw: it reads nothing they wrote, writes nothing they
    /// read, and goes into another target than the draw before it.
    pub concurrent_ms: f64,
    /// One megabyte written into colour attachments.
    pub ms_per_mb_written: f64,
    /// One million texel fetches (RGBA32F, scattered).
    pub ms_per_m_fetches: f64,
    /// One million one-pixel points.
    pub ms_per_m_points: f64,
    /// One million vertices of triangles or lines, each fetching a texel.
    pub ms_per_m_vertices: f64,
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
    /// One million texels cleared (a render pass clears its frame first): the frame's clear
    /// timed alone, less a pass's fixed cost (a clear waits on what came before it as a pass
    /// does), per texel.
    pub ms_per_m_cleared: f64,
}

impl Constants {
    /// Every constant 0: for runs whose predictions nobody reads (a GPU clock's priming).
    pub const NONE: Constants = Constants {
        fixed_ms: 0.0,
        follow_on_ms: 0.0,
        concurrent_ms: 0.0,
        ms_per_mb_written: 0.0,
        ms_per_m_fetches: 0.0,
        ms_per_m_points: 0.0,
        ms_per_m_vertices: 0.0,
        frame: None,
    };

    /// The model's time for a piece of work, every draw a pass.
    pub fn predict(&self, passes: u64, bytes: u64, fetches: u64, points: u64) -> f64 {
        passes as f64 * self.fixed_ms
            + bytes as f64 * 1e-6 * self.ms_per_mb_written
            + fetches as f64 * 1e-6 * self.ms_per_m_fetches
            + points as f64 * 1e-6 * self.ms_per_m_points
    }

    /// The constants in words, as the tables print them (the frame's apart).
    pub fn describe(&self) -> String {
        format!(
            "{:.4} ms a pass, {:.6} ms a follow-on draw, {:.6} ms a concurrent draw, {:.4} ms per \
             MB written, {:.4} ms per million texel fetches, {:.4} ms per million points, {:.4} \
             ms per million vertices of triangles and lines",
            self.fixed_ms,
            self.follow_on_ms,
            self.concurrent_ms,
            self.ms_per_mb_written,
            self.ms_per_m_fetches,
            self.ms_per_m_points,
            self.ms_per_m_vertices
        )
    }

    /// The draws' fixed costs and their vertices other than points'.
    fn draws_and_vertices(&self, d: &DrawStats) -> f64 {
        d.chained() as f64 * self.fixed_ms
            + d.follow_ons.min(d.draws) as f64 * self.follow_on_ms
            + d.concurrent.min(d.draws) as f64 * self.concurrent_ms
            + d.vertices.saturating_sub(d.points) as f64 * 1e-6 * self.ms_per_m_vertices
    }

    /// The model's time for what the GL layer counted.
    pub fn predict_drawn(&self, d: &DrawStats) -> f64 {
        self.draws_and_vertices(d) + self.predict(0, d.bytes_written, d.fetches, d.points)
    }

    /// The model's time for a pass drawing into a frame that passed `fragments` (a samples
    /// query's count): its points and fragments at the frame's constants where measured, else
    /// as [`predict_drawn`](Self::predict_drawn).
    pub fn predict_frame(&self, d: &DrawStats, fragments: u64) -> f64 {
        match self.frame {
            Some(f) => {
                d.cleared as f64 * 1e-6 * f.ms_per_m_cleared
                    + self.draws_and_vertices(d)
                    + self.predict(0, 0, d.fetches, 0)
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
    let follow_on_ms = med(&mut || fixed.measure_follow_ons(timer))?;
    let concurrent_ms = med(&mut || fixed.measure_concurrent(timer))?;
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
    let probe = VertexProbe::new(ctx)?;
    let vertices = med(&mut || timer.time(|| probe.draw(&target, &source, points)))?;
    let per_m = |t: f64, n: f64| (t.max(0.0) / n) * 1e6;
    Ok(Constants {
        fixed_ms,
        follow_on_ms,
        concurrent_ms,
        ms_per_m_vertices: per_m(vertices - fixed_ms, points as f64),
        ms_per_mb_written: per_m(write - fixed_ms, bytes),
        ms_per_m_fetches: per_m(fetch - write, fetches as f64 * points as f64),
        ms_per_m_points: per_m(drawn - write, points as f64),
        frame: None,
    })
}

/// The vertex probe: triangles whose vertices each fetch a texel and that the clipper drops
/// (`glsl/bench/vertex_probe.vert`).
struct VertexProbe {
    ctx: Context,
    program: Program,
    empty: VertexArray,
}

impl VertexProbe {
    fn new(ctx: &Context) -> Result<Self> {
        let d: Defines = vec![("TARGETS".into(), "1".into())];
        Ok(VertexProbe {
            ctx: ctx.clone(),
            program: Program::new(
                ctx,
                "bench/vertex_probe.vert",
                "common/write_floor.frag",
                &d,
            )?,
            empty: VertexArray::empty(ctx, "vertex probe")?,
        })
    }

    /// `vertices` (rounded down to whole triangles) fetching texels of `source` (a square of a
    /// power-of-two side), drawn towards `target`.
    fn draw(&self, target: &Framebuffer, source: &Texture, vertices: usize) {
        let log_w = source.width().trailing_zeros() as i32;
        self.ctx.draw(&Draw {
            program: &self.program,
            target,
            viewport: None,
            vertices: &self.empty,
            primitive: Primitive::Triangles,
            count: (vertices / 3 * 3) as u32,
            state: &DrawState::REPLACE,
            textures: &[("u_source", source.into())],
            uniforms: &[
                ("u_log_w", Uniform::I32(log_w)),
                ("u_zero", Uniform::F32(0.0)),
                ("u_value", Uniform::Vec4(glam::Vec4::ZERO)),
            ],
        });
    }
}

/// Full-frame triangles drawn for the fragment probe: enough fragments to time well above a
/// timer's resolution at small frames.
const FRAGMENT_PROBE_DRAWS: usize = 8;

/// Measures the frame constants into `frame` (the scene's frame target: its size, format and
/// depth attachment, not tested), medians of `repeats`, less the draws' fixed costs (`c`'s,
/// measured in the same run, which the model charges each draw apart: the first draw into the
/// frame a pass, the probe's others follow-ons). Leaves `frame` holding the probes' colours: a
/// render clears it first.
pub fn measure_frame_constants(
    ctx: &Context,
    timer: &PassTimer,
    frame: &Framebuffer,
    c: &Constants,
    repeats: usize,
) -> Result<FrameConstants> {
    let fixed_ms = c.fixed_ms;
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
    let draws_ms = fixed_ms + (draws - 1.0) * c.follow_on_ms;
    let fragment = (blended - clear - draws_ms).max(0.0) / (draws * pixels);
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
        ms_per_m_cleared: (clear - fixed_ms).max(0.0) / pixels * 1e6,
    })
}
