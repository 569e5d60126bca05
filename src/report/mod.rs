//! `texflow report`: the reproduction of the papers, measured on this device and written as
//! tables, CSV, JSON, PNG plots and a markdown summary (docs/reproduction.md, docs/numerics.md).
//!
//! - [`tables`]: UberFlow's Table 1 (sorting) and Table 2 (E1-E5 frames per second).
//! - [`convergence`]: work-precision diagrams (error against GPU time per simulated second) and
//!   observed convergence orders, per integrator and precision, on problems with exact solutions.
//! - [`sort_frames`]: Latta's odd-even sort spread over frames under a moving camera:
//!   inversions and displacements against passes per frame and GPU time.
//! - [`collide_stats`]: what one step's collision detection found against the true pairs
//!   (`texflow collide-stats`); [`collide_runs`]: a run measured and the sweep of its settings.
//! - [`collisions`]: the miss rate of the collision detection against its GPU time.
//! - [`plot`]: the log-log plots (the only user of `plotters` and the DejaVu font).
//! - [`baselines`]: the stateless particle system (a closed form of start values and time)
//!   against the stateful engine, on error and GPU time per step.
//! - [`constraints`]: the cloth's edge error against relaxation passes and GPU time, per scheme.
//! - [`fluid`]: the dam break's density and front errors against run time, over dt and h.
//! - [`stability`]: the stiff spring and the stiff drag swept across their stability limits, and
//!   the extreme cases (huge speeds and coordinates, tiny and zero time steps, half-float
//!   overflow, identifiers beyond the float mantissa, 10^5 particles in one cell), each with its
//!   documented outcome.
//!
//! `texflow report all --out DIR` runs every [`Section`] of [`sections`] in order; each writes its
//! files into `DIR` and returns a markdown fragment, and `summary.md` joins the fragments. A new
//! report is one more entry in [`sections`].

pub mod baselines;
pub mod collide_iterations;
pub mod collide_runs;
pub mod collide_stats;
pub mod collisions;
pub mod constraints;
pub mod convergence;
pub mod cost;
pub mod fluid;
pub mod pile_depth;
pub mod plot;
pub mod sort_frames;
pub mod sort_spread;
pub mod stability;
pub mod tables;

use std::fs;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::gl::Context;

/// How much to measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Size {
    /// Everything the docs report (minutes on llvmpipe).
    #[default]
    Full,
    /// Fewer and shorter runs, sized for llvmpipe on 2 cores (about 11 s): CI's size.
    Quick,
}

/// Options every section receives.
#[derive(Debug, Clone, Copy)]
pub struct ReportOptions {
    /// How much to measure.
    pub size: Size,
    /// Runs of each benchmark table; every cell reports the run of median time (the machines are
    /// shared and noisy).
    pub runs: usize,
}

impl Default for ReportOptions {
    fn default() -> Self {
        ReportOptions {
            size: Size::Full,
            runs: 1,
        }
    }
}

impl ReportOptions {
    /// The full report, or the quick one, with one run of each table.
    pub fn new(quick: bool) -> Self {
        ReportOptions {
            size: if quick { Size::Quick } else { Size::Full },
            runs: 1,
        }
    }
}

/// What a section wrote.
#[derive(Debug, Clone, Default)]
pub struct SectionOutput {
    /// Files written (every one must exist and be non-empty afterwards).
    pub files: Vec<PathBuf>,
    /// Its part of `summary.md` (starting with a `##` heading).
    pub markdown: String,
    /// Findings the command line should repeat on stderr (a case that did not end in its
    /// documented outcome, say).
    pub warnings: Vec<String>,
}

/// Reports progress: a short message per unit of work.
pub type Progress<'a> = &'a mut dyn FnMut(&str);

/// One part of `texflow report all`.
#[derive(Debug, Clone, Copy)]
pub struct Section {
    /// Short name (also the CLI's subcommand where it has one).
    pub name: &'static str,
    /// Runs the measurements, writes files into the folder and returns them with the markdown.
    pub run: fn(&Context, &ReportOptions, &Path, Progress<'_>) -> Result<SectionOutput>,
}

/// The sections of `texflow report all`, in the order of `summary.md`. Append new reports here.
pub fn sections() -> Vec<Section> {
    vec![
        Section {
            name: "tables",
            run: tables::section,
        },
        Section {
            name: "convergence",
            run: convergence::section,
        },
        Section {
            name: "sort_frames",
            run: sort_spread::section,
        },
        Section {
            name: "collisions",
            run: collisions::section,
        },
        Section {
            name: "stability",
            run: stability::section,
        },
        Section {
            name: "cost",
            run: cost::section,
        },
        Section {
            name: "baselines",
            run: baselines::section,
        },
        Section {
            name: "constraints",
            run: constraints::section,
        },
        Section {
            name: "fluid",
            run: fluid::section,
        },
    ]
}

/// What `report all` wrote.
#[derive(Debug, Clone)]
pub struct AllOutput {
    /// Every file, `summary.md` last.
    pub files: Vec<PathBuf>,
    /// Every section's warnings.
    pub warnings: Vec<String>,
}

/// Runs every section into `out` (created if missing; a file in the way is an error before any
/// GPU work) and writes `summary.md`. Fails if a section did not write a file it promised.
pub fn run_all(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    progress: Progress<'_>,
) -> Result<AllOutput> {
    run_sections(ctx, opts, out, &sections(), progress)
}

/// The sections named in `names` (comma-free names of [`sections`]), in the report's order; an
/// unknown name is an error that lists the known ones.
pub fn select(names: &[String]) -> Result<Vec<Section>> {
    let all = sections();
    for n in names {
        if !all.iter().any(|s| s.name == n.trim()) {
            return Err(Error::InvalidInput(format!(
                "unknown report section `{n}`: the sections are {}",
                all.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
            )));
        }
    }
    Ok(all
        .into_iter()
        .filter(|s| names.iter().any(|n| n.trim() == s.name))
        .collect())
}

/// Runs `sections` into `out` like [`run_all`]; `summary.md` says which ran.
pub fn run_sections(
    ctx: &Context,
    opts: &ReportOptions,
    out: &Path,
    sections: &[Section],
    progress: Progress<'_>,
) -> Result<AllOutput> {
    create_dir(out)?;
    let mut files = Vec::new();
    let mut warnings = Vec::new();
    let everything = sections.len() == self::sections().len();
    let names: Vec<&str> = sections.iter().map(|s| s.name).collect();
    let mut md = format!(
        "# texflow report\n\nDevice: {} ({}); {} run{}. Regenerate with `texflow report all --out \
         {}{}{}{}`.\nWhat is measured and how: docs/reproduction.md, docs/numerics.md.\n",
        ctx.limits().renderer,
        ctx.limits().version,
        match opts.size {
            Size::Full => "full",
            Size::Quick => "quick",
        },
        if everything {
            String::new()
        } else {
            format!(" of {}", names.join(", "))
        },
        out.display(),
        if opts.size == Size::Quick {
            " --quick"
        } else {
            ""
        },
        if everything {
            String::new()
        } else {
            format!(" --only {}", names.join(","))
        },
        if opts.runs > 1 {
            format!(" --runs {}", opts.runs)
        } else {
            String::new()
        }
    );
    // Each section's wall time, so that a slow report says where its time went.
    let mut took = Vec::new();
    for s in sections {
        progress(s.name);
        let start = std::time::Instant::now();
        let o = (s.run)(ctx, opts, out, progress)?;
        took.push((s.name, start.elapsed().as_secs_f64()));
        check_files(s.name, &o.files)?;
        md.push('\n');
        md.push_str(&o.markdown);
        files.extend(o.files);
        warnings.extend(o.warnings);
    }
    md.push_str("\n## Run time\n\n| section | wall time, s |\n|---|---:|\n");
    for (name, secs) in &took {
        md.push_str(&format!("| {name} | {secs:.1} |\n"));
    }
    md.push_str("\n## Files\n\n");
    for f in &files {
        let name = f.strip_prefix(out).unwrap_or(f);
        md.push_str(&format!("- [{0}]({0})\n", name.display()));
    }
    let summary = out.join("summary.md");
    write_atomic(&summary, md.as_bytes())?;
    files.push(summary);
    Ok(AllOutput { files, warnings })
}

/// Checks that every promised file exists and is not empty.
pub fn check_files(section: &str, files: &[PathBuf]) -> Result<()> {
    for f in files {
        let len = fs::metadata(f).map(|m| m.len()).unwrap_or(0);
        if len == 0 {
            return Err(Error::Io {
                path: f.clone(),
                source: std::io::Error::other(format!(
                    "report section `{section}` promised this file but it is missing or empty"
                )),
            });
        }
    }
    Ok(())
}

/// Creates the output folder after the same checks as `render --out`.
pub fn create_dir(out: &Path) -> Result<()> {
    crate::output::FrameWriter::check(out)?;
    fs::create_dir_all(out).map_err(|source| Error::Io {
        path: out.to_owned(),
        source,
    })
}

/// Writes `bytes` through a temporary file and a rename, so no reader sees half a file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let io = |source| Error::Io {
        path: path.to_owned(),
        source,
    };
    let tmp = path.with_extension(format!(
        "{}.tmp",
        path.extension().and_then(|e| e.to_str()).unwrap_or("")
    ));
    fs::write(&tmp, bytes).map_err(io)?;
    fs::rename(&tmp, path).map_err(io)
}

/// Writes `value` as pretty JSON through [`write_atomic`].
pub fn write_json<T: serde::Serialize + ?Sized>(path: &Path, value: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(value).map_err(|e| Error::Io {
        path: path.to_owned(),
        source: std::io::Error::other(format!("serialising the report: {e}")),
    })?;
    write_atomic(path, text.as_bytes())
}

/// A CSV table: a header and rows of formatted fields, written through the csv crate (RFC 4180:
/// a field holding a comma, a quote or a newline is quoted, so no field can break a row).
#[derive(Debug, Clone, Default)]
pub struct Csv {
    rows: Vec<Vec<String>>,
}

impl Csv {
    /// A table with these column names.
    pub fn new(header: &[&str]) -> Self {
        let mut c = Csv::default();
        c.row(header.iter().map(|s| s.to_string()));
        c
    }

    /// Appends a row.
    pub fn row(&mut self, fields: impl IntoIterator<Item = String>) {
        self.rows.push(fields.into_iter().collect());
    }

    /// The table as CSV text.
    pub fn to_text(&self) -> String {
        let mut w = csv::WriterBuilder::new()
            .flexible(true)
            .from_writer(Vec::new());
        for r in &self.rows {
            // Writing into memory fails only on a broken invariant of the crate.
            w.write_record(r).expect("CSV into memory");
        }
        String::from_utf8(w.into_inner().expect("CSV into memory")).expect("UTF-8 fields")
    }

    /// Writes the table.
    pub fn write(&self, path: &Path) -> Result<()> {
        write_atomic(path, self.to_text().as_bytes())
    }
}

/// A number for CSV and tables: full precision, `nan`/`inf` spelled out, empty for none.
pub fn num(x: Option<f64>) -> String {
    match x {
        None => String::new(),
        Some(v) if v.is_nan() => "nan".into(),
        Some(v) if v.is_infinite() => if v > 0.0 { "inf" } else { "-inf" }.into(),
        Some(v) => format!("{v:e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::Csv;

    #[test]
    fn csv_fields_with_commas_quotes_and_newlines_keep_their_row() {
        let mut c = Csv::new(&["name", "value"]);
        c.row(["a, b".to_string(), "1".to_string()]);
        c.row(["say \"hi\"\nthere".to_string(), "2".to_string()]);
        let text = c.to_text();
        let mut r = csv::Reader::from_reader(text.as_bytes());
        let rows: Vec<Vec<String>> = r
            .records()
            .map(|x| x.unwrap().iter().map(str::to_owned).collect())
            .collect();
        assert_eq!(
            rows,
            [["a, b", "1"], ["say \"hi\"\nthere", "2"]].map(|r| r.map(str::to_owned).to_vec())
        );
    }
}
