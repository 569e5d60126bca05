//! The phases that need more than a timer: the engine's sort stage timed in its parts, the
//! floors of the passes that write the state.

use super::fetch::{recorded, FetchFloor, FETCH_FLOOR};
use super::floors::drawn;
use super::{scratch_like, timed, Phases};
use crate::bench::stats::{FixedCost, PassTimer, RenderFloor, WriteFloor};
use crate::engine::Stages;
use crate::error::Result;
use crate::gl::{Context, Framebuffer, Texture, TextureDesc, TextureFormat};
use crate::sim::{Simulation, Stage};
use crate::sort::KeyMode;

/// What the sort's phases are timed with and measured against: the timer, a write-only pass
/// into one target, one into the sort's own target where that is layers or integers (each made
/// once, before the repetitions: a program made and first drawn within a timed range charges
/// its build to the floor), and one into the gathered textures (the engine's, as many as the
/// renderer draws from; `None` with the index lookup, which gathers nothing).
pub(super) struct SortFloors<'a> {
    pub(super) timer: &'a PassTimer,
    pub(super) floor1: &'a WriteFloor,
    pub(super) layers: Option<&'a WriteFloor>,
    pub(super) gather: Option<&'a WriteFloor>,
    pub(super) fetch: &'a FetchFloor,
}

/// One frame's sorting, the engine's own sort stage run in its parts: keys, network, and the
/// gather unless the renderer draws through the sort's index. Whether the scene sorts.
pub(super) fn sort_phases(
    ctx: &Context,
    on: &SortFloors,
    phases: &mut Phases,
    e: &mut dyn Stages,
) -> Result<bool> {
    let Some(sorter) = e.sorter() else {
        return Ok(false);
    };
    // Each write floor drawn right before its phase into the phase's own target is drawn once
    // untimed first: the timed draw then follows a draw into its target, as the phase's draw
    // does (it follows the floor's), and a driver's cost of switching targets is charged to
    // neither (llvmpipe, 32² and 64²: the floors took 0.045-0.074 ms less, half of what they
    // took, and the keys pass 0.07-0.16 ms).
    on.floor1.draw(sorter.keys_target());
    let (f, fd) = drawn(ctx, || {
        on.timer.time(|| on.floor1.draw(sorter.keys_target()))
    })?;
    let mut mode = None;
    let ((t, td), shapes) = recorded(|| {
        drawn(ctx, || {
            timed(on.timer, || {
                mode = e.sort_keys()?;
                Ok(())
            })
        })
    })?;
    let fetch = on.fetch.measure(on.timer, &shapes)?;
    let keys = match mode {
        Some(KeyMode::Age { .. }) => "sort keys: age",
        Some(KeyMode::Axis { .. }) => "sort keys: along the half-angle vector",
        // The render sort keys by distance, age or the half-angle axis, never by cell.
        Some(KeyMode::GridCell { .. }) => unreachable!("a render sort keyed by cell"),
        Some(KeyMode::ViewerDistance { .. }) | None => "sort keys: distance to the viewer",
    };
    let floor = "write-only pass into the sort texture";
    let bounds = [(floor, f, Some(fd)), (FETCH_FLOOR, fetch.0, Some(fetch.1))];
    phases.push_bounds(keys, t, Some(td), &bounds);
    // Each pass's floor writes what it writes: the sort texture, or for the blocked
    // variant its layers (and the row-major texture once, in its unpack pass).
    let sorter = e.sorter().expect("a scene that sorted keys has a sorter");
    let target = sorter.target();
    let (fl, fld) = match on.layers {
        Some(f) => drawn(ctx, || on.timer.time(|| f.draw(target)))?,
        None => drawn(ctx, || on.timer.time(|| on.floor1.draw(target)))?,
    };
    let (fk, fkd) = drawn(ctx, || {
        on.timer.time(|| on.floor1.draw(sorter.keys_target()))
    })?;
    let (fp, fpd) = match sorter.partition_target() {
        Some(t) => drawn(ctx, || on.timer.time(|| on.floor1.draw(t)))?,
        None => (0.0, super::Drawn::default()),
    };
    let (network_passes, partition_passes, name) = (
        sorter.network_pass_count(),
        sorter.partition_pass_count(),
        format!("sort network ({})", sorter.variant().name()),
    );
    let mut passes = 0;
    let ((t, td), shapes) =
        recorded(|| drawn(ctx, || on.timer.time(|| passes = e.sort_network())))?;
    let fetch = on.fetch.measure(on.timer, &shapes)?;
    // Passes run this frame (all of a full sort, or a share of one spread over frames): the
    // network's first, then its partition passes, then the unpack.
    let network = network_passes.min(passes);
    let partition = partition_passes.min(passes - network);
    let unpack = passes - network - partition;
    let floor = "write-only pass into each pass's targets × passes run";
    let f = fl * network as f64 + fp * partition as f64 + fk * unpack as f64;
    let fd = fld
        .times(network as u64)
        .plus(fpd.times(partition as u64))
        .plus(fkd.times(unpack as u64));
    let bounds = [(floor, f, Some(fd)), (FETCH_FLOOR, fetch.0, Some(fetch.1))];
    phases.push_bounds(&name, t, Some(td), &bounds);
    gather_phase(ctx, on, phases, e)?;
    Ok(true)
}

/// The sort's gather of what the renderer draws, next to a write-only pass into the gathered
/// textures and its fetch floor; without a phase under the index lookup (nothing gathered).
fn gather_phase(
    ctx: &Context,
    on: &SortFloors,
    phases: &mut Phases,
    e: &mut dyn Stages,
) -> Result<()> {
    let floor = match (e.sorted(), on.gather) {
        (Some(sorted), Some(gather)) => Some((sorted.attachments(), {
            // Untimed first, as the keys' floor is (above).
            gather.draw(sorted);
            drawn(ctx, || on.timer.time(|| gather.draw(sorted)))?
        })),
        _ => None,
    };
    let Some((n, (f, fd))) = floor else {
        // Latta §3.4.4's index lookup: the render pass reads the sort texture itself.
        return e.sort_gather();
    };
    let ((t, td), shapes) = recorded(|| drawn(ctx, || timed(on.timer, || e.sort_gather())))?;
    let fetch = on.fetch.measure(on.timer, &shapes)?;
    let (name, floor) = match n {
        2 => (
            "gather position and static textures".to_owned(),
            "write-only pass into the two gathered textures".to_owned(),
        ),
        _ => (
            format!(
                "gather position, static and {} more texture(s) drawn",
                n - 2
            ),
            format!("write-only pass into the {n} gathered textures"),
        ),
    };
    let bounds = [
        (&*floor, f, Some(fd)),
        (FETCH_FLOOR, fetch.0, Some(fetch.1)),
    ];
    phases.push_bounds(&name, t, Some(td), &bounds);
    Ok(())
}

/// The floors of the passes that write the state: a write-only pass into a framebuffer of the
/// state's formats and size, and the fixed cost of a dependent pass.
pub(super) struct StateFloors {
    state: WriteFloor,
    fixed_cost: FixedCost,
    scratch: Framebuffer,
    scratch_bytes: u64,
    /// The births' floor: one-pixel points into `single`, one RGBA32F texture of the state's
    /// size (as the static texture), and into `scratch` (as the state).
    points: RenderFloor,
    single: Framebuffer,
    /// The second bound of every stage: its own draws' fetches.
    pub(super) fetch: FetchFloor,
}

impl StateFloors {
    pub(super) fn new(ctx: &Context, sim: &dyn Simulation) -> Result<Self> {
        let scratch = scratch_like(ctx, sim.state_target())?;
        let state = WriteFloor::new(ctx, sim.state_target().textures().len())?;
        let fixed_cost = FixedCost::new(ctx)?;
        let scratch_bytes =
            scratch.width() as u64 * scratch.height() as u64 * scratch.bytes_per_texel() as u64;
        let [w, h] = sim.size();
        let t = Texture::new(
            ctx,
            TextureDesc {
                width: w,
                height: h,
                format: TextureFormat::Rgba32F,
                label: "births floor",
            },
        )?;
        Ok(Self {
            state,
            fixed_cost,
            scratch,
            scratch_bytes,
            points: RenderFloor::new(ctx)?,
            single: Framebuffer::new(ctx, "births floor", vec![t])?,
            fetch: FetchFloor::new(ctx)?,
        })
    }

    /// One step, stage by stage, from the simulation's own pass list (what its step runs):
    /// the integration next to a write-only pass into the state's targets over the same rows;
    /// the births next to as many one-pixel points as they drew; every other stage
    /// (constraint relaxation, collisions) next to its passes' fixed cost plus its bytes
    /// written at the rate of a write-only pass into the state's targets, both measured now.
    pub(super) fn step_phases(
        &self,
        ctx: &Context,
        timer: &PassTimer,
        sim: &mut dyn Simulation,
        phases: &mut Phases,
    ) -> Result<()> {
        let passes = sim.passes();
        for stage in sim.stages() {
            // Each pass by the words before its details, once.
            let mut names: Vec<&str> = Vec::new();
            for p in passes.iter().filter(|p| p.stage == stage) {
                let short = short_name(&p.name);
                if !names.contains(&short) {
                    names.push(short);
                }
            }
            let name = format!("{}: {}", stage.label(), names.join(", "));
            if stage == Stage::Integrate {
                // The live rows the simulation draws (whole rows; all of them but under a
                // min-heap allocator).
                let rows = (sim.drawn().count / sim.size()[0].max(1) as usize) as u32;
                let (f, fd) = drawn(ctx, || {
                    timer.time(|| self.state.draw_rows(&self.scratch, 0, rows))
                })?;
                let (t, td, fetch) = self.run(ctx, timer, sim, stage)?;
                let floor = "write-only pass into the state's targets, live rows";
                let bounds = [(floor, f, Some(fd)), (FETCH_FLOOR, fetch.0, Some(fetch.1))];
                phases.push_bounds(&name, t, Some(td), &bounds);
                continue;
            }
            if stage == Stage::Births {
                self.births(ctx, timer, sim, phases, &name)?;
                continue;
            }
            let fixed = self.fixed_cost.measure(timer)?;
            let f = timer.time(|| self.state.draw(&self.scratch))?;
            let rate = self.scratch_bytes as f64 / (f - fixed).max(1e-9);
            let (t, td, fetch) = self.run(ctx, timer, sim, stage)?;
            let d = td.stats;
            // A stage that drew nothing this time still costs its call: one pass's fixed cost.
            // A bound computed from the stage's own draws: nothing drawn to compare.
            let floor = "its chained passes (at least one) × the fixed cost of a pass + its bytes \
                         at the state's write rate";
            // Draws that wait on none before them (follow-ons, concurrent) may cost next to
            // nothing: only the chain's passes are each a pass's fixed cost at least.
            let f = d.chained().max(1) as f64 * fixed + d.bytes_written as f64 / rate;
            let bounds = [(floor, f, None), (FETCH_FLOOR, fetch.0, Some(fetch.1))];
            phases.push_bounds(&name, t, Some(td), &bounds);
        }
        Ok(())
    }

    /// Runs `stage` timed, counting what it drew, then its fetch floor from its own draws.
    fn run(
        &self,
        ctx: &Context,
        timer: &PassTimer,
        sim: &mut dyn Simulation,
        stage: Stage,
    ) -> Result<(f64, super::Drawn, (f64, super::Drawn))> {
        let ((t, td), shapes) = recorded(|| drawn(ctx, || timed(timer, || sim.run(stage))))?;
        let fetch = self.fetch.measure(timer, &shapes)?;
        Ok((t, td, fetch))
    }

    /// The births (the allocator's emit pass: its vertices uploaded, then one-pixel points into
    /// each target it writes), then their floor: the same bytes uploaded, then as many one-pixel
    /// points in as many draws into targets of the same formats, nothing where nothing was born.
    fn births(
        &self,
        ctx: &Context,
        timer: &PassTimer,
        sim: &mut dyn Simulation,
        phases: &mut Phases,
        name: &str,
    ) -> Result<()> {
        let (t, td, fetch) = self.run(ctx, timer, sim, Stage::Births)?;
        let d = td.stats;
        let per_draw = d.points.checked_div(d.draws).unwrap_or(0) as usize;
        let bytes = per_draw * crate::sim::BIRTH_VERTEX_BYTES;
        // The emit pass draws into the static texture, the state, then (Verlet) the previous
        // positions: one RGBA32F texture, the state's targets, one again.
        let targets: Vec<&Framebuffer> = (0..d.draws)
            .map(|k| match k {
                1 => &self.scratch,
                _ => &self.single,
            })
            .collect();
        let mut made = Ok(());
        let (f, fd) = drawn(ctx, || {
            timer.time(|| made = (self.points).uploaded_points(&targets, per_draw, bytes))
        })?;
        made?;
        let floor = "the births' vertex bytes uploaded into a new buffer, then as many one-pixel \
                     points in as many draws as the emit pass, into targets of the same formats \
                     (one RGBA32F texture of the state's size, the state's, one again)";
        let bounds = [(floor, f, Some(fd)), (FETCH_FLOOR, fetch.0, Some(fetch.1))];
        phases.push_bounds(name, t, Some(td), &bounds);
        Ok(())
    }
}

/// A pass's name up to its details: before the first `:`, `,` or `[` outside parentheses
/// (`fire (thesis §3-4, Listings 1-2): physics ...` is `fire (thesis §3-4, Listings 1-2)`).
fn short_name(name: &str) -> &str {
    let mut depth = 0i32;
    for (i, c) in name.char_indices() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            ':' | ',' | '[' if depth <= 0 => return name[..i].trim(),
            _ => {}
        }
    }
    name.trim()
}

#[cfg(test)]
mod tests {
    use super::short_name;

    /// The phase table names a pass by the words before its details, and never cuts inside
    /// its parentheses.
    #[test]
    fn a_pass_is_named_by_the_words_before_its_details() {
        for (name, short) in [
            (
                "fire (thesis §3-4, Listings 1-2): physics, in-shader respawn [position]",
                "fire (thesis §3-4, Listings 1-2)",
            ),
            (
                "integrate (live rows only): Latta's Euler (eq. 3, 8)",
                "integrate (live rows only)",
            ),
            (
                "gather position, velocity, static in cell order",
                "gather position",
            ),
            ("spin (UberFlow §4.5)", "spin (UberFlow §4.5)"),
            (
                "render points (texture fetch, additive)",
                "render points (texture fetch, additive)",
            ),
        ] {
            assert_eq!(short_name(name), short);
        }
    }
}
