//! `bench scene`'s records as text: the Markdown tables and the one-paragraph summaries.

use super::SceneBenchRecord;
use crate::bench::stats::{median, ratio_cell};
use crate::scene::SceneFile;

/// The records as a Markdown table per size, with the column names of the JSON keys.
pub fn scene_markdown(records: &[SceneBenchRecord]) -> String {
    let mut out = String::new();
    for r in records {
        out += &format!(
            "\n{} at {}x{} ({} particles, {} live, {}x{} frame, {} step(s) per frame): \
             frame_ms {:.3}, fps {:.1}, particles_per_s {:.3e}\n\n",
            r.scene,
            r.size,
            r.size,
            r.particles,
            r.live,
            r.resolution[0],
            r.resolution[1],
            r.substeps,
            r.frame_ms,
            r.fps,
            r.particles_per_s
        );
        let c = &r.constants;
        out += &format!(
            "Cost model (constants measured in the same run): {} (fetches: those declared).\n\n",
            c.describe()
        );
        if let Some(f) = &c.frame {
            out += &format!(
                "Into the {}x{} frame (the render pass): {:.4} ms per million points, {:.4} ms \
                 per million blended fragments, {:.4} ms per million texels cleared.\n\n",
                f.resolution[0],
                f.resolution[1],
                f.ms_per_m_points,
                f.ms_per_m_fragments,
                f.ms_per_m_cleared
            );
        }
        out += "| phase | ms | floor_ms | ratio | floor | bounds_ms | predicted_ms | \
                predicted / ms |\n\
                |---|---:|---:|---:|---|---|---:|---:|\n";
        for p in &r.phases {
            // Every bound measured, in order (render: placed points, then the fill floor); the
            // ratio is against the larger.
            let bounds: Vec<String> = p.bounds.iter().map(|b| format!("{:.3}", b.ms)).collect();
            let (predicted, ratio) = match p.predicted_ms {
                Some(m) => (format!("{m:.3}"), format!("{:.2}", m / p.ms)),
                None => ("–".into(), "–".into()),
            };
            out += &format!(
                "| {} | {:.3} | {:.3} | {} | {} | {} | {predicted} | {ratio} |\n",
                p.phase,
                p.ms,
                p.floor_ms,
                ratio_cell(p.ratio),
                p.floor,
                bounds.join(" / ")
            );
        }
    }
    out
}

/// One paragraph about a run, like the CUDA `particles` sample's `-benchmark` line: frames,
/// particles, median frame time, fps and particles per second, and each phase against its floor.
/// `render --stats` prints it for the run it made; `record` is one size of [`bench_scene`](super::bench_scene).
pub fn summary(record: &SceneBenchRecord) -> String {
    let r = record;
    let mut out = format!(
        "texflow, scene {}: {} particles ({} live), {}x{} frame, {} step(s) per frame; \
         median frame {:.3} ms = {:.1} fps, {:.4} M particles/s ({}, medians of {}).",
        r.scene,
        r.particles,
        r.live,
        r.resolution[0],
        r.resolution[1],
        r.substeps,
        r.frame_ms,
        r.fps,
        r.particles_per_s * 1e-6,
        r.clock.name(),
        r.repeats
    );
    if !r.phases.is_empty() {
        let parts: Vec<String> = r
            .phases
            .iter()
            .map(|p| format!("{} {:.3} ms ({:.2}x floor)", p.phase, p.ms, p.ratio))
            .collect();
        out += &format!(" Phases: {}.", parts.join("; "));
    }
    out
}

/// One paragraph about a run that was not a benchmark (`render --stats`): the frames it made,
/// their median time from `frame_ms` (one entry per frame: simulation and drawing, without
/// writing files), fps and particles per second, like the CUDA `particles` sample's
/// `-benchmark` line. For the phases and their floors, run `texflow bench scene` ([`summary`]).
pub fn run_summary(scene: &SceneFile, frame_ms: &[f64], live: u64) -> String {
    let [w, h] = scene.particles.size;
    let particles = w as u64 * h as u64;
    let m = median(frame_ms);
    format!(
        "texflow, scene {}: {} frames of {} particles ({} live at the end), {}x{} frame, {} \
         step(s) per frame; median frame {:.3} ms = {:.1} fps, {:.4} M particles/s (wall time \
         of simulation and drawing, files not counted). Phases and floors: texflow bench scene {}",
        scene.name,
        frame_ms.len(),
        particles,
        live,
        scene.render.resolution[0],
        scene.render.resolution[1],
        scene.time.substeps,
        m,
        1e3 / m,
        particles as f64 * 1e-3 / m,
        scene.name
    )
}
