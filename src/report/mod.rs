//! `texflow report`: the reproduction of the papers, measured on this device and written as
//! tables, CSV, JSON, PNG plots and a markdown summary (docs/reproduction.md, docs/numerics.md).
//!
//! - [`tables`]: UberFlow's Table 1 (sorting) and Table 2 (E1-E5 frames per second).
//! - [`convergence`]: work-precision diagrams (error against GPU time per simulated second) and
//!   observed convergence orders, per integrator and precision, on problems with exact solutions.
//! - [`sort_frames`]: Latta's odd-even sort spread over frames under a moving camera:
//!   inversions and displacements against passes per frame and GPU time.
//! - [`collide_stats`]: what one step's collision detection found against the true pairs
//!   (`texflow collide-stats`), and the sweep of its settings.
//! - [`collisions`]: the miss rate of the collision detection against its GPU time.
//! - [`stability`]: the stiff spring and the stiff drag swept across their stability limits, and
//!   the extreme cases (huge speeds and coordinates, tiny and zero time steps, half-float
//!   overflow, identifiers beyond the float mantissa, 10^5 particles in one cell), each with its
//!   documented outcome.
//!
//! `texflow report all --out DIR` runs every [`Section`] of [`sections`] in order; each writes its
//! files into `DIR` and returns a markdown fragment, and `summary.md` joins the fragments. A new
//! report is one more entry in [`sections`].

pub mod collide_stats;
pub mod collisions;
pub mod convergence;
pub mod sort_frames;
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
            run: sort_frames::section,
        },
        Section {
            name: "collisions",
            run: collisions::section,
        },
        Section {
            name: "stability",
            run: stability::section,
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
    for s in sections {
        progress(s.name);
        let o = (s.run)(ctx, opts, out, progress)?;
        check_files(s.name, &o.files)?;
        md.push('\n');
        md.push_str(&o.markdown);
        files.extend(o.files);
        warnings.extend(o.warnings);
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
    crate::render::FrameWriter::check(out)?;
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

/// A CSV table: a header and rows of already formatted fields (none holds a comma or a quote).
#[derive(Debug, Clone, Default)]
pub struct Csv {
    text: String,
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
        let fields: Vec<String> = fields.into_iter().collect();
        debug_assert!(fields.iter().all(|f| !f.contains([',', '"', '\n'])));
        self.text.push_str(&fields.join(","));
        self.text.push('\n');
    }

    /// Writes the table.
    pub fn write(&self, path: &Path) -> Result<()> {
        write_atomic(path, self.text.as_bytes())
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

/// Marker of a plotted curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// Filled circle.
    Circle,
    /// Triangle.
    Triangle,
    /// Cross.
    Cross,
}

/// One curve of a log-log plot.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// (x, y) points; non-positive or non-finite ones are left out of the plot.
    pub points: Vec<(f64, f64)>,
    /// Which points to draw hollow (same length as `points`; e.g. errors at the rounding floor).
    pub hollow: Vec<bool>,
    /// Line and marker colour.
    pub color: (u8, u8, u8),
    /// Marker.
    pub marker: Marker,
    /// Dashed line.
    pub dashed: bool,
}

/// A log-axis tick label: 1, 2 and 5 times a power of ten only, so that labels near a decade do
/// not run into each other.
fn tick(v: &f64) -> String {
    let m = v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0, 10.0]
        .iter()
        .any(|k| (m - k).abs() < 1e-3 * k)
    {
        format!("{v:.0e}")
    } else {
        String::new()
    }
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // DejaVu Sans, embedded: no system fonts needed on a headless machine.
        let _ = plotters::style::register_font(
            "sans-serif",
            plotters::style::FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// Where a plot's legend goes (the corner the data leave free).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Legend {
    /// Upper left.
    UpperLeft,
    /// Upper right.
    UpperRight,
}

/// Draws a log-log plot of `series` into a PNG of `size` pixels, with both axes labelled.
pub fn plot_loglog(
    path: &Path,
    title: &str,
    axes: (&str, &str),
    series: &[Series],
    size: (u32, u32),
    legend: Legend,
) -> Result<()> {
    use plotters::prelude::*;
    register_font();
    let fail = |e: &dyn std::fmt::Display| Error::Image {
        path: path.to_owned(),
        reason: e.to_string(),
    };
    let ok = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite() && p.0 > 0.0 && p.1 > 0.0;
    let pts: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(ok)
        .collect();
    let range = |f: fn(&(f64, f64)) -> f64| {
        let lo = pts.iter().map(f).fold(f64::INFINITY, f64::min);
        let hi = pts.iter().map(f).fold(0.0, f64::max);
        if pts.is_empty() {
            (0.1, 10.0)
        } else {
            // A margin of a fifth of a decade, and at least one decade shown.
            let (lo, hi) = (lo.log10() - 0.2, hi.log10() + 0.2);
            let mid = 0.5 * (lo + hi);
            let half = (0.5 * (hi - lo)).max(0.5);
            (10f64.powf(mid - half), 10f64.powf(mid + half))
        }
    };
    let (x0, x1) = range(|p| p.0);
    let (y0, y1) = range(|p| p.1);
    let (w, h) = size;
    let mut buf = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(14)
            .x_label_area_size(52)
            .y_label_area_size(84)
            .build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc(axes.0)
            .y_desc(axes.1)
            .axis_desc_style(("sans-serif", 16))
            .label_style(("sans-serif", 13))
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| fail(&e))?;
        for s in series {
            let color = RGBColor(s.color.0, s.color.1, s.color.2);
            let line = ShapeStyle {
                color: color.to_rgba(),
                filled: false,
                stroke_width: 2,
            };
            let p: Vec<(f64, f64)> = s.points.iter().copied().filter(ok).collect();
            let anno = if s.dashed {
                chart.draw_series(DashedLineSeries::new(p.clone(), 6, 4, line))
            } else {
                chart.draw_series(LineSeries::new(p.clone(), line))
            }
            .map_err(|e| fail(&e))?;
            let marker = s.marker;
            anno.label(s.label.clone()).legend(move |(x, y)| {
                EmptyElement::at((x, y))
                    + PathElement::new(vec![(-10, 0), (10, 0)], line)
                    + marker_element(marker, (0, 0), true, color)
            });
            let drawn = s
                .points
                .iter()
                .zip(s.hollow.iter().chain(std::iter::repeat(&false)))
                .filter(|(p, _)| ok(p));
            let drawn: Vec<((f64, f64), bool)> = drawn.map(|(&p, &h)| (p, h)).collect();
            chart
                .draw_series(drawn.iter().map(|&(p, hollow)| {
                    EmptyElement::at(p) + marker_element(s.marker, (0, 0), !hollow, color)
                }))
                .map_err(|e| fail(&e))?;
            // Hollow points (not fitted) also get a ring, whatever their marker.
            chart
                .draw_series(drawn.iter().filter(|d| d.1).map(|&(p, _)| {
                    EmptyElement::at(p) + Circle::new((0, 0), 8, color.stroke_width(1))
                }))
                .map_err(|e| fail(&e))?;
        }
        chart
            .configure_series_labels()
            .label_font(("sans-serif", 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .position(match legend {
                Legend::UpperLeft => SeriesLabelPosition::UpperLeft,
                Legend::UpperRight => SeriesLabelPosition::UpperRight,
            })
            .draw()
            .map_err(|e| fail(&e))?;
        root.present().map_err(|e| fail(&e))?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or_else(|| Error::Image {
        path: path.to_owned(),
        reason: "plot buffer of the wrong size".into(),
    })?;
    crate::render::write_png_atomic(path, &img)
}

fn marker_element<DB: plotters::prelude::DrawingBackend>(
    m: Marker,
    at: (i32, i32),
    filled: bool,
    color: plotters::style::RGBColor,
) -> plotters::element::DynElement<'static, DB, (i32, i32)> {
    use plotters::prelude::*;
    let style = ShapeStyle {
        color: color.to_rgba(),
        filled,
        stroke_width: 2,
    };
    match m {
        Marker::Circle => Circle::new(at, 4, style).into_dyn(),
        Marker::Triangle => {
            let (x, y) = at;
            let corners = vec![(x, y - 6), (x + 5, y + 4), (x - 5, y + 4)];
            if filled {
                Polygon::new(corners, style).into_dyn()
            } else {
                let mut closed = corners.clone();
                closed.push(corners[0]);
                PathElement::new(closed, style).into_dyn()
            }
        }
        Marker::Cross => Cross::new(at, 4, style).into_dyn(),
    }
}
