//! How deep the `collide` pile settles against the work spent: the mean overlap depth of the
//! pile after a run, with UberFlow's detection and with the exact one at 1, 2 and 4 iterations,
//! beside the GPU time of a step's collision passes. A small pile poured faster (the whole
//! texture in one cycle of a few seconds), so that llvmpipe runs it in the report's time;
//! docs/collisions.md has the 64x64 figures of the scene as it is.

use std::path::{Path, PathBuf};

use crate::bench::Clock;
use crate::error::Result;
use crate::gl::Context;
use crate::scene::{self, SceneFile};

use super::collide_runs::measure;
use super::{Progress, Size};

/// One configuration's pile.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PileRow {
    /// Detection (`uberflow` or `exact`).
    pub detection: String,
    /// Exact iterations per step (1 for UberFlow's, which has none).
    pub iterations: u32,
    /// Mean overlap depth of the overlapping pairs, percent of the diameter.
    pub mean_depth_percent: f64,
    /// Overlapping neighbours per particle.
    pub overlaps_per_particle: f64,
    /// Live particles at the end.
    pub particles: usize,
    /// Median GPU time of a step's collision passes (ms).
    pub gpu_ms: f64,
}

/// A pile: particles per side, steps, and the emitter's cycle and life (s).
#[derive(Debug, Clone, Copy)]
pub struct Plan {
    /// Particles per side of the state texture.
    pub side: u32,
    /// Steps to run.
    pub steps: u64,
    /// The emitter's cycle and life (s): the whole texture is poured in one cycle.
    pub cycle: f32,
}

/// The pile of each report size (the full one is `tests/pile_depth.rs`'s).
pub fn plan(size: Size) -> Plan {
    match size {
        Size::Full => Plan {
            side: 32,
            steps: 700,
            cycle: 4.0,
        },
        Size::Quick => Plan {
            side: 16,
            steps: 150,
            cycle: 2.0,
        },
    }
}

/// The `collide` scene as `plan` pours it, with `detection` and `iterations`.
pub fn pile_scene(plan: Plan, detection: scene::Detection, iterations: u32) -> Result<SceneFile> {
    let mut s = scene::load("collide")?;
    s.particles.size = [plan.side, plan.side];
    for e in s.emitters.timestamp.iter_mut() {
        e.cycle = Some(plan.cycle);
        e.life = Some([plan.cycle, plan.cycle].into());
    }
    if let Some(c) = s.collisions.as_mut() {
        c.detection = detection;
        c.iterations = iterations;
    }
    s.check()?;
    Ok(s)
}

/// UberFlow's detection, then the exact one at 1, 2 and 4 iterations.
pub fn pile_sweep(
    ctx: &Context,
    plan: Plan,
    seed: u32,
    progress: Progress<'_>,
) -> Result<Vec<PileRow>> {
    let configs = [
        (scene::Detection::Uberflow, 1),
        (scene::Detection::Exact, 1),
        (scene::Detection::Exact, 2),
        (scene::Detection::Exact, 4),
    ];
    let mut rows = Vec::new();
    for (detection, iterations) in configs {
        let name = format!("{detection:?} x{iterations}").to_lowercase();
        progress(&format!("pile depth: {name}"));
        let s = pile_scene(plan, detection, iterations)?;
        let st = measure(ctx, &s, plan.steps, seed, || {})?;
        rows.push(PileRow {
            detection: format!("{detection:?}").to_lowercase(),
            iterations,
            mean_depth_percent: 100.0 * st.mean_depth,
            overlaps_per_particle: st.overlaps_per_particle,
            particles: st.particles,
            gpu_ms: st.gpu_ms,
        });
    }
    Ok(rows)
}

/// The rows as markdown, under a `###` heading.
pub fn markdown(rows: &[PileRow], plan: Plan, clock: Clock) -> String {
    let Plan { side, steps, cycle } = plan;
    let mut md = format!(
        "\n### Pile depth against iterations\n\n`collide` at {side}x{side} particles poured in \
         {cycle} s (emitter cycle and life), step {steps}: mean overlap depth of the overlapping pairs (all pairs on the CPU) and the \
         median GPU time of a step's collision passes ({}); `pile_depth.json`.\n\n\
         | detection | iterations | mean overlap (% of diameter) | overlapping neighbours per \
         particle | live particles | GPU ms per step |\n| --- | ---: | ---: | ---: | ---: | ---: |\n",
        clock.name()
    );
    for r in rows {
        md += &format!(
            "| {} | {} | {:.2} | {:.2} | {} | {:.2} |\n",
            r.detection,
            r.iterations,
            r.mean_depth_percent,
            r.overlaps_per_particle,
            r.particles,
            r.gpu_ms
        );
    }
    md
}

/// Writes `pile_depth.json`.
pub fn write_json(rows: &[PileRow], out: &Path) -> Result<PathBuf> {
    let path = out.join("pile_depth.json");
    super::write_json(&path, rows)?;
    Ok(path)
}
