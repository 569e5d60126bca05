//! The stiff spring and the stiff drag, swept across their stability limits, against the
//! spectral radius of each scheme's amplification matrix.

use glam::Vec3;

use super::{parse, scene, start, Boundary, Stability, StabilityOptions, StiffRow};
use super::{DIVERGED, DRAG_SWEEP, SPRING_SWEEP, STIFF_DT};
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::report::convergence::{integrator_name, INTEGRATORS};
use crate::report::Progress;
use crate::scene::Integrator;
use crate::sim::nonfinite::{NonFiniteCount, NonFiniteCounter};
use crate::sim::ParticleSim;

/// Spectral radius of λ² − tr λ + det = 0.
fn spectral_radius(tr: f64, det: f64) -> f64 {
    let disc = tr * tr - 4.0 * det;
    if disc < 0.0 {
        det.sqrt()
    } else {
        let r = disc.sqrt();
        ((tr + r).abs()).max((tr - r).abs()) / 2.0
    }
}

/// Theory for the undamped spring at h = ω·dt: the amplification matrices of (x, v), or of
/// (x_n, x_{n-1}) for Verlet.
pub fn spring_theory(integrator: Integrator, h: f64) -> f64 {
    match integrator {
        // [[1 - h², h], [-h, 1]]: det 1, trace 2 - h².
        Integrator::Euler => spectral_radius(2.0 - h * h, 1.0),
        // [[1 - h²/2, h], [-h, 1]]: det 1 + h²/2, trace 2 - h²/2.
        Integrator::Uberflow => spectral_radius(2.0 - h * h / 2.0, 1.0 + h * h / 2.0),
        // x' = (2 - h²) x - x_prev: det 1, trace 2 - h².
        Integrator::Verlet => spectral_radius(2.0 - h * h, 1.0),
        // I + hA + (hA)²/2 with A² = -I: [[1 - h²/2, h], [-h, 1 - h²/2]].
        Integrator::Heun => {
            let c = 1.0 - h * h / 2.0;
            spectral_radius(2.0 * c, c * c + h * h)
        }
        // Σ (hA)^k / k! to k = 4: c I + s A, eigenvalues c ± i s.
        Integrator::Rk4 => {
            let c = 1.0 - h * h / 2.0 + h.powi(4) / 24.0;
            let s = h - h.powi(3) / 6.0;
            spectral_radius(2.0 * c, c * c + s * s)
        }
        // Kick-drift-kick: symplectic, trace 2 - h², det 1, as Verlet.
        Integrator::Leapfrog => spectral_radius(2.0 - h * h, 1.0),
    }
}

/// Growth per step of an amplitude sampled as (step, value), starting from 1: from the envelopes
/// (maxima over eight windows) of the first and the last window whose samples are all finite and
/// within [10^-6, 10^30], or, when growth or decay is too fast for that, from the first and last
/// such samples. Below 10^-6 a decaying amplitude meets the float floor (a Verlet velocity is a
/// difference of positions; denormals are flushed) and stops telling the scheme's factor.
fn growth(samples: &[(u64, f64)], steps: u64) -> Option<f64> {
    let good = |a: f64| a.is_finite() && (1e-6..1e30).contains(&a);
    let windows = 8u64;
    let width = (steps / windows).max(1);
    let mut env = vec![None::<f64>; windows as usize];
    let mut broken = vec![false; windows as usize];
    for &(n, a) in samples {
        let w = (((n.max(1) - 1) / width) as usize).min(windows as usize - 1);
        if good(a) {
            env[w] = Some(env[w].map_or(a, |e: f64| e.max(a)));
        } else {
            broken[w] = true;
        }
    }
    let whole: Vec<(usize, f64)> = env
        .iter()
        .enumerate()
        .filter(|(w, e)| e.is_some() && !broken[*w])
        .map(|(w, e)| (w, e.unwrap_or(0.0)))
        .collect();
    if whole.len() >= 3 && whole[0].0 == 0 {
        let (first, last) = (whole[0], whole[whole.len() - 1]);
        if first.1 > 0.0 && last.1 > 0.0 {
            return Some((last.1 / first.1).powf(1.0 / ((last.0 - first.0) as f64 * width as f64)));
        }
    }
    let fine: Vec<&(u64, f64)> = samples.iter().filter(|s| good(s.1) && s.1 > 0.0).collect();
    match (fine.first(), fine.last()) {
        (Some(a), Some(b)) if b.0 > a.0 => Some((b.1 / a.1).powf(1.0 / (b.0 - a.0) as f64)),
        _ => None,
    }
}

/// Runs up to four spring particles at once (one particle type each, mass (dt/h)² with
/// stiffness 1), sampling |x| every 10 steps.
fn spring_rows(
    ctx: &Context,
    integrator: Integrator,
    hs: &[f64],
    steps: u64,
) -> Result<Vec<StiffRow>> {
    let masses: Vec<f64> = hs.iter().map(|h| (STIFF_DT / h).powi(2)).collect();
    let src = scene(
        integrator,
        [hs.len() as u32, 1],
        STIFF_DT,
        &masses,
        "[[forces.spring]]\nanchor = [0.0, 0.0, 0.0]\nstiffness = 1.0\n",
    );
    let particles: Vec<(Vec3, Vec3, u32)> = (0..hs.len())
        .map(|j| (Vec3::X, Vec3::ZERO, j as u32))
        .collect();
    let mut sim = start(ctx, &parse(&src)?, &particles)?;
    let amplitude = |p: &[f32], j: usize| -> f64 {
        let x = &p[j * 4..j * 4 + 3];
        (x.iter().map(|v| (*v as f64).powi(2)).sum::<f64>()).sqrt()
    };
    track(ctx, &mut sim, hs.len(), steps, |sim| {
        let p = sim.read_positions()?;
        Ok((0..hs.len()).map(|j| amplitude(&p, j)).collect())
    })
    .map(|tracks| {
        tracks
            .into_iter()
            .zip(hs)
            .map(|(t, &h)| StiffRow {
                case: "spring",
                integrator: integrator_name(integrator),
                h,
                stability: t.stability,
                diverged_at_step: t.diverged_at,
                growth_per_step: growth(&t.samples, steps),
                theory_growth_per_step: spring_theory(integrator, h),
                non_finite: t.non_finite,
            })
            .collect()
    })
}

struct Track {
    samples: Vec<(u64, f64)>,
    stability: Stability,
    diverged_at: Option<u64>,
    non_finite: u64,
}

/// Steps `sim`, sampling `measure` (one amplitude per particle, start amplitude 1) every step
/// for the first 50 steps and every 10th after; at the end the GPU counts non-finite state, and the count must agree with the
/// read-back (it is what the report shows).
fn track(
    ctx: &Context,
    sim: &mut ParticleSim,
    particles: usize,
    steps: u64,
    mut measure: impl FnMut(&ParticleSim) -> Result<Vec<f64>>,
) -> Result<Vec<Track>> {
    let mut tracks: Vec<Track> = (0..particles)
        .map(|_| Track {
            samples: Vec::new(),
            stability: Stability::Bounded,
            diverged_at: None,
            non_finite: 0,
        })
        .collect();
    let mut n = 0;
    while n < steps {
        // Every step at first (fast decays and growths), then every 10th.
        let every = if n < 50 { 1 } else { 10 };
        for _ in 0..every.min(steps - n) {
            sim.run(crate::sim::Stage::Integrate)?;
            n += 1;
        }
        for (t, a) in tracks.iter_mut().zip(measure(sim)?) {
            t.samples.push((n, a));
            if t.diverged_at.is_none() && (a.is_nan() || a > DIVERGED) {
                t.diverged_at = Some(n);
                t.stability = Stability::Diverged;
            }
        }
    }
    let gpu = NonFiniteCounter::for_sim(ctx, sim)?.count_sim(sim)?;
    let velocities = match sim.velocities().or(sim.previous()) {
        Some(t) => t.read_f32()?,
        None => Vec::new(),
    };
    let positions = sim.read_positions()?;
    let cpu = NonFiniteCount::of_slices(&positions, &velocities);
    if gpu != cpu {
        return Err(Error::Gl(format!(
            "the GPU count of non-finite particles {gpu:?} differs from the read-back {cpu:?}"
        )));
    }
    for (j, t) in tracks.iter_mut().enumerate() {
        let one = NonFiniteCount::of_slices(
            &positions[j * 4..j * 4 + 4],
            velocities.get(j * 4..j * 4 + 4).unwrap_or(&[]),
        );
        t.non_finite = one.non_finite;
        if one.non_finite > 0 {
            t.stability = Stability::Diverged;
            t.diverged_at.get_or_insert(steps);
        }
    }
    ctx.check_error("stiff run")?;
    Ok(tracks)
}

/// One drag run: a particle at 1 m/s under damping c = h / dt, |v| sampled every 10 steps.
fn drag_row(ctx: &Context, integrator: Integrator, h: f64, steps: u64) -> Result<StiffRow> {
    let src = scene(
        integrator,
        [1, 1],
        STIFF_DT,
        &[1.0],
        &format!("[[forces.damping]]\nrate = {:?}\n", h / STIFF_DT),
    );
    let mut sim = start(ctx, &parse(&src)?, &[(Vec3::ZERO, Vec3::X, 0)])?;
    let t = track(ctx, &mut sim, 1, steps, |sim| {
        let v = sim.read_velocities()?;
        Ok(vec![(v[..3]
            .iter()
            .map(|x| (*x as f64).powi(2))
            .sum::<f64>())
        .sqrt()])
    })?
    .remove(0);
    Ok(StiffRow {
        case: "drag",
        integrator: integrator_name(integrator),
        h,
        stability: t.stability,
        diverged_at_step: t.diverged_at,
        growth_per_step: growth(&t.samples, steps),
        theory_growth_per_step: (1.0 - h).abs(),
        non_finite: t.non_finite,
    })
}

/// The stiff spring table and boundary search, and the stiff drag table.
pub fn stiff(
    ctx: &Context,
    opts: &StabilityOptions,
    progress: Progress<'_>,
) -> Result<(Vec<StiffRow>, Vec<Boundary>)> {
    let steps = opts.stiff_steps;
    let mut rows = Vec::new();
    let mut boundaries = Vec::new();
    for &integrator in &INTEGRATORS {
        let name = integrator_name(integrator);
        progress(&format!("stiff spring {name}"));
        let mut table = Vec::new();
        for chunk in SPRING_SWEEP.chunks(4) {
            table.extend(spring_rows(ctx, integrator, chunk, steps)?);
        }
        boundaries.push(spring_boundary(ctx, integrator, &table, opts)?);
        rows.extend(table);
    }
    for &integrator in &INTEGRATORS {
        let name = integrator_name(integrator);
        progress(&format!("stiff drag {name}"));
        let table: Vec<StiffRow> = DRAG_SWEEP
            .iter()
            .map(|&h| drag_row(ctx, integrator, h, steps))
            .collect::<Result<_>>()?;
        boundaries.push(drag_boundary(name, &table));
        rows.extend(table);
    }
    Ok((rows, boundaries))
}

/// The spring's stability boundary for one scheme from its sweep `table`: none for UberFlow's
/// scheme, else a search between ω·dt = 1.9 and 2.1 when the sweep brackets it there.
fn spring_boundary(
    ctx: &Context,
    integrator: Integrator,
    table: &[StiffRow],
    opts: &StabilityOptions,
) -> Result<Boundary> {
    let steps = opts.stiff_steps;
    let name = integrator_name(integrator);
    let verdict = |h: f64, t: &[StiffRow]| {
        t.iter()
            .find(|r| r.h == h)
            .map(|r| r.stability == Stability::Diverged)
    };
    Ok(if integrator == Integrator::Uberflow {
        let first = table.iter().find(|r| r.stability == Stability::Diverged);
        Boundary {
            case: "spring",
            integrator: name,
            theory: None,
            measured: None,
            note: format!(
                "no stability limit: det = 1 + (ω·dt)²/2 > 1, the energy grows at every dt \
                 (measured growth per step above 1 at every ω·dt of the sweep); beyond {DIVERGED:.0}x \
                 within {steps} steps from ω·dt = {}",
                first.map_or("-".to_owned(), |r| r.h.to_string())
            ),
        }
    } else if verdict(1.9, table) == Some(false) && verdict(2.1, table) == Some(true) {
        let [lo, hi] = search_spring_limit(ctx, integrator, opts)?;
        Boundary {
            case: "spring",
            integrator: name,
            theory: Some(2.0),
            measured: Some([lo, hi]),
            note: format!(
                "{}-round 4-ary search in [1.9, 2.1], {steps} steps each; theory: the \
                 amplification matrix has det 1 and trace 2 − (ω·dt)², within [−2, 2] up to \
                 ω·dt = 2",
                opts.search_rounds
            ),
        }
    } else {
        Boundary {
            case: "spring",
            integrator: name,
            theory: Some(2.0),
            measured: None,
            note: "not bracketed by ω·dt = 1.9 (bounded) and 2.1 (diverged)".into(),
        }
    })
}

/// Narrows [1.9, 2.1] around the spring's stability limit: each round runs four ω·dt inside the
/// bracket at once and keeps the interval where the runs turn from bounded to diverged.
fn search_spring_limit(
    ctx: &Context,
    integrator: Integrator,
    opts: &StabilityOptions,
) -> Result<[f64; 2]> {
    let (mut lo, mut hi) = (1.9f64, 2.1f64);
    for _ in 0..opts.search_rounds {
        let hs: Vec<f64> = (1..=4).map(|j| lo + (hi - lo) * j as f64 / 5.0).collect();
        let found = spring_rows(ctx, integrator, &hs, opts.stiff_steps)?;
        match found
            .iter()
            .position(|r| r.stability == Stability::Diverged)
        {
            Some(0) => hi = hs[0],
            Some(k) => (lo, hi) = (hs[k - 1], hs[k]),
            None => lo = hs[3],
        }
    }
    Ok([lo, hi])
}

/// The drag's measured boundary: between the largest bounded and the smallest diverged c·dt.
fn drag_boundary(name: &'static str, table: &[StiffRow]) -> Boundary {
    let lo = table
        .iter()
        .filter(|r| r.stability == Stability::Bounded)
        .map(|r| r.h)
        .fold(f64::NAN, f64::max);
    let hi = table
        .iter()
        .filter(|r| r.stability == Stability::Diverged)
        .map(|r| r.h)
        .fold(f64::NAN, f64::min);
    Boundary {
        case: "drag",
        integrator: name,
        theory: Some(2.0),
        measured: (lo < hi).then_some([lo, hi]),
        note: "velocity × (1 − c·dt) per step for every scheme".into(),
    }
}
