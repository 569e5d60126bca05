//! The list of passes a scene runs (`texflow scene passes`): [`Plan`], which an engine assembles
//! from what it holds ([`Engine::plan`](super::Engine::plan)): its simulation's step passes
//! ([`Simulation::passes`](crate::sim::Simulation::passes), from the features it compiled), its
//! sort's and its renderer's. And [`sort_plan`]: the sort a scene needs, from the scene alone,
//! which the engine builds its sorter from.

use std::fmt;

use crate::gl::PassInfo;
use crate::scene::{Blending, DrawOrder, SceneFile, SortKey};
use crate::sort::Variant;

/// The passes of one frame.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Plan {
    /// Scene name.
    pub scene: String,
    /// Passes of one simulation step.
    pub per_step: Vec<String>,
    /// Steps per frame.
    pub substeps: u32,
    /// Passes run once per frame after the steps.
    pub per_frame: Vec<String>,
    /// The same passes with the programs each draws (per step for the step's stages, per frame
    /// for the others), as the stages that built them return them.
    pub passes: Vec<PassInfo>,
}

/// The stages a simulation step runs; the others (sort, gather, render) run once a frame.
pub const STEP_STAGES: [&str; 4] = ["births", "integrate", "relax", "collide"];

impl Plan {
    /// The plan of `passes`, in order: those of [`STEP_STAGES`] run `substeps` times a frame.
    pub fn new(scene: &str, substeps: u32, passes: Vec<PassInfo>) -> Self {
        let (step, frame): (Vec<&PassInfo>, Vec<&PassInfo>) =
            passes.iter().partition(|p| STEP_STAGES.contains(&p.stage));
        Plan {
            scene: scene.to_owned(),
            per_step: step.into_iter().map(|p| p.name.clone()).collect(),
            substeps,
            per_frame: frame.into_iter().map(|p| p.name.clone()).collect(),
            passes,
        }
    }

    /// The draws of one frame by program, in the order of their first pass: (program, draws,
    /// whether the count depends on the data, in which case it is the most a frame draws).
    pub fn frame_draws(&self) -> Vec<(String, u64, bool)> {
        let mut out: Vec<(String, u64, bool)> = Vec::new();
        for p in &self.passes {
            let times = match STEP_STAGES.contains(&p.stage) {
                true => self.substeps as u64,
                false => 1,
            };
            for (program, n) in &p.draws {
                match out.iter_mut().find(|(name, ..)| name == program) {
                    Some((_, t, v)) => {
                        *t += n * times;
                        *v |= p.varies;
                    }
                    None => out.push((program.clone(), n * times, p.varies)),
                }
            }
        }
        out
    }
}

/// How an alpha-blended scene is sorted: variant, sort texture size, passes per full sort.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SortPlan {
    /// Variant.
    pub variant: Variant,
    /// Sort texture size (the state's, rounded up to powers of two).
    pub size: [u32; 2],
    /// Passes of one full sort.
    pub passes: usize,
    /// Passes per frame when the sort is spread over frames (Latta).
    pub passes_per_frame: Option<u32>,
    /// The blocked variant's shape: 16 exact entries per fragment, or 32 compact ones.
    pub shape: crate::sort::BlockedShape,
}

/// The sort a scene needs: only alpha blending depends on the drawing order.
pub fn sort_plan(scene: &SceneFile) -> Option<SortPlan> {
    if scene.render.blending != Blending::Alpha {
        return None;
    }
    let variant = scene.render.sort.variant.unwrap_or(Variant::OddEven);
    let [w, h] = scene.particles.size.map(|s| s.next_power_of_two().max(2));
    let block = w * h;
    // Compact entries 16 to a fragment and merged (`4cm`): on the H200 4.05, 16.7 and 69.1 ms
    // at 1024², 2048² and 4096² against 4.32, 18.1 and 79.1 for 32 to a fragment (`5cm`).
    let shape = if scene.render.sort.entries == Some(crate::scene::SortEntries::Compact) {
        crate::sort::BlockedShape {
            bits: 4,
            pinned: false,
            compact: true,
            merge: true,
        }
    } else {
        crate::sort::BlockedShape::default()
    };
    let options = crate::sort::SortOptions {
        blocked: shape,
        ..Default::default()
    };
    let passes = crate::sort::pass_count(variant, w, h, block, &options);
    Some(SortPlan {
        variant,
        size: [w, h],
        passes,
        passes_per_frame: scene.render.sort.passes_per_frame,
        shape,
    })
}

/// The sort's key and network passes of a frame, where alpha blending needs one (the engine
/// words the gather, from the textures it gathers).
pub fn sort_lines(scene: &SceneFile) -> Vec<String> {
    let r = &scene.render;
    let mut per_frame = Vec::new();
    let Some(s) = sort_plan(scene) else {
        return per_frame;
    };
    let order = match r.order {
        DrawOrder::BackToFront => "back to front",
        DrawOrder::FrontToBack => "front to back",
    };
    let key = match r.sort.key {
        _ if r.lighting == crate::scene::Lighting::HalfAngle => {
            "position along the half-angle vector"
        }
        SortKey::Distance => "distance to the viewer",
        SortKey::YoungestOnTop => "age, the youngest on top",
        SortKey::OldestOnTop => "age, the oldest on top",
    };
    let order = if r.lighting == crate::scene::Lighting::HalfAngle {
        "nearest the light first"
    } else {
        order
    };
    per_frame.push(format!(
        "sort keys: {key} ({order}), {}x{} entries{}",
        s.size[0],
        s.size[1],
        if s.passes_per_frame.is_some() {
            ", re-keyed in the order reached so far"
        } else {
            ""
        }
    ));
    per_frame.push(match s.passes_per_frame {
        Some(n) if r.sort.spread == crate::scene::Spread::Local => format!(
            "sort: {} network, {n} passes per frame, its first {} stages re-run before each \
             later one (local spread)",
            s.variant.name(),
            crate::sort::spread::LOCAL_STAGES
        ),
        Some(n) => format!(
            "sort: {} network, {n} of its {} passes per frame (spread over {} frames)",
            s.variant.name(),
            s.passes,
            s.passes.div_ceil(n as usize)
        ),
        None => format!("sort: {} network, {} passes", s.variant.name(), s.passes),
    });
    per_frame
}

impl fmt::Display for Plan {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "scene {}: passes per frame", self.scene)?;
        writeln!(f, "  {} step(s), each:", self.substeps)?;
        for p in &self.per_step {
            writeln!(f, "    - {p}")?;
        }
        writeln!(f, "  then once:")?;
        for p in &self.per_frame {
            writeln!(f, "    - {p}")?;
        }
        Ok(())
    }
}
