//! The measurement written out: the orders table, the CSV files and the work-precision plots.

use std::path::Path;

use super::{ConvergenceReport, Curve, CurveStatus, Point, PointStatus, StatePrecision};
use super::{FLOOR_FRACTION, LARGE_FRACTION};
use crate::error::Result;
use crate::report::plot::{self, Legend, Marker, Series};
use crate::report::{num, Csv};

fn fmt_order(o: Option<f64>) -> String {
    // `+ 0.0` turns a -0.00 into 0.00.
    o.map_or("-".into(), |p| {
        format!("{:.2}", (p * 100.0).round() / 100.0 + 0.0)
    })
}

/// The orders as a markdown table.
pub fn table(r: &ConvergenceReport) -> String {
    let mut s = String::from(
        "| problem | integrator | precision | expected | observed | successive orders | status | error range |\n\
         |---|---|---|---:|---:|---|---|---|\n",
    );
    for c in &r.curves {
        let errs: Vec<f64> = c.points.iter().map(|p| p.error).collect();
        let lo = errs.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = errs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        s += &format!(
            "| {} | {} | {} | {} | {} | {} | {} | {:.1e} … {:.1e} |\n",
            c.problem,
            c.integrator,
            c.precision.name(),
            fmt_order(c.expected),
            fmt_order(c.fit.order),
            if c.fit.successive.is_empty() {
                "-".into()
            } else {
                c.fit
                    .successive
                    .iter()
                    .map(|o| fmt_order(Some(*o)))
                    .collect::<Vec<_>>()
                    .join(", ")
            },
            c.fit.status.name(),
            lo,
            hi
        );
    }
    s
}

/// Writes `convergence.csv` (every point), `convergence_orders.csv` (every curve) and, per
/// problem, `wp_<problem>.png` (error against GPU time per simulated second) and
/// `dt_<problem>.png` (error against dt). Returns the files.
pub fn write_files(r: &ConvergenceReport, out: &Path) -> Result<Vec<std::path::PathBuf>> {
    let mut files = Vec::new();
    let (points, orders) = csv_tables(r);
    let f = out.join("convergence.csv");
    points.write(&f)?;
    files.push(f);
    let f = out.join("convergence_orders.csv");
    orders.write(&f)?;
    files.push(f);
    for sweep in &r.sweeps {
        let name = sweep.problem.name();
        let curves: Vec<&Curve> = r.curves.iter().filter(|c| c.problem == name).collect();
        // Errors fall with work (free corner: upper right) and rise with dt (upper left).
        for (file, xlabel, x, legend) in [
            (
                format!("wp_{name}.png"),
                "GPU time per simulated second (ms)",
                (|p: &Point| p.gpu_ms_per_sim_s) as fn(&Point) -> f64,
                Legend::UpperRight,
            ),
            (
                format!("dt_{name}.png"),
                "time step dt (s)",
                |p: &Point| p.dt,
                Legend::UpperLeft,
            ),
        ] {
            let series: Vec<Series> = curves.iter().map(|c| series(c, x)).collect();
            let path = out.join(file);
            plot::loglog(
                &path,
                &format!("{} ({})", sweep.problem.title(), r.device),
                (xlabel, sweep.problem.error_label()),
                &series,
                (1000, 720),
                legend,
            )?;
            files.push(path);
        }
    }
    let f = out.join("convergence.json");
    crate::report::write_json(&f, r)?;
    files.push(f);
    Ok(files)
}

/// The points and the fitted orders as CSV tables.
fn csv_tables(r: &ConvergenceReport) -> (Csv, Csv) {
    let mut points = Csv::new(&[
        "problem",
        "integrator",
        "precision",
        "dt_s",
        "steps",
        "error",
        "error_unit",
        "scheme_error",
        "rounding_deviation",
        "status",
        "gpu_ms_per_step",
        "gpu_ms_per_simulated_s",
        "non_finite",
    ]);
    let mut orders = Csv::new(&[
        "problem",
        "integrator",
        "precision",
        "expected_order",
        "observed_order",
        "successive_orders",
        "status",
        "points_fitted",
    ]);
    for c in &r.curves {
        let unit = if c.problem == "kepler" { "1" } else { "m" };
        for p in &c.points {
            points.row([
                c.problem.clone(),
                c.integrator.into(),
                c.precision.name().into(),
                num(Some(p.dt)),
                p.steps.to_string(),
                num(Some(p.error)),
                unit.into(),
                num(Some(p.scheme_error)),
                num(Some(p.deviation)),
                format!("{:?}", p.status).to_lowercase(),
                num(Some(p.gpu_ms_per_step)),
                num(Some(p.gpu_ms_per_sim_s)),
                p.non_finite.to_string(),
            ]);
        }
        orders.row([
            c.problem.clone(),
            c.integrator.into(),
            c.precision.name().into(),
            num(c.expected),
            num(c.fit.order),
            c.fit
                .successive
                .iter()
                .map(|o| format!("{o:.4}"))
                .collect::<Vec<_>>()
                .join(" "),
            c.fit.status.name().replace(' ', "_"),
            c.fit.fitted.len().to_string(),
        ]);
    }
    (points, orders)
}

/// One curve of a plot against `x`: colour by integrator, marker by precision, hollow where a
/// point did not measure the scheme.
fn series(c: &Curve, x: fn(&Point) -> f64) -> Series {
    Series {
        label: format!(
            "{} {}: p = {}{}",
            c.integrator,
            c.precision.name(),
            fmt_order(c.fit.order),
            match c.fit.status {
                CurveStatus::Measured => String::new(),
                s => format!(" ({})", s.name()),
            }
        ),
        points: c.points.iter().map(|p| (x(p), p.error)).collect(),
        hollow: c
            .points
            .iter()
            .map(|p| p.status != PointStatus::Ok)
            .collect(),
        color: match c.integrator {
            "euler" => (200, 40, 40),
            "uberflow" => (30, 90, 200),
            "heun" => (230, 140, 20),
            "rk4" => (140, 50, 170),
            "leapfrog" => (20, 170, 180),
            _ => (20, 140, 60),
        },
        marker: match c.precision {
            StatePrecision::Fp32 => Marker::Circle,
            StatePrecision::Fp16Velocity => Marker::Triangle,
            StatePrecision::Fp24 => Marker::Cross,
        },
        dashed: c.precision != StatePrecision::Fp32,
    }
}

/// The markdown of the section.
pub fn markdown(r: &ConvergenceReport) -> String {
    format!(
        "## Error against run time\n\n\
         Work-precision diagrams: `wp_<problem>.png` (error against GPU time per simulated \
         second, {}), `dt_<problem>.png` (error against dt); hollow, ringed markers are points \
         that take no part in the fit: at the rounding floor (the GPU differs from the \
         rounding-free twin by more than {:.0}% of the error), outside the asymptotic range \
         (error above {:.0}% of the problem's scale) or diverged. Every point: `convergence.csv`; every \
         curve: `convergence_orders.csv`.\n\n{}",
        r.clock.name(),
        FLOOR_FRACTION * 100.0,
        LARGE_FRACTION * 100.0,
        table(r)
    )
}
