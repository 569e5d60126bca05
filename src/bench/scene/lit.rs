//! The bounds of a lit render (half-angle slicing, `render.lighting = "half_angle"`) and its
//! passes timed apart.
//!
//! The render's slices are a chain: each slice's eye pass reads the light buffer the slice before
//! it lit, and its light pass then overwrites what the eye pass read, so the passes wait on one
//! another whatever they draw. Beside the placed points, the render has two bounds drawn in the
//! same run:
//!
//! - the slices' chain: the same targets, blends and order, as many slices, each pass drawing
//!   one pixel that it leaves as it was, each eye pass fetching one texel of the light buffer
//!   (`glsl/bench/chain_floor.frag`): the dependencies and nothing else;
//! - the fill floor: the same slices' quads through the same vertex stage, targets and blends,
//!   with a constant fragment that changes no pixel (`glsl/bench/fill_floor.frag`), no atlas
//!   and no light buffer read.
//!
//! On a GPU clock a third, the shading floor: the slices' own passes, every fetch and
//! computation, each colour made one that leaves its target unchanged under the pass's blend
//! (`SHADE_FLOOR` in `glsl/render/halfangle_*.frag`), into a light buffer of its own.
//!
//! The light passes alone and the eye passes alone (on the light buffer the light passes left)
//! are each bounded by the same fill floor's passes of that kind, and the shading floor's.

use super::{counted, timed, Drawn, Phases};
use crate::bench::stats::PassTimer;
use crate::engine::Stages;
use crate::error::Result;
use crate::gl::{Context, Defines, Draw, Primitive, Program, SamplesQuery, Uniform, VertexArray};
use crate::render::{Camera, FrameState, FrameTarget, HalfAngleRenderer, SlicePasses};
use crate::sim::state::{POSITION, STATIC};

/// The slices' chain bound, as the phase table words it.
pub(super) const SLICE_CHAIN: &str = "the slices' chain: as many slices, each an eye pass into \
     the frame fetching one texel of the light buffer the light pass before it wrote, then a \
     light pass overwriting it, each pass one pixel left unchanged, the same blends";
/// The lit render's fill floor, as the phase table words it.
const LIT_FILL: &str = "fill floor: the slices' own quads through their own vertex stage, same \
     targets, blends and order, a constant fragment that leaves each target unchanged, no atlas \
     or light-buffer fetch";

/// The lit render's shading floor, as the phase table words it.
const LIT_SHADING: &str = "shading floor: the slices' own passes (every fetch and computation),      same targets, blends and order, each colour then made one that leaves its target      unchanged, a light buffer of its own";

/// What a lit scene's render and its passes are bounded by: the slices with the fill floor's
/// fragment stage, the chain's two programs (an eye pass that reads, a light pass that does
/// not), and on a GPU clock the slices' shading floor.
pub(super) struct LitFloors {
    fill: HalfAngleRenderer,
    shade: Option<HalfAngleRenderer>,
    eye: Program,
    light: Program,
    empty: VertexArray,
}

impl LitFloors {
    /// The floors of `lit`'s slices; the shading floor where `shading` (on a GPU clock: see
    /// `shading_floor` in the module).
    pub(super) fn new(ctx: &Context, lit: &HalfAngleRenderer, shading: bool) -> Result<Self> {
        let read: Defines = vec![("READ".into(), "1".into())];
        let (vert, frag) = ("bench/chain_floor.vert", "bench/chain_floor.frag");
        Ok(LitFloors {
            fill: lit.with_fragment("bench/fill_floor.frag")?,
            shade: shading.then(|| lit.shading_floor()).transpose()?,
            eye: Program::new(ctx, vert, frag, &read)?,
            light: Program::new(ctx, vert, frag, &Defines::new())?,
            empty: VertexArray::empty(ctx, "slices' chain floor")?,
        })
    }

    /// The slices' chain of `lit` for `count` particles: the light buffer and the frame cleared
    /// as the render clears them, then for every slice drawn an eye pass of one pixel reading
    /// the light buffer and a light pass of one pixel, each under its pass's blend.
    fn chain(
        &self,
        ctx: &Context,
        lit: &HalfAngleRenderer,
        (target, camera): (&FrameTarget, &Camera),
        count: usize,
    ) -> Result<()> {
        let draws = lit.slice_draws(camera);
        let buffer = lit.light_buffer();
        buffer.clear([1.0; 4]);
        target.clear_to(draws.eye_clear);
        let (eye_state, light_state) = draws.states();
        let zero = [("u_zero", Uniform::F32(0.0))];
        let pass = |program, fb, state, textures| {
            ctx.draw(&Draw {
                program,
                target: fb,
                viewport: None,
                vertices: &self.empty,
                primitive: Primitive::Points,
                count: 1,
                state,
                textures,
                uniforms: &zero,
            })
        };
        let light_texture = [("u_read", buffer.only_texture().into())];
        for _ in 0..lit.slices_drawn(count) {
            pass(&self.eye, target.framebuffer(), &eye_state, &light_texture);
            pass(&self.light, buffer, &light_state, &[]);
        }
        ctx.check_error("drawing the slices' chain floor")
    }
}

impl LitFloors {
    /// The fill floor's `passes` (no atlas) and, where drawn, the shading floor's (the
    /// render's atlas), each timed and counted, as the phase table's bounds.
    fn drawn(
        &self,
        ctx: &Context,
        (timer, samples): (&PassTimer, &SamplesQuery),
        engine: &dyn Stages,
        state: &FrameState<'_>,
        passes: SlicePasses,
    ) -> Result<Vec<(&'static str, f64, Option<Drawn>)>> {
        let (target, camera) = (engine.target(), engine.camera());
        let mut floors = vec![(LIT_FILL, &self.fill, None)];
        if let Some(shade) = &self.shade {
            floors.push((LIT_SHADING, shade, engine.renderer().atlas()));
        }
        floors
            .into_iter()
            .map(|(what, floor, atlas)| {
                let (t, d) = counted(ctx, samples, || {
                    timed(timer, || {
                        floor.draw_passes(target, state, camera, atlas, passes)
                    })
                })?;
                Ok((what, t, Some(d)))
            })
            .collect()
    }
}

/// The sorted state a lit render draws from: the gathered positions and statics, the engine's
/// clock, the simulation's drawn rows.
fn lit_state(engine: &dyn Stages) -> Option<FrameState<'_>> {
    let sorted = engine.sorted()?;
    Some(FrameState {
        positions: sorted.texture(POSITION),
        statics: sorted.texture(STATIC),
        motion: None,
        time: engine.sim().time() as f32,
        spins: None,
        count: engine.sim().drawn().count,
        user: &[],
    })
}

/// The lit render's bounds beside the placed points: the slices' chain and the fill floor,
/// each counted as the render is.
pub(super) fn render_bounds(
    ctx: &Context,
    (timer, samples): (&PassTimer, &SamplesQuery),
    floors: &LitFloors,
    engine: &dyn Stages,
) -> Result<Vec<(&'static str, f64, Option<Drawn>)>> {
    let (Some(lit), Some(state)) = (engine.lit(), lit_state(engine)) else {
        return Ok(Vec::new());
    };
    let (target, camera) = (engine.target(), engine.camera());
    let count = state.count;
    let chain = counted(ctx, samples, || {
        timed(timer, || floors.chain(ctx, lit, (target, camera), count))
    })?;
    let mut bounds = vec![(SLICE_CHAIN, chain.0, Some(chain.1))];
    bounds.extend(floors.drawn(ctx, (timer, samples), engine, &state, SlicePasses::Both)?);
    Ok(bounds)
}

/// Half-angle slicing's passes apart: every slice's light pass alone, then every slice's eye
/// pass alone (on the light buffer the light passes left), each next to the fill floor's passes
/// of that kind. (Not next to the live particles as points: on llvmpipe a million points cost
/// 0.22 s, the slices' culled quads of the dead far less, and the points took 1.9 times the
/// light passes they were to bound.)
pub(super) fn lit_phases(
    ctx: &Context,
    (timer, samples): (&PassTimer, &SamplesQuery),
    floors: Option<&LitFloors>,
    phases: &mut Phases,
    engine: &dyn Stages,
) -> Result<()> {
    let (Some(lit), Some(state), Some(floors)) = (engine.lit(), lit_state(engine), floors) else {
        return Ok(());
    };
    let (camera, target) = (engine.camera(), engine.target());
    let atlas = engine.renderer().atlas();
    for (passes, name) in [
        (
            SlicePasses::Light,
            format!("light-buffer passes ({} slices)", lit.slices()),
        ),
        (
            SlicePasses::Eye,
            format!(
                "eye passes ({} slices, lit by the light buffer)",
                lit.slices()
            ),
        ),
    ] {
        // Twice, the first round's times dropped: whichever of the three came first after the
        // render paid for the switch (on an NVIDIA H100, the light passes' fill floor 21-29 µs
        // timed first, 11.4 timed after the passes; the passes 13.1-13.4 timed last, 21.7-30.7
        // timed first).
        let round = || -> Result<_> {
            let bounds = floors.drawn(ctx, (timer, samples), engine, &state, passes)?;
            let (t, drawn) = counted(ctx, samples, || {
                timed(timer, || {
                    lit.draw_passes(target, &state, camera, atlas, passes)
                })
            })?;
            Ok((bounds, t, drawn))
        };
        round()?;
        let (bounds, t, drawn) = round()?;
        phases.push_bounds(&name, t, Some(drawn), &bounds);
    }
    Ok(())
}
