//! Shared measuring tools: the median, the write-only floor passes, and the JSON records. The
//! two clocks and the pass timer are the GL layer's ([`crate::gl::Clock`], [`crate::gl::PassTimer`]).

use glam::Vec4;

use crate::error::Result;
use crate::gl::{
    Attribute, Blend, Buffer, BufferKind, BufferUsage, Context, Defines, Draw, DrawState,
    Framebuffer, FullscreenPass, PointSize, Primitive, Program, Uniform, VertexArray,
    FULLSCREEN_VERTEX,
};
pub use crate::gl::{Clock, PassTimer};

/// A write-only pass into `targets` render targets: the floor of any pass writing them.
#[derive(Debug)]
pub struct WriteFloor {
    program: Program,
    pass: FullscreenPass,
}

impl WriteFloor {
    /// Builds the floor pass for framebuffers of `targets` attachments.
    pub fn new(ctx: &Context, targets: usize) -> Result<Self> {
        Self::with_defines(ctx, vec![("TARGETS".into(), targets.to_string())])
    }

    fn with_defines(ctx: &Context, defines: Defines) -> Result<Self> {
        Ok(WriteFloor {
            program: Program::new(ctx, FULLSCREEN_VERTEX, "common/write_floor.frag", &defines)?,
            pass: FullscreenPass::new(ctx)?,
        })
    }

    /// The floor pass for `fb`: its number of attachments, float or integer.
    pub fn for_target(ctx: &Context, fb: &Framebuffer) -> Result<Self> {
        let mut defines: Defines = vec![("TARGETS".into(), fb.attachments().to_string())];
        if fb.integer() {
            defines.push(("UINT".into(), "1".into()));
        }
        Self::with_defines(ctx, defines)
    }

    /// Writes a constant into every texel of every attachment of `fb`.
    pub fn draw(&self, fb: &Framebuffer) {
        let value = [("u_value", Uniform::Vec4(Vec4::new(0.25, 0.5, 0.75, 1.0)))];
        self.pass.draw(&self.program, &[], &value, fb);
    }

    /// Writes rows `y0..y0+rows` only: the floor of a pass restricted to the live rows.
    pub fn draw_rows(&self, fb: &Framebuffer, y0: u32, rows: u32) {
        let value = [("u_value", Uniform::Vec4(Vec4::new(0.25, 0.5, 0.75, 1.0)))];
        self.pass
            .draw_rows(&self.program, &[], &value, fb, y0, rows);
    }
}

/// The fixed cost of a pass: many passes over 1×1 targets, each reading what the one before
/// wrote (a ping-pong, as the papers' passes depend on each other), timed together and divided
/// by their count. What a pass costs however little it writes (state changes, the draw, the wait
/// for the pass before); below about 256² it dominates on a GPU.
#[derive(Debug)]
pub struct FixedCost {
    program: Program,
    pass: FullscreenPass,
    targets: [Framebuffer; 2],
    /// A texel that no probe draws into, read by the concurrent draws.
    source: crate::gl::Texture,
}

impl FixedCost {
    /// Passes timed together per measurement.
    pub const PASSES: usize = 200;

    /// Builds the two 1×1 RGBA32F targets and the pass (one texel fetch, one write).
    pub fn new(ctx: &Context) -> Result<Self> {
        let texel = || {
            crate::gl::Texture::new(
                ctx,
                crate::gl::TextureDesc {
                    width: 1,
                    height: 1,
                    format: crate::gl::TextureFormat::Rgba32F,
                    label: "fixed cost",
                },
            )
        };
        let target = |k: usize| -> Result<Framebuffer> {
            Framebuffer::new(ctx, &format!("fixed cost {k}"), vec![texel()?])
        };
        let d: Defines = vec![("FETCHES".into(), "1".into())];
        Ok(FixedCost {
            program: Program::new(ctx, FULLSCREEN_VERTEX, "bench/fetch_probe.frag", &d)?,
            pass: FullscreenPass::new(ctx)?,
            targets: [target(0)?, target(1)?],
            source: texel()?,
        })
    }

    /// Milliseconds of one pass, from [`FixedCost::PASSES`] dependent passes timed together.
    pub fn measure(&self, timer: &PassTimer) -> Result<f64> {
        let p = &self.program;
        let t = timer.time(|| {
            for i in 0..Self::PASSES {
                let (from, to) = (&self.targets[i % 2], &self.targets[1 - i % 2]);
                let source = [("u_source", from.only_texture().into())];
                self.pass
                    .draw(p, &source, &[("u_log_w", Uniform::I32(0))], to);
            }
        })?;
        Ok(t / Self::PASSES as f64)
    }

    /// Milliseconds of one follow-on draw: [`FixedCost::PASSES`] draws of the same pass into
    /// one target, each reading the other (which none writes), timed together.
    pub fn measure_follow_ons(&self, timer: &PassTimer) -> Result<f64> {
        let p = &self.program;
        let source = [("u_source", self.targets[1].only_texture().into())];
        let t = timer.time(|| {
            for _ in 0..Self::PASSES {
                self.pass.draw(
                    p,
                    &source,
                    &[("u_log_w", Uniform::I32(0))],
                    &self.targets[0],
                );
            }
        })?;
        Ok(t / Self::PASSES as f64)
    }

    /// Milliseconds of one concurrent draw (see [`DrawStats::concurrent`]) after a pass: a
    /// pass into one target then a draw into the other, both reading a texel that neither
    /// writes, timed together, less the pass timed alone.
    ///
    /// A short sequence, as the phases that have such draws are (the births' draws into the
    /// static and the state textures): on an NVIDIA H100, 200 such draws in turn cost what 200
    /// chained passes do (7 µs each), where the births' two draws took 7-8 µs together and the
    /// second draw here costs 0.6-1.1 µs.
    ///
    /// [`DrawStats::concurrent`]: crate::gl::DrawStats::concurrent
    pub fn measure_concurrent(&self, timer: &PassTimer) -> Result<f64> {
        let p = &self.program;
        let source = [("u_source", (&self.source).into())];
        let log_w = [("u_log_w", Uniform::I32(0))];
        let draw = |to: &Framebuffer| self.pass.draw(p, &source, &log_w, to);
        let one = timer.time(|| draw(&self.targets[0]))?;
        let two = timer.time(|| {
            draw(&self.targets[0]);
            draw(&self.targets[1]);
        })?;
        Ok((two - one).max(0.0))
    }
}

/// The floor of a render pass (used by `bench step`): the clear, then as many points as the pass
/// draws through the same target and blend state, from a vertex shader that fetches no texture
/// (`glsl/bench/render_floor.vert`), at the smallest point size (1 pixel), writing a constant.
/// No point-drawing pass with that blend state into that target can be cheaper; the ratio of the
/// render pass to it is what the texel fetches, the point sizes and the shading cost.
#[derive(Debug)]
pub struct RenderFloor {
    ctx: Context,
    program: Program,
    vao: VertexArray,
}

impl RenderFloor {
    /// Builds the floor's program.
    pub fn new(ctx: &Context) -> Result<Self> {
        let defines: Defines = vec![("TARGETS".into(), "1".into())];
        Ok(RenderFloor {
            ctx: ctx.clone(),
            program: Program::new(
                ctx,
                "bench/render_floor.vert",
                "common/write_floor.frag",
                &defines,
            )?,
            vao: VertexArray::empty(ctx, "render floor")?,
        })
    }

    /// Clears `target` to `clear`, then draws `points` one-pixel points with `blend`.
    pub fn draw(&self, target: &Framebuffer, clear: [f32; 4], blend: Option<Blend>, points: usize) {
        target.clear(clear);
        self.points(target, blend, points);
    }

    /// Draws `points` one-pixel points with `blend` into `target`, not cleared: the floor of a
    /// point draw of as many single pixels (the allocator's births, `glsl/sim/emit.vert`). No
    /// draw for none.
    pub fn points(&self, target: &Framebuffer, blend: Option<Blend>, points: usize) {
        self.points_from(&self.vao, target, blend, points, [0, 0]);
    }

    /// Clears `target` to `clear`, then draws `points` one-pixel points with `blend` in the
    /// target's raster order (point k at pixel k, wrapping), not scattered.
    pub fn draw_in_raster_order(
        &self,
        target: &Framebuffer,
        clear: [f32; 4],
        blend: Option<Blend>,
        points: usize,
    ) {
        target.clear(clear);
        let raster = [target.width() as i32, target.height() as i32];
        self.points_from(&self.vao, target, blend, points, raster);
    }

    /// A draw of `points` one-pixel points into each of `targets` in turn, not blended, from a
    /// vertex buffer of `bytes` bytes made and filled first, as the allocator's births make
    /// theirs (the vertex stage reads none of it): the floor of the births' emit draws. Nothing
    /// for no points.
    pub fn uploaded_points(
        &self,
        targets: &[&Framebuffer],
        points: usize,
        bytes: usize,
    ) -> Result<()> {
        if points == 0 || targets.is_empty() {
            return Ok(());
        }
        let data = vec![0u8; bytes.max(4)];
        let buffer = Buffer::with_data(
            &self.ctx,
            "births floor",
            BufferKind::Vertex,
            &data,
            BufferUsage::StreamDraw,
        )?;
        let attribute = Attribute {
            buffer: &buffer,
            location: 0,
            components: 1,
            stride: 4,
            offset: 0,
        };
        let vao = VertexArray::with_attributes(&self.ctx, "births floor", &[attribute])?;
        for target in targets {
            self.points_from(&vao, target, None, points, [0, 0]);
        }
        Ok(())
    }

    /// `raster`: the frame's width and height for points in raster order, `[0, 0]` scattered.
    fn points_from(
        &self,
        vao: &VertexArray,
        target: &Framebuffer,
        blend: Option<Blend>,
        points: usize,
        raster: [i32; 2],
    ) {
        if points == 0 {
            return;
        }
        let p = &self.program;
        let uniforms = [
            ("u_seed", Uniform::U32(0x9e37_79b9)),
            ("u_value", Uniform::Vec4(Vec4::new(0.02, 0.01, 0.005, 0.1))),
            ("u_raster_width", Uniform::I32(raster[0])),
            ("u_raster_height", Uniform::I32(raster[1])),
        ];
        self.ctx.draw(&Draw {
            program: p,
            target,
            viewport: None,
            vertices: vao,
            primitive: Primitive::Points,
            count: points as u32,
            state: &DrawState {
                blend,
                ..DrawState::REPLACE
            },
            textures: &[],
            uniforms: &uniforms,
        });
    }
}

/// The render floor drawn where the particles are (see `glsl/bench/render_floor_at.vert`): a
/// snapshot of their positions in a vertex buffer, drawn with the pass's camera, point size and
/// blend, fetching no texture and shading with a constant.
///
/// Its program and buffer are made once and the buffer refilled for each snapshot
/// ([`place`](Self::place)): a program made anew for every repetition had its first draws timed,
/// and llvmpipe builds a program's code for a draw state at its first draw (the floor then took
/// 0.1-0.3 ms more than the render it bounded at 32² and 64²).
#[derive(Debug)]
pub struct PlacedRenderFloor {
    ctx: Context,
    program: Program,
    buffer: Buffer,
    vao: VertexArray,
    count: std::cell::Cell<usize>,
}

impl PlacedRenderFloor {
    /// A floor for up to `particles` positions (xyzw each, w the remaining life), holding none
    /// until [`place`](Self::place).
    pub fn new(ctx: &Context, particles: usize) -> Result<Self> {
        let defines: Defines = vec![("TARGETS".into(), "1".into())];
        let program = Program::new(
            ctx,
            "bench/render_floor_at.vert",
            "common/write_floor.frag",
            &defines,
        )?;
        let buffer = Buffer::with_size(
            ctx,
            "render floor positions",
            BufferKind::Vertex,
            16 * particles.max(1),
            // As drawn many times: a driver may keep a stream buffer in host memory, where
            // the points would fetch slower than the pass's texels.
            BufferUsage::StaticDraw,
        )?;
        let vao = VertexArray::with_attributes(
            ctx,
            "render floor positions",
            &[Attribute {
                buffer: &buffer,
                location: 0,
                components: 4,
                stride: 16,
                offset: 0,
            }],
        )?;
        Ok(PlacedRenderFloor {
            ctx: ctx.clone(),
            program,
            buffer,
            vao,
            count: std::cell::Cell::new(0),
        })
    }

    /// Holds `positions` (xyzw per particle, at most the particles it was made for) from now on.
    pub fn place(&self, positions: &[f32]) -> Result<()> {
        self.buffer.replace(bytemuck::cast_slice(positions))?;
        self.count.set(positions.len() / 4);
        Ok(())
    }

    /// Clears `target`, then draws the first `count` particles (at most all) as points of
    /// `point_size` with `blend`: as many vertices as the render pass draws, no more. With
    /// `color_writes` off the points are rasterized and write nothing: a vertex floor.
    pub fn draw(
        &self,
        target: &Framebuffer,
        (clear, blend, color_writes): ([f32; 4], Option<Blend>, bool),
        (view_proj, point_size): (&glam::Mat4, f32),
        count: usize,
    ) {
        target.clear(clear);
        let p = &self.program;
        let value = Vec4::new(0.02, 0.01, 0.005, 0.1);
        self.ctx.draw(&Draw {
            program: p,
            target,
            viewport: None,
            vertices: &self.vao,
            primitive: Primitive::Points,
            count: self.count.get().min(count) as u32,
            state: &DrawState {
                blend,
                point_size: PointSize::Program,
                depth: crate::gl::Depth::Off,
                color_writes,
            },
            textures: &[],
            // The camera and size of the pass it floors: they travel with the draw.
            uniforms: &[
                ("u_view_proj", Uniform::Mat4(*view_proj)),
                ("u_point_size", Uniform::F32(point_size)),
                ("u_value", Uniform::Vec4(value)),
            ],
        });
    }
}

/// The device a benchmark ran on, for its JSON: the EGL device, the GL
/// renderer and driver version, and the clocks where they can be read.
#[derive(Debug, Clone, serde::Serialize)]
pub struct DeviceRecord {
    /// EGL device index.
    pub index: usize,
    /// `GL_RENDERER`.
    pub renderer: String,
    /// `GL_VENDOR`.
    pub vendor: String,
    /// `GL_VERSION` (names the driver: Mesa's version, NVIDIA's driver version).
    pub driver: String,
    /// `GL_SHADING_LANGUAGE_VERSION`.
    pub glsl_version: String,
    /// Whether it is a software rasterizer (llvmpipe): the CPU is its GPU.
    pub software: bool,
    /// Core and memory clocks, where GL exposes them; `"unknown"` otherwise (always, so far:
    /// neither llvmpipe nor NVIDIA's EGL report clocks through GL).
    pub clocks: String,
    /// CPU threads of the host (llvmpipe rasterizes on them).
    pub host_threads: usize,
}

impl DeviceRecord {
    /// The record of `ctx`'s device.
    pub fn of(ctx: &Context) -> Self {
        let l = ctx.limits();
        DeviceRecord {
            index: ctx.device_index(),
            renderer: l.renderer.clone(),
            vendor: l.vendor.clone(),
            driver: l.version.clone(),
            glsl_version: l.glsl_version.clone(),
            software: Clock::for_context(ctx) == Clock::Wall,
            clocks: "unknown".into(),
            host_threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
        }
    }
}

/// Wraps benchmark records in the object every command's JSON is:
/// `texflow_version`, `schema` (`texflow.<command>/<version>`), `device`, the clock and the
/// records under `records`.
pub fn json_envelope<T: serde::Serialize>(
    schema: &str,
    ctx: &Context,
    clock: Option<Clock>,
    records: &T,
) -> serde_json::Value {
    serde_json::json!({
        "texflow_version": env!("CARGO_PKG_VERSION"),
        "schema": schema,
        "device": DeviceRecord::of(ctx),
        "clock": clock,
        "records": records,
    })
}

/// How a benchmark cell's timed runs spread: count, min, median and max, in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Spread {
    /// Timed runs.
    pub count: usize,
    /// The fastest run.
    pub min: f64,
    /// The median run (what the tables print).
    pub median: f64,
    /// The slowest run.
    pub max: f64,
}

impl Spread {
    /// The spread of `v` (NaN fields for none).
    pub fn of(v: &[f64]) -> Self {
        let min = v.iter().copied().fold(f64::NAN, f64::min);
        let max = v.iter().copied().fold(f64::NAN, f64::max);
        Spread {
            count: v.len(),
            min,
            median: median(v),
            max,
        }
    }

    /// Whether the runs spread too far to trust the median at a glance: the slowest over 1.5×
    /// the fastest.
    pub fn unreliable(&self) -> bool {
        self.count > 1 && self.max > 1.5 * self.min
    }
}

/// The machine's one-minute load average (Linux `/proc/loadavg`), if it can be read: a busy
/// machine makes timings of a shared CPU (llvmpipe, the CPU baselines) unreliable.
pub fn load_average() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/loadavg").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// A phase's time over its floor below which the floor failed to bound the phase (noise aside).
pub const FLOOR_FAILED: f64 = 0.95;

/// A ratio to a floor as a table cell, with ⚠ where the floor did not bound the phase.
pub fn ratio_cell(ratio: f64) -> String {
    let flag = if ratio < FLOOR_FAILED { " ⚠" } else { "" };
    format!("{ratio:.2}{flag}")
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
