//! The particle pipeline's phases that need more than a timer: the sort built as the engine
//! builds it and timed in its passes, and the floors of the passes that write the state.

use super::{scratch_like, timed, Phases};
use crate::bench::stats::{FixedCost, PassTimer, WriteFloor};
use crate::error::Result;
use crate::gl::{Context, Framebuffer};
use crate::scene::SceneFile;
use crate::sim::state::{POSITION, STATIC};
use crate::sim::{ParticleSim, Simulation, Stage};
use crate::sort::{KeyMode, Sorter};

/// The sort the engine runs, built from the same plan, with its own gather target: the sorter,
/// the gathered position and static textures, whether it is spread over frames, and whether
/// keys were written yet.
pub(super) type BenchSort = (Sorter, Framebuffer, bool, bool);

pub(super) fn bench_sort(ctx: &Context, s: &SceneFile) -> Result<Option<BenchSort>> {
    let Some((sorter, p)) = crate::engine::sorter_for(ctx, s)? else {
        return Ok(None);
    };
    let sorted = crate::engine::gather_target(ctx, s, "bench sorted", &[POSITION, STATIC])?;
    Ok(Some((sorter, sorted, p.passes_per_frame.is_some(), false)))
}

/// What the sort's phases are timed with and measured against.
pub(super) struct SortFloors<'a> {
    pub(super) timer: &'a PassTimer,
    pub(super) floor1: &'a WriteFloor,
    pub(super) floor2: &'a WriteFloor,
}

/// One frame's sorting in its phases: keys, network, and the gather unless the renderer draws
/// through the sort's index (`gather` false).
pub(super) fn sort_phases(
    ctx: &Context,
    on: &SortFloors,
    phases: &mut Phases,
    (sorter, sorted, spread, keyed): &mut BenchSort,
    sim: &ParticleSim,
    mode: &KeyMode,
    gather: bool,
) -> Result<()> {
    let [w, h] = sim.size().to_array();
    let texels = w as usize * h as usize;
    let f = on.timer.time(|| on.floor1.draw(sorter.keys_target()))?;
    let t = timed(on.timer, || {
        let refresh = *spread && *keyed;
        sorter.write_keys_with_statics(sim.positions(), sim.statics(), texels, mode, true, refresh)
    })?;
    *keyed = true;
    phases.push(
        match mode {
            KeyMode::Age { .. } => "sort keys: age",
            _ => "sort keys: distance to the viewer",
        },
        "write-only pass into the sort texture",
        t,
        f,
    );
    // Each pass's floor writes what it writes: the sort texture, or for the blocked
    // variant its layers (and the row-major texture once, in its unpack pass).
    let target = sorter.target();
    let fl = if target.attachments() > 1 || target.integer() {
        let f = WriteFloor::for_target(ctx, target)?;
        on.timer.time(|| f.draw(target))?
    } else {
        on.timer.time(|| on.floor1.draw(target))?
    };
    let fk = on.timer.time(|| on.floor1.draw(sorter.keys_target()))?;
    let mut passes = 0;
    let t = on.timer.time(|| passes = sorter.sort_frame())?;
    let unpack = passes.saturating_sub(sorter.network_pass_count().min(passes));
    phases.push(
        &format!("sort network ({})", sorter.variant().name()),
        "write-only pass into each pass's targets × passes run",
        t,
        fl * (passes - unpack) as f64 + fk * unpack as f64,
    );
    if !gather {
        // Latta §3.4.4's index lookup: the render pass reads the sort texture itself.
        return Ok(());
    }
    let f = on.timer.time(|| on.floor2.draw(sorted))?;
    let t = timed(on.timer, || {
        sorter.gather(&[sim.positions(), sim.statics()], sorted)
    })?;
    phases.push(
        "gather position and static textures",
        "write-only pass into the two gathered textures",
        t,
        f,
    );
    Ok(())
}

/// The floors of the passes that write the state: a write-only pass into a framebuffer of the
/// state's formats and size, and the fixed cost of a dependent pass.
pub(super) struct StateFloors {
    state: WriteFloor,
    fixed_cost: FixedCost,
    scratch: Framebuffer,
    scratch_bytes: u64,
}

impl StateFloors {
    pub(super) fn new(ctx: &Context, sim: &ParticleSim) -> Result<Self> {
        let scratch = scratch_like(ctx, sim.front())?;
        let state = WriteFloor::new(ctx, sim.front().textures().len())?;
        let fixed_cost = FixedCost::new(ctx)?;
        let scratch_bytes =
            scratch.width() as u64 * scratch.height() as u64 * scratch.bytes_per_texel() as u64;
        Ok(Self {
            state,
            fixed_cost,
            scratch,
            scratch_bytes,
        })
    }

    /// One step, stage by stage, from the simulation's own pass list (what its step runs):
    /// the integration next to a write-only pass into the state's targets over the same rows;
    /// every other stage (births, constraint relaxation, collisions) next to its passes' fixed
    /// cost plus its bytes written at the rate of a write-only pass into the state's targets,
    /// both measured now.
    pub(super) fn step_phases(
        &self,
        ctx: &Context,
        timer: &PassTimer,
        sim: &mut ParticleSim,
        phases: &mut Phases,
    ) -> Result<()> {
        let passes = sim.passes();
        for stage in sim.stages() {
            // Each pass by the words before its details, once.
            let mut names: Vec<&str> = Vec::new();
            for p in passes.iter().filter(|p| p.stage == stage) {
                let short = p
                    .name
                    .split([':', ',', '['])
                    .next()
                    .unwrap_or(&p.name)
                    .trim();
                if !names.contains(&short) {
                    names.push(short);
                }
            }
            let name = format!("{}: {}", stage_name(stage), names.join(", "));
            if stage == Stage::Integrate {
                let rows = sim.active_rows();
                let f = timer.time(|| self.state.draw_rows(&self.scratch, 0, rows))?;
                let t = timed(timer, || sim.run(stage))?;
                phases.push(
                    &name,
                    "write-only pass into the state's targets, live rows",
                    t,
                    f,
                );
                continue;
            }
            let fixed = self.fixed_cost.measure(timer)?;
            let f = timer.time(|| self.state.draw(&self.scratch))?;
            let rate = self.scratch_bytes as f64 / (f - fixed).max(1e-9);
            ctx.take_draw_stats();
            let t = timed(timer, || sim.run(stage))?;
            let drawn = ctx.take_draw_stats();
            // A stage that drew nothing this time (no births in the step) still costs its
            // call: one pass's fixed cost.
            phases.push(
                &name,
                "its passes (at least one) × the fixed cost of a pass + its bytes at the state's \
                 write rate",
                t,
                drawn.draws.max(1) as f64 * fixed + drawn.bytes_written as f64 / rate,
            );
        }
        Ok(())
    }
}

/// A stage's name in the phase table.
fn stage_name(stage: Stage) -> &'static str {
    match stage {
        Stage::Births => "births",
        Stage::Integrate => "integrate",
        Stage::Relax => "relax",
        Stage::Collide => "collide",
    }
}
