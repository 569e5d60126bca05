//! Points, curves and the fit of their order.

use serde::Serialize;

use super::{StatePrecision, ERRATIC_SPREAD};

/// Whether a point can be fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointStatus {
    /// Rounding is a small part of the error.
    Ok,
    /// Rounding or storage precision makes more than [`FLOOR_FRACTION`](super::FLOOR_FRACTION)
    /// of the error.
    Floor,
    /// The error exceeds [`LARGE_FRACTION`](super::LARGE_FRACTION) of the problem's scale.
    Large,
    /// Non-finite state or error.
    Diverged,
}

/// One run: one time step.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// Time step, s.
    pub dt: f64,
    /// Steps to the end time.
    pub steps: u64,
    /// The GPU's error against the exact solution.
    pub error: f64,
    /// The error of the rounding-free twin of the scheme (the truncation error alone).
    pub scheme_error: f64,
    /// What rounding and storage did, in the error's unit: the largest difference between the
    /// GPU's particles (or energy samples) and the twin's; for the bouncing ball, whose contacts
    /// are decisions that rounding can move by a step, the difference of the two errors.
    pub deviation: f64,
    /// Fit or not.
    pub status: PointStatus,
    /// Median GPU time of one integration pass, ms.
    pub gpu_ms_per_step: f64,
    /// GPU time per simulated second, ms (`gpu_ms_per_step / dt`).
    pub gpu_ms_per_sim_s: f64,
    /// Live particles with non-finite state at the end (GPU count).
    pub non_finite: u64,
}

/// The verdict on a curve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveStatus {
    /// An order was measured.
    Measured,
    /// Measured, but successive orders spread by more than [`ERRATIC_SPREAD`].
    Erratic,
    /// Errors do not fall with dt (slope under 0.3).
    NoConvergence,
    /// Fewer than two points above the rounding floor: no order.
    Floor,
    /// Fewer than two points with errors small enough for the asymptotic range: no order.
    PreAsymptotic,
    /// Fewer than two finite points.
    Diverged,
}

impl CurveStatus {
    /// Name in tables.
    pub fn name(self) -> &'static str {
        match self {
            CurveStatus::Measured => "measured",
            CurveStatus::Erratic => "erratic",
            CurveStatus::NoConvergence => "no convergence",
            CurveStatus::Floor => "rounding floor",
            CurveStatus::PreAsymptotic => "pre-asymptotic",
            CurveStatus::Diverged => "diverged",
        }
    }
}

/// The order fitted on a curve.
#[derive(Debug, Clone, Serialize)]
pub struct Fit {
    /// Least-squares slope of log error against log dt on the valid points.
    pub order: Option<f64>,
    /// Orders of successive halvings among the valid points.
    pub successive: Vec<f64>,
    /// Indices of the points fitted (the longest run of consecutive valid points).
    pub fitted: Vec<usize>,
    /// Verdict.
    pub status: CurveStatus,
}

/// Fits the order of `points` (coarsest dt first).
pub fn fit(points: &[Point]) -> Fit {
    // The longest run of consecutive valid points (the first of equal length).
    let mut best: Vec<usize> = Vec::new();
    let mut run: Vec<usize> = Vec::new();
    for (i, p) in points.iter().enumerate() {
        if p.status == PointStatus::Ok {
            run.push(i);
            if run.len() > best.len() {
                best = run.clone();
            }
        } else {
            run.clear();
        }
    }
    let successive: Vec<f64> = best
        .windows(2)
        .map(|w| {
            let (a, b) = (&points[w[0]], &points[w[1]]);
            (a.error / b.error).ln() / (a.dt / b.dt).ln()
        })
        .collect();
    let slope = |idx: &[usize]| {
        let xs: Vec<f64> = idx.iter().map(|&i| points[i].dt.ln()).collect();
        let ys: Vec<f64> = idx.iter().map(|&i| points[i].error.ln()).collect();
        let n = xs.len() as f64;
        let (mx, my) = (xs.iter().sum::<f64>() / n, ys.iter().sum::<f64>() / n);
        let sxy: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
        let sxx: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
        sxy / sxx
    };
    let order = (best.len() >= 2).then(|| slope(&best));
    let finite: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].status != PointStatus::Diverged)
        .collect();
    let floor = points.iter().any(|p| p.status == PointStatus::Floor);
    let spread = successive.iter().copied().fold(f64::NEG_INFINITY, f64::max)
        - successive.iter().copied().fold(f64::INFINITY, f64::min);
    let status = match order {
        None if finite.len() < 2 => CurveStatus::Diverged,
        None if floor => CurveStatus::Floor,
        // Only large errors: falling (pre-asymptotic) or not at all.
        None if slope(&finite) < 0.3 => CurveStatus::NoConvergence,
        None => CurveStatus::PreAsymptotic,
        Some(p) if p < 0.3 => CurveStatus::NoConvergence,
        Some(_) if spread > ERRATIC_SPREAD => CurveStatus::Erratic,
        Some(_) => CurveStatus::Measured,
    };
    Fit {
        order,
        successive,
        fitted: best,
        status,
    }
}

/// One integrator and precision over a sweep.
#[derive(Debug, Clone, Serialize)]
pub struct Curve {
    /// The problem's name.
    pub problem: String,
    /// Integrator.
    pub integrator: &'static str,
    /// Storage precision.
    pub precision: StatePrecision,
    /// Order theory expects.
    pub expected: Option<f64>,
    /// Points, coarsest dt first.
    pub points: Vec<Point>,
    /// The fit.
    pub fit: Fit,
}

impl Curve {
    /// Whether the measured order matches the expected one: status `measured` and every
    /// successive order within `tolerance`.
    pub fn matches_expected(&self, tolerance: f64) -> bool {
        match self.expected {
            Some(p) => {
                self.fit.status == CurveStatus::Measured
                    && self
                        .fit
                        .successive
                        .iter()
                        .all(|o| (o - p).abs() <= tolerance)
            }
            None => false,
        }
    }
}
