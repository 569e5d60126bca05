//! Table 2 as markdown, and the GPU-over-CPU ratios the paper compares.

use super::SceneRecord;
use crate::gl::Clock;

/// Fills `vs_e5` and `paper_vs_e5` from the E5 record of the same size.
pub(super) fn add_ratios(records: &mut [SceneRecord]) {
    let e5: Vec<(u32, Option<f64>, Option<f64>)> = records
        .iter()
        .filter(|r| r.experiment == "E5")
        .map(|r| (r.size, r.fps, r.paper_fps))
        .collect();
    for r in records.iter_mut() {
        if let Some(&(_, fps, paper)) = e5.iter().find(|(s, ..)| *s == r.size) {
            r.vs_e5 = r.fps.zip(fps).map(|(a, b)| a / b);
            r.paper_vs_e5 = r.paper_fps.zip(paper).map(|(a, b)| a / b);
        }
    }
}

/// A number with three significant digits at most, or more before the point.
fn num(x: f64) -> String {
    if x >= 100.0 {
        format!("{x:.0}")
    } else if x >= 10.0 {
        format!("{x:.1}")
    } else if x >= 1.0 {
        format!("{x:.2}")
    } else {
        format!("{x:.3}")
    }
}

fn thousands(n: u64) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The records as two Markdown tables: fps per experiment with the paper's in parentheses and
/// E3/E5 (GPU over CPU, the paper's comparison); then milliseconds per frame and live particles.
/// Experiments not run show "—".
pub fn markdown(records: &[SceneRecord]) -> String {
    let mut sizes: Vec<u32> = records.iter().map(|r| r.size).collect();
    sizes.dedup();
    let mut names: Vec<&str> = Vec::new();
    for r in records {
        if !names.contains(&r.experiment.as_str()) {
            names.push(&r.experiment);
        }
    }
    let mut out = fps_table(records, &sizes, &names);
    out.push('\n');
    out += &ms_table(records, &sizes, &names);
    out += &phases_table(records);
    out
}

/// The experiment `name` at `size`, if it was run.
fn find<'a>(records: &'a [SceneRecord], size: u32, name: &str) -> Option<&'a SceneRecord> {
    records
        .iter()
        .find(|r| r.size == size && r.experiment == name)
}

/// Frames per second against the paper's, and E3/E5 where both ran.
fn fps_table(records: &[SceneRecord], sizes: &[u32], names: &[&str]) -> String {
    let mut out = String::new();
    let ratio = names.contains(&"E3") && names.contains(&"E5");
    let mut header = "| size | particles |".to_owned();
    let mut rule = "|---|---:|".to_owned();
    for n in names {
        header += &format!(" {n} fps (paper) |");
        rule += "---:|";
    }
    if ratio {
        header += " E3/E5 (paper) |";
        rule += "---:|";
    }
    out += &format!("{header}\n{rule}\n");
    for &size in sizes {
        let mut row = format!("| {size}² | {} |", thousands(size as u64 * size as u64));
        for n in names {
            let Some(r) = find(records, size, n) else {
                row += " |";
                continue;
            };
            let mut measured = r.fps.map(num).unwrap_or_else(|| "—".into());
            if let Some(f) = r.pairs_found {
                measured += &format!(", {:.1}% of pairs found", 100.0 * f);
            }
            if let Some(o) = r.overlaps_per_particle {
                measured += &format!(" at {o:.3} overlaps per particle");
            }
            row += &match r.paper_fps {
                Some(p) => format!(" {measured} ({}) |", num(p)),
                None => format!(" {measured} |"),
            };
        }
        if ratio {
            let e3 = find(records, size, "E3");
            let measured = e3
                .and_then(|r| r.vs_e5)
                .map(num)
                .unwrap_or_else(|| "—".into());
            row += &match e3.and_then(|r| r.paper_vs_e5) {
                Some(p) => format!(" {measured} ({}) |", num(p)),
                None => format!(" {measured} |"),
            };
        }
        out += &row;
        out.push('\n');
    }
    out
}

/// Milliseconds per frame, wall time beside the GPU clock's, and the live particles.
fn ms_table(records: &[SceneRecord], sizes: &[u32], names: &[&str]) -> String {
    let mut out = String::new();
    let gpu_clock = records.iter().any(|r| r.clock == Some(Clock::Gpu));
    let mut header = "| size |".to_owned();
    let mut rule = "|---|".to_owned();
    for n in names {
        header += &format!(" {n} ms |");
        rule += "---:|";
    }
    if gpu_clock {
        header += " wall ms (GPU experiments) |";
        rule += "---|";
    }
    header += " live particles |";
    rule += "---|";
    out += &format!("{header}\n{rule}\n");
    for &size in sizes {
        let mut row = format!("| {size}² |");
        let mut walls = Vec::new();
        let mut lives = Vec::new();
        for n in names {
            let r = find(records, size, n);
            row += &format!(
                " {} |",
                r.and_then(|r| r.ms)
                    .map(|m| format!("{m:.3}"))
                    .unwrap_or_else(|| "—".into())
            );
            if let Some(r) = r {
                if let (Some(w), Some(Clock::Gpu)) = (r.wall_ms, r.clock) {
                    walls.push(format!("{n} {w:.3}"));
                }
                if let Some(l) = r.live {
                    lives.push((*n, l));
                }
            }
        }
        if gpu_clock {
            row += &format!(" {} |", walls.join(", "));
        }
        let same = lives.windows(2).all(|w| w[0].1 == w[1].1);
        row += &match (same, lives.first()) {
            (true, Some((_, l))) => format!(" {} |", thousands(*l)),
            _ => {
                let v: Vec<String> = lives
                    .iter()
                    .map(|(n, l)| format!("{n} {}", thousands(*l)))
                    .collect();
                format!(" {} |", v.join(", "))
            }
        };
        out += &row;
        out.push('\n');
    }
    out
}

/// The parts of a frame, where they were timed.
fn phases_table(records: &[SceneRecord]) -> String {
    let mut out = String::new();
    if records.iter().any(|r| !r.phases.is_empty()) {
        out += "\n| size | experiment | parts of a frame, ms (each finished before the next) |\n";
        out += "|---|---|---|\n";
        for r in records.iter().filter(|r| !r.phases.is_empty()) {
            let parts: Vec<String> = r
                .phases
                .iter()
                .map(|p| format!("{} {:.3}", p.name, p.ms))
                .collect();
            out += &format!(
                "| {}² | {} | {} |\n",
                r.size,
                r.experiment,
                parts.join("; ")
            );
        }
    }
    out
}
