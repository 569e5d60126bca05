//! The report's plots: log-log curves into PNG files. The only file that names `plotters` or the
//! embedded DejaVu font, so that plotting can become an optional feature: the data types
//! ([`Series`], [`Marker`], [`Legend`]) do not depend on either, only [`loglog`] and its helpers
//! do.

use std::path::Path;

use crate::error::{Error, Result};

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

/// A log-axis tick label: 1, 2 and 5 times a power of ten where the axis spans more than a
/// decade and a half (so that labels near a decade do not run into each other), every whole
/// multiple of a power of ten on a shorter axis (so that it has more than one label); written as
/// a plain number from 0.001 to 99,999, else as m×10ⁿ.
#[cfg(feature = "plots")]
fn tick(v: f64, span_decades: f64) -> String {
    let e = v.log10().floor();
    let m = v / 10f64.powf(e);
    let wanted: &[f64] = if span_decades > 1.5 {
        &[1.0, 2.0, 5.0, 10.0]
    } else {
        &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0]
    };
    let Some(&k) = wanted.iter().find(|&&k| (m - k).abs() < 1e-3 * k) else {
        return String::new();
    };
    let (k, e) = if k == 10.0 { (1.0, e + 1.0) } else { (k, e) };
    if (-3.0..5.0).contains(&e) {
        let decimals = (-e).max(0.0) as usize;
        format!("{:.*}", decimals, k * 10f64.powf(e))
    } else {
        let sup: String = format!("{e:.0}")
            .chars()
            .map(|c| match c {
                '-' => '⁻',
                d => ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'][d as usize - '0' as usize],
            })
            .collect();
        if k == 1.0 {
            format!("10{sup}")
        } else {
            format!("{k:.0}×10{sup}")
        }
    }
}

#[cfg(feature = "plots")]
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

/// Without the `plots` feature there is no drawing: the call says how to get it.
#[cfg(not(feature = "plots"))]
pub fn loglog(
    path: &Path,
    _title: &str,
    _axes: (&str, &str),
    _series: &[Series],
    _size: (u32, u32),
    _legend: Legend,
) -> Result<()> {
    Err(Error::InvalidInput(format!(
        "{} is a plot, and texflow was built without its `plots` feature: build with \
         `--features plots` (the default `cli` feature includes it)",
        path.display()
    )))
}

/// Draws a log-log plot of `series` into a PNG of `size` pixels, with both axes labelled.
#[cfg(feature = "plots")]
pub fn loglog(
    path: &Path,
    title: &str,
    axes: (&str, &str),
    series: &[Series],
    size: (u32, u32),
    legend: Legend,
) -> Result<()> {
    use plotters::prelude::*;
    register_font();
    let fail = |e: &dyn std::fmt::Display| plot_error(path, e);
    let ((x0, x1), (y0, y1)) = log_ranges(series);
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
            .x_label_formatter(&|v| tick(*v, (x1 / x0).log10()))
            .y_label_formatter(&|v| tick(*v, (y1 / y0).log10()))
            .x_labels(20)
            .y_labels(20)
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(|e| fail(&e))?;
        for s in series {
            draw_curve(&mut chart, s, path)?;
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
    crate::output::write_png_atomic(path, &img)
}

/// The chart [`loglog`] draws into: log axes on a PNG buffer.
#[cfg(feature = "plots")]
type LogChart<'a, 'b> = plotters::chart::ChartContext<
    'a,
    plotters::backend::BitMapBackend<'b>,
    plotters::coord::cartesian::Cartesian2d<
        plotters::coord::combinators::LogCoord<f64>,
        plotters::coord::combinators::LogCoord<f64>,
    >,
>;

/// A plotting error, naming the plot's file.
#[cfg(feature = "plots")]
fn plot_error(path: &Path, e: &dyn std::fmt::Display) -> Error {
    Error::Image {
        path: path.to_owned(),
        reason: e.to_string(),
    }
}

/// Draws one curve of [`loglog`]: its line (with its legend entry), its markers, and a ring
/// around each hollow point; points off the log axes are left out.
#[cfg(feature = "plots")]
fn draw_curve<'a, 'b: 'a>(chart: &mut LogChart<'a, 'b>, s: &Series, path: &Path) -> Result<()> {
    use plotters::prelude::*;
    let fail = |e: &dyn std::fmt::Display| plot_error(path, e);
    let ok = on_log_axes;
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
        .draw_series(
            drawn
                .iter()
                .filter(|d| d.1)
                .map(|&(p, _)| EmptyElement::at(p) + Circle::new((0, 0), 8, color.stroke_width(1))),
        )
        .map_err(|e| fail(&e))?;
    Ok(())
}

/// Whether a point can be drawn on log axes (finite and positive).
#[cfg(feature = "plots")]
fn on_log_axes(p: &(f64, f64)) -> bool {
    p.0.is_finite() && p.1.is_finite() && p.0 > 0.0 && p.1 > 0.0
}

/// The x and y ranges of the drawable points of `series`: from a power of ten to a fifth of a
/// decade past the largest point.
#[cfg(feature = "plots")]
fn log_ranges(series: &[Series]) -> ((f64, f64), (f64, f64)) {
    let pts: Vec<(f64, f64)> = series
        .iter()
        .flat_map(|s| s.points.iter().copied())
        .filter(on_log_axes)
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
            // The axis starts at a power of ten: plotters puts its first tick at the first power
            // of ten inside the range, so a range that starts above one has no label below it.
            (10f64.powf((mid - half).floor()), 10f64.powf(mid + half))
        }
    };
    (range(|p| p.0), range(|p| p.1))
}

#[cfg(feature = "plots")]
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

#[cfg(all(test, feature = "plots"))]
mod tests {
    use super::tick;

    #[test]
    fn ticks_read_as_plain_numbers_and_a_short_axis_gets_more_of_them() {
        assert_eq!(tick(50.0, 3.0), "50");
        assert_eq!(tick(0.002, 3.0), "0.002");
        assert_eq!(tick(1000.0, 3.0), "1000");
        assert_eq!(tick(3.0, 3.0), "");
        assert_eq!(tick(3.0, 1.0), "3");
        assert_eq!(tick(1e-6, 5.0), "10⁻⁶");
        assert_eq!(tick(5e-6, 5.0), "5×10⁻⁶");
        assert_eq!(tick(2e5, 3.0), "2×10⁵");
    }
}
