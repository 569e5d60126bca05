//! `texflow collide-stats` over runs: [`measure`] runs a scene, measures the last step's
//! detection ([`Snapshot`]) and times the collision passes; [`sweep`] varies one setting at a
//! time.

use crate::bench::{median, Clock, PassTimer};
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::scene::{self, SceneFile};
use crate::sim::ParticleSim;

use super::collide_iterations::{energy_momentum, iteration_stats};
use super::collide_stats::{CollisionStats, Snapshot};

/// Steps at the end of a [`measure`] run whose collision passes are timed (the median is
/// reported: one step alone is at the mercy of a noisy machine).
pub const TIMED_STEPS: u64 = 5;

/// Runs `scene` for `steps` steps and measures the last step's detection against the CPU
/// reference, with the median GPU time of the collision passes over the last [`TIMED_STEPS`]
/// steps (fewer if the run is shorter). `progress` is called after each step.
pub fn measure(
    ctx: &Context,
    scene: &SceneFile,
    steps: u64,
    seed: u32,
    mut progress: impl FnMut(),
) -> Result<CollisionStats> {
    if steps == 0 {
        return Err(Error::InvalidInput(
            "measuring needs at least 1 step".into(),
        ));
    }
    let mut sim = ParticleSim::new(ctx, scene, seed)?;
    if sim.collisions().is_none() {
        return Err(Error::InvalidInput(format!(
            "scene `{}` has no [collisions] section",
            scene.name
        )));
    }
    let timer = PassTimer::new(ctx, Clock::for_context(ctx))?;
    let (e0, p0) = energy_momentum(&sim)?;
    let timed = TIMED_STEPS.min(steps);
    for _ in timed..steps {
        sim.step()?;
        progress();
    }
    // Collision scenes emit by time stamps, so a step is the integration pass and the collision
    // stage: the same step, with the stage timed alone. The last step also reads back each
    // exact iteration (untimed, unless it is the only timed step).
    let mut times = Vec::new();
    for k in 0..timed {
        let last = k + 1 == timed;
        if let Some(c) = sim.collisions_mut() {
            c.record_iterations(last);
        }
        sim.run(crate::sim::Stage::Integrate)?;
        let mut result = Ok(());
        let t = timer.time(|| result = sim.run(crate::sim::Stage::Collide))?;
        if !last || timed == 1 {
            times.push(t);
        }
        result?;
        progress();
    }
    let stage = sim.collisions().expect("checked above");
    let mut stats = Snapshot::read(stage)?.stats();
    stats.gpu_ms = median(&times);
    stats.iterations = iteration_stats(stage);
    let (e1, p1) = energy_momentum(&sim)?;
    stats.kinetic_energy = [e0, e1];
    stats.momentum = [p0, p1];
    ctx.check_error("measuring collisions")?;
    Ok(stats)
}

/// One row of [`sweep`]: what was varied and what it gave.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SweepRow {
    /// What differs from the scene's own settings.
    pub variant: String,
    /// Neighbours per side.
    pub k: u32,
    /// Staggered lattice.
    pub staggered: bool,
    /// Rows-only sort sets (None: full sort).
    pub rows_only: Option<u32>,
    /// Lattice mesh size (m).
    pub cell: f32,
    /// The measurement.
    pub stats: CollisionStats,
}

/// The scene's detection measured with one setting changed at a time: k, the staggered lattice,
/// rows-only sorting, and the cell size (particles per cell).
pub fn sweep(
    ctx: &Context,
    scene: &SceneFile,
    steps: u64,
    seed: u32,
    mut progress: impl FnMut(&str),
) -> Result<Vec<SweepRow>> {
    let Some(base) = scene.collisions.clone() else {
        return Err(Error::InvalidInput(format!(
            "scene `{}` has no [collisions] section",
            scene.name
        )));
    };
    let g = base.cell();
    let mut variants: Vec<(String, scene::Collisions)> = vec![("scene".into(), base.clone())];
    for k in [1u32, 2, 4, 16] {
        if k != base.neighbours {
            variants.push((
                format!("k = {k}"),
                scene::Collisions {
                    neighbours: k,
                    ..base.clone()
                },
            ));
        }
    }
    variants.push((
        format!("staggered {}", if base.staggered { "off" } else { "on" }),
        scene::Collisions {
            staggered: !base.staggered,
            ..base.clone()
        },
    ));
    for rows in [1u32, 8] {
        variants.push((
            format!(
                "rows-only sort ({rows} row{})",
                if rows == 1 { "" } else { "s" }
            ),
            scene::Collisions {
                rows_only: Some(rows),
                ..base.clone()
            },
        ));
    }
    for f in [2.0f32, 4.0] {
        variants.push((
            format!("cell {f} x"),
            scene::Collisions {
                cell: Some(g * f),
                ..base.clone()
            },
        ));
    }
    let mut rows = Vec::new();
    for (name, c) in variants {
        progress(&name);
        let mut s = scene.clone();
        s.collisions = Some(c.clone());
        let stats = measure(ctx, &s, steps, seed, || {})?;
        rows.push(SweepRow {
            variant: name,
            k: c.neighbours,
            staggered: c.staggered,
            rows_only: c.rows_only,
            cell: c.cell(),
            stats,
        });
    }
    Ok(rows)
}

/// The sweep as a markdown table.
pub fn sweep_table(rows: &[SweepRow]) -> String {
    let mut out = String::from(
        "| variant | k | staggered | sort | cell (m) | particles/cell | true pairs | found | \
         missed | miss rate | adjacent cells | other row | far along row | closer kept | \
         tunnelled | conflicts | GPU ms |\n\
         | --- | ---: | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: \
         | ---: | ---: | ---: | ---: |\n",
    );
    for r in rows {
        let s = &r.stats;
        out.push_str(&format!(
            "| {} | {} | {} | {} | {:.3} | {:.2} | {} | {} | {} | {:.1}% | {} | {} | {} | {} | {} \
             | {} | {:.2} |\n",
            r.variant,
            r.k,
            if r.staggered { "on" } else { "off" },
            match r.rows_only {
                None => "full".to_owned(),
                Some(1) => "rows".to_owned(),
                Some(n) => format!("{n} rows"),
            },
            r.cell,
            s.particles_per_cell,
            s.pairs_true,
            s.found,
            s.missed,
            100.0 * s.missed as f64 / s.pairs_true.max(1) as f64,
            s.missed_adjacent_cells,
            s.missed_other_row,
            s.missed_far_along_row,
            s.missed_closer_partner,
            s.tunnelled,
            s.conflicts,
            s.gpu_ms
        ));
    }
    out
}
