//! The bounds of `bench scene`'s phases that are drawn passes, and what they drew: the render
//! phase against the placed points and the fill floor, each counted (draws, points, bytes,
//! fragments) so that a test can check that a floor draws no more than its phase.

use super::{counted, timed, Phases};
use crate::bench::stats::{Clock, PassTimer, PlacedRenderFloor};
use crate::engine::Stages;
use crate::error::Result;
use crate::gl::{Context, DrawStats, SamplesQuery};
use crate::render::ParticleStyle;
use crate::scene::SceneFile;
use crate::scene::{DrawMode, DrawPrimitive};

/// One lower bound of a phase.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Bound {
    /// What it is.
    pub floor: String,
    /// Median milliseconds.
    pub ms: f64,
    /// What it drew in the last repetition; `None` for a bound computed from the phase's own
    /// draws (the collision and relaxation stages).
    pub drawn: Option<Drawn>,
}

/// What a phase or a floor drew, as the GL layer counted it, and the fragments written where a
/// samples query counted them (render phases). A floor bounds its phase by construction only if
/// it draws no more: no more draws, points, bytes and fragments (`tests/bench_floors.rs`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Drawn {
    /// Draws, full-screen bytes and points.
    pub stats: DrawStats,
    /// Fragments written (`GL_SAMPLES_PASSED`), where counted.
    pub fragments: Option<u64>,
    /// Of a fetch floor's draws, those that walked the cells around every live particle as
    /// the phase's draw did (a neighbour search).
    pub walked: u64,
}

impl Drawn {
    /// `stats` without a fragment count.
    pub(super) fn of(stats: DrawStats) -> Self {
        Drawn {
            stats,
            fragments: None,
            walked: 0,
        }
    }

    /// `k` runs of what this drew (a floor of one pass, charged once per pass run).
    pub(super) fn times(self, k: u64) -> Self {
        Drawn {
            stats: self.stats.times(k),
            fragments: self.fragments.map(|f| f * k),
            walked: self.walked * k,
        }
    }

    /// What this and `other` drew together.
    pub(super) fn plus(self, other: Drawn) -> Self {
        Drawn {
            stats: self.stats.plus(other.stats),
            fragments: self.fragments.zip(other.fragments).map(|(x, y)| x + y),
            walked: self.walked + other.walked,
        }
    }
}

/// What the render phase is timed with and bounded by: the timer, a samples query (fragments
/// written), and the fill floor (the renderer's own vertex stage, a constant fragment), where
/// the renderer has one; a lit render's (half-angle slices) floors.
pub(super) struct RenderFloors<'a> {
    pub(super) timer: &'a PassTimer,
    pub(super) samples: SamplesQuery,
    /// The placed points, refilled each repetition with its positions.
    pub(super) placed: PlacedRenderFloor,
    pub(super) fill: Option<crate::render::ParticleRenderer>,
    /// The shading floor: the renderer's own stages, its colours made ones that change no
    /// pixel (points and sprites, not lit).
    pub(super) shade: Option<crate::render::ParticleRenderer>,
    pub(super) lit: Option<super::lit::LitFloors>,
}

impl<'a> RenderFloors<'a> {
    /// The render's floors for `e`, built once before the repetitions (a program built within
    /// them would be timed at its first draw).
    pub(super) fn new(ctx: &Context, timer: &'a PassTimer, e: &dyn Stages) -> Result<Self> {
        let p = &e.sim().drawn().positions;
        Ok(RenderFloors {
            timer,
            samples: SamplesQuery::new(ctx)?,
            placed: PlacedRenderFloor::new(ctx, (p.width() * p.height()) as usize)?,
            // Not for a lit scene: its render is the half-angle slices (their own vertex stage
            // and floors), not the plain renderer's points.
            fill: match e.lit() {
                Some(_) => None,
                None => Some(e.renderer().with_fragment("bench/fill_floor.frag")?),
            },
            shade: shading_floor(e, timer.clock())?,
            lit: (e.lit())
                .map(|l| super::lit::LitFloors::new(ctx, l, timer.clock() == Clock::Gpu))
                .transpose()?,
        })
    }
}

/// The shading floor of `e`'s render (points and sprites; a lit render's is the slices', in
/// `lit`), on a GPU clock only: a GPU blends in fixed-function units after the fragment stage,
/// which the floor leaves with nothing to change; llvmpipe compiles the blend into the fragment
/// code, so there the floor is the pass itself, and it measured 1.0-1.24 times the pass (2
/// cores, every built-in at 64² and 128²).
fn shading_floor(e: &dyn Stages, clock: Clock) -> Result<Option<crate::render::ParticleRenderer>> {
    match (e.lit(), clock) {
        (None, Clock::Gpu) => e.renderer().shading_floor(),
        _ => Ok(None),
    }
}

/// The shading floor, as the phase table words it.
const SHADING_FLOOR: &str = "shading floor: the pass itself, its vertex and fragment stages \
     (every fetch and computation) and colliders' geometry, same blend and depth, each colour \
     then made one that leaves the frame unchanged (the blends its colours make left out)";

/// The placed points' bound where they write: the pass's own points of one size.
const PLACED_WRITING: &str = "clear + the live particles as points where they are, as many as \
     the pass draws, at its point size, same blend, no fetch (a surface or strands: the clear \
     alone)";
/// The placed points' bound where they write nothing.
const PLACED_SILENT: &str = "clear + the live particles as points where they are, as many as \
     the pass draws, at its point size (round points, or depth-tested against geometry) or one \
     pixel (sprites, quads), writing nothing (the vertex stage and rasterization alone; a \
     surface or strands: the clear alone)";

/// The placed points' size and whether they write, for a render of `style` at `point_size`.
fn placed_points(style: &ParticleStyle, point_size: f32) -> (f32, bool) {
    // At the pass's point size where every particle is drawn at it (points of one size);
    // else one pixel, which any sprite or quad of at least a pixel covers at its centre
    // (sprites' sizes vary with the type, the age and size_range, down below point_size).
    let uniform = style.mode == DrawMode::Points
        && style.primitive == DrawPrimitive::Points
        && style.types.iter().all(|t| t.size_range == [1.0; 2]);
    // The floor writes only where it covers what the pass writes: square points of one size.
    // Round points (the soft fire) leave their corners as they were, one-pixel points stand in
    // for larger sprites whose blends spread over their area; a floor writing there costs what
    // the pass does not (NVIDIA, the fire at 4096²: 168 ms against its render's 142 ms), so
    // those points write nothing, their vertex stage and rasterization a lower bound of any
    // pass that draws them.
    let round = style.fire.is_some_and(|f| f.soft);
    // A pass that depth-tests its particles against the colliders' geometry writes none of
    // those behind it; the placed points, drawn without the geometry, blended every one
    // (`collide` on the H100 at 256²: the points bound 1.56 times its render). They write
    // nothing there: the fill floor, which draws the geometry, is the bound that writes.
    let writes = uniform && !round && !style.depth_test;
    (if uniform { point_size } else { 1.0 }, writes)
}

/// The render pass against two bounds: the particles as points where they are (as many
/// vertices as the pass draws, its point size and blend, no fetch), and the fill floor (the
/// same points or sprites through the pass's own vertex stage, its blend, a constant fragment
/// that changes no pixel).
pub(super) fn render_phase(
    ctx: &Context,
    on: &RenderFloors,
    phases: &mut Phases,
    engine: &dyn Stages,
    s: &SceneFile,
    sorted: bool,
) -> Result<()> {
    let (timer, samples) = (on.timer, &on.samples);
    let (style, params) = (engine.renderer().style(), engine.renderer().params());
    let (blend, clear) = engine.frame_blend();
    let blend = Some(blend);
    let fb = engine.target().framebuffer();
    // A snapshot of this repetition's positions, drawn without fetching or shading.
    let placed = &on.placed;
    placed.place(&engine.sim().drawn().positions.read_f32()?)?;
    let [rw, rh] = s.render.resolution;
    let view_proj = engine.camera().view_projection(rw as f32 / rh as f32);
    let (size, writes) = placed_points(style, params.point_size);
    let camera = (&view_proj, size);
    // The live rows' particles (the simulation's drawn count): every live particle is among
    // them, sorted or not (the snapshot is of the simulation's own order), and no pass draws
    // fewer vertices with a live one left out. (Every texel, when sorted, was more than a
    // renderer that draws the live count only, as the half-angle slices do: 4M culled points
    // costing 5 times the pass they bounded.)
    // A connected render (a surface, strands) draws no point per particle: the points would
    // not bound its lines or triangles (hidden behind one another, overlapping), so its floor
    // is the clear alone.
    let count = if engine.renderer().draws_connected() {
        0
    } else {
        engine.sim().drawn().count
    };
    // Drawn once untimed first, as it is timed: the snapshot is new each repetition, and a
    // first draw may pay its upload (on the H200 at 256² these points took 11-30 µs more than
    // the render they bound, writing or not).
    placed.draw(fb, (clear, blend, writes), camera, count);
    let points = counted(ctx, samples, || {
        timer.time(|| placed.draw(fb, (clear, blend, writes), camera, count))
    })?;
    let text = if writes {
        PLACED_WRITING
    } else {
        PLACED_SILENT
    };
    let mut bounds = vec![(text, points.0, Some(points.1))];
    if let Some(fill) = &on.fill {
        let f = counted(ctx, samples, || {
            timed(timer, || engine.render_pass_with(fill, sorted))
        })?;
        bounds.push((
            "fill floor: the pass's own vertex stage (the same points, sprites, surface or \
             strands) and colliders' geometry, same blend and depth, a constant fragment (that \
             leaves the frame unchanged where it blends), no atlas fetch, no shading",
            f.0,
            Some(f.1),
        ));
    }
    if let Some(shade) = &on.shade {
        let f = counted(ctx, samples, || {
            timed(timer, || engine.render_pass_with(shade, sorted))
        })?;
        bounds.push((SHADING_FLOOR, f.0, Some(f.1)));
    }
    if let Some(lit) = &on.lit {
        bounds.extend(super::lit::render_bounds(
            ctx,
            (timer, samples),
            lit,
            engine,
        )?);
    }
    let (t, drawn) = counted(ctx, samples, || timed(timer, || engine.render_pass(sorted)))?;
    let name = format!("render ({})", engine.renderer().pass_names().join(", "));
    phases.push_bounds(&name, t, Some(drawn), &bounds);
    Ok(())
}

/// Runs `f` (a timed range) counting what it drew, as the GL layer counts draws.
pub(super) fn drawn(ctx: &Context, f: impl FnOnce() -> Result<f64>) -> Result<(f64, Drawn)> {
    ctx.take_draw_stats();
    let t = f()?;
    Ok((t, Drawn::of(ctx.take_draw_stats())))
}
