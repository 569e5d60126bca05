//! The extreme cases of the integration: huge speeds and coordinates, half-float overflow and
//! stalls, tiny and zero time steps, non-finite scene values; and [`extremes`], every case in
//! the report's order (the sort's cases are in `sort_cases`).

use glam::Vec3;

use super::sort_cases::{ids_fp24, ids_fp32, one_cell};
use super::{case, parse, scene, start, ExtremeCase, Outcome, StabilityOptions};
use crate::error::Result;
use crate::gl::Context;
use crate::report::convergence::{integrator_name, INTEGRATORS};
use crate::report::Progress;
use crate::scene::Integrator;
use crate::sim::nonfinite::{NonFiniteCount, NonFiniteCounter};
use crate::sim::ParticleSim;

fn count(ctx: &Context, sim: &ParticleSim) -> Result<NonFiniteCount> {
    NonFiniteCounter::for_sim(ctx, sim)?.count_sim(sim)
}

/// Indices of live particles with non-finite state in a read-back.
fn non_finite_ids(sim: &ParticleSim) -> Result<Vec<u64>> {
    let p = sim.read_positions()?;
    let v = sim.read_velocities()?;
    Ok((0..p.len() / 4)
        .filter(|&i| {
            NonFiniteCount::of_slices(&p[i * 4..i * 4 + 4], &v[i * 4..i * 4 + 4]).non_finite > 0
        })
        .map(|i| i as u64)
        .collect())
}

fn motion_scene(integrator: Integrator, n: u32, dt: f64, extra: &str, velocity: &str) -> String {
    scene(integrator, [n, 1], dt, &[1.0], extra)
        .replace("[particles]\n", &format!("[particles]\n{velocity}\n"))
}

/// Speeds of 10^6 m/s in fp32, for each integrator: finite, positions v·t to f32 rounding.
fn speed_1e6(ctx: &Context) -> Result<ExtremeCase> {
    let mut worst = 0.0f64;
    let mut bad = Vec::new();
    for &integrator in &INTEGRATORS {
        let s = parse(&motion_scene(integrator, 4, 1.0 / 64.0, "", ""))?;
        let v = Vec3::new(1e6, -1e6, 5e5);
        let mut sim = start(ctx, &s, &[(Vec3::ZERO, v, 0); 4])?;
        for _ in 0..64 {
            sim.run(crate::sim::Stage::Integrate)?;
        }
        let c = count(ctx, &sim)?;
        bad.extend(non_finite_ids(&sim)?);
        let p = sim.read_positions()?;
        for k in 0..3 {
            worst = worst.max(((p[k] - v[k]) as f64 / 1e6).abs());
        }
        if !c.is_clean() {
            worst = f64::INFINITY;
        }
    }
    let measured = if bad.is_empty() && worst < 1e-6 {
        Outcome::Finite
    } else if bad.is_empty() {
        Outcome::Stalled
    } else {
        Outcome::NonFinite
    };
    Ok(case(
        "speed 1e6 m/s",
        "v = (1e6, -1e6, 5e5) m/s, fp32, dt = 1/64 s, 64 steps, each integrator",
        Outcome::Finite,
        measured,
        format!("largest relative position error after 1 s: {worst:.1e}"),
        bad,
    ))
}

/// How the driver converts fragment outputs to half floats (GL leaves it open).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum HalfRounding {
    Nearest,
    TowardZero,
    Unknown,
}

/// Half-float velocities overflow: from 65000 m/s under 3000 m/s², |v| passes 65504. Round to
/// nearest gives +inf (non-finite, counted on the GPU); rounding toward zero saturates at 65504
/// (finite but wrong): either way the particles are reported.
fn half_overflow(ctx: &Context, rounding: HalfRounding) -> Result<ExtremeCase> {
    let s = parse(&motion_scene(
        Integrator::Euler,
        16,
        1.0 / 64.0,
        "[[forces.gravity]]\nacceleration = [3000.0, 0.0, 0.0]\n",
        "velocity_format = \"rgba16f\"",
    ))?;
    let mut sim = start(
        ctx,
        &s,
        &[(Vec3::ZERO, Vec3::new(65000.0, 0.0, 0.0), 0); 16],
    )?;
    let mut first_inf = None;
    let mut largest = 0.0f32;
    for step in 1..=64u64 {
        sim.run(crate::sim::Stage::Integrate)?;
        let v = sim.read_velocities()?[0];
        if v.is_finite() {
            largest = largest.max(v);
        } else if first_inf.is_none() {
            first_inf = Some(step);
        }
    }
    let c = count(ctx, &sim)?;
    let v = sim.read_velocities()?;
    let saturated: Vec<u64> = (0..16u64)
        .filter(|&i| {
            v[i as usize * 4..i as usize * 4 + 3]
                .iter()
                .any(|x| x.abs() == 65504.0)
        })
        .collect();
    let clamped = saturated.len();
    let (measured, ids) = if c.non_finite > 0 {
        (Outcome::NonFinite, non_finite_ids(&sim)?)
    } else if !saturated.is_empty() {
        (Outcome::Saturated, saturated)
    } else {
        (Outcome::Finite, Vec::new())
    };
    let expected = match rounding {
        HalfRounding::TowardZero => Outcome::Saturated,
        HalfRounding::Nearest | HalfRounding::Unknown => Outcome::NonFinite,
    };
    Ok(case(
        "half-float overflow",
        "rgba16f velocities from 65000 m/s under 3000 m/s², dt = 1/64 s, 16 particles",
        expected,
        measured,
        format!(
            "largest finite stored speed {largest} m/s (true: {:.0} m/s after 1 s); velocity +inf \
             {}; GPU count: {} of {} live particles non-finite ({} with non-finite \
             positions); {} clamped at 65504. Expected from the driver's half-float rounding \
             ({rounding:?}, measured by the free fall): +inf with round to nearest, saturation \
             toward zero",
            65000.0 + 3000.0,
            first_inf.map_or("never".into(), |s| format!("at step {s}")),
            c.non_finite,
            c.live,
            c.non_finite_position,
            clamped,
        ),
        ids,
    ))
}

/// Half-float free fall at 60 Hz stalls where g·dt falls below half the float spacing: 512 m/s
/// with round-to-nearest, 256 m/s if the conversion truncates (GL leaves it open: detected).
fn half_free_fall(ctx: &Context) -> Result<(ExtremeCase, HalfRounding)> {
    let s = parse(&motion_scene(
        Integrator::Euler,
        1,
        1.0 / 60.0,
        "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n",
        "velocity_format = \"rgba16f\"",
    ))?;
    let mut sim = start(
        ctx,
        &s,
        &[(Vec3::new(0.0, 1e4, 0.0), Vec3::new(0.0, -200.0, 0.0), 0)],
    )?;
    let mut history = Vec::new();
    for _ in 0..1800 {
        sim.run(crate::sim::Stage::Integrate)?;
        history.push(sim.read_velocities()?[1]);
    }
    let last = history[history.len() - 1];
    let stalled = history[history.len() - 200..].iter().all(|v| *v == last);
    let (rounding, mode) = match -last {
        512.0 => (HalfRounding::Nearest, "round to nearest"),
        256.0 => (HalfRounding::TowardZero, "truncation (toward zero)"),
        _ => (HalfRounding::Unknown, "an unexpected conversion"),
    };
    let c = case(
        "half-float free fall",
        "rgba16f velocities, g = 9.81 m/s², dt = 1/60 s, from -200 m/s, 1800 steps",
        Outcome::Stalled,
        if stalled {
            Outcome::Stalled
        } else {
            Outcome::Finite
        },
        format!(
            "speed stalls at {} m/s (true speed after 30 s: {:.0} m/s): the driver converts to \
             half floats by {mode}. Round to nearest stalls at 512 m/s, where g·dt = 0.16 m/s is \
             under half the spacing of 0.5 m/s; truncation at 256 m/s, where it is under the \
             spacing of 0.25 m/s",
            -last,
            200.0 + 9.81 * 30.0
        ),
        if stalled { vec![0] } else { vec![] },
    );
    Ok((c, rounding))
}

/// Large coordinates: at 0.1 m/s and 60 Hz a step is 1.7 mm; float spacing eats it.
fn large_coordinates(ctx: &Context) -> Result<ExtremeCase> {
    let xs = [1e3f32, 1e4, 1e5, 1e6, 1e7];
    let s = parse(&motion_scene(Integrator::Euler, 5, 1.0 / 60.0, "", ""))?;
    let particles: Vec<(Vec3, Vec3, u32)> = xs
        .iter()
        .map(|&x| (Vec3::new(x, 0.0, 0.0), Vec3::new(0.1, 0.0, 0.0), 0))
        .collect();
    let mut sim = start(ctx, &s, &particles)?;
    for _ in 0..600 {
        sim.run(crate::sim::Stage::Integrate)?;
    }
    let c = count(ctx, &sim)?;
    let p = sim.read_positions()?;
    let moved: Vec<f64> = (0..xs.len())
        .map(|i| p[i * 4] as f64 - xs[i] as f64)
        .collect();
    let stalled: Vec<u64> = (0..xs.len())
        .filter(|&i| moved[i].abs() < 0.5)
        .map(|i| i as u64)
        .collect();
    let measured = if !c.is_clean() {
        Outcome::NonFinite
    } else if stalled.contains(&4) {
        Outcome::Stalled
    } else {
        Outcome::Finite
    };
    let detail = xs
        .iter()
        .zip(&moved)
        .map(|(x, m)| format!("x = {x:.0e}: moved {m:.3} m"))
        .collect::<Vec<_>>()
        .join("; ");
    Ok(case(
        "position 1e7 m",
        "v = 0.1 m/s at x = 1e3 … 1e7 m, fp32, dt = 1/60 s, 600 steps (1 m expected)",
        Outcome::Stalled,
        measured,
        format!(
            "{detail}. Motion stops where v·dt < half the float spacing, |x| ≥ 2^24·v·dt ≈ 2.8e4 m \
             here; stalled particles are listed"
        ),
        stalled,
    ))
}

/// dt = 0 is refused when the scene is checked.
fn dt_zero(ctx: &Context) -> Result<ExtremeCase> {
    let mut s = parse(&motion_scene(Integrator::Euler, 1, 1.0 / 60.0, "", ""))?;
    s.time.dt = 0.0;
    let (measured, detail) = match ParticleSim::new(ctx, &s, 1) {
        Err(e) if e.is_bad_input() => (Outcome::Refused, e.to_string()),
        Err(e) => (
            Outcome::Corrupted,
            format!("failed, but not as bad input: {e}"),
        ),
        Ok(_) => (Outcome::Finite, "accepted".into()),
    };
    Ok(case(
        "dt = 0",
        "a scene with time.dt = 0 (also `render --dt 0`)",
        Outcome::Refused,
        measured,
        detail,
        vec![],
    ))
}

/// dt = 1e-9: allowed and finite for every integrator (Verlet divides by dt), but motion at
/// |x| = 1 is below the float spacing.
fn dt_tiny(ctx: &Context) -> Result<ExtremeCase> {
    let mut bad = Vec::new();
    let mut stalled = Vec::new();
    let mut details = Vec::new();
    for &integrator in &INTEGRATORS {
        let s = parse(&motion_scene(
            integrator,
            2,
            1e-9,
            "[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n",
            "",
        ))?;
        let mut sim = start(
            ctx,
            &s,
            &[
                (Vec3::new(1.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0), 0),
                (Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), 0),
            ],
        )?;
        for _ in 0..1000 {
            sim.run(crate::sim::Stage::Integrate)?;
        }
        let c = count(ctx, &sim)?;
        if !c.is_clean() {
            bad.extend(non_finite_ids(&sim)?);
        }
        let p = sim.read_positions()?;
        let (far, near) = (p[0] as f64 - 1.0, p[4] as f64);
        if far.abs() < 0.5e-6 {
            stalled.push(0);
        }
        details.push(format!(
            "{}: moved {far:.1e} m at x = 1, {near:.2e} m at x = 0",
            integrator_name(integrator)
        ));
    }
    let measured = if !bad.is_empty() {
        Outcome::NonFinite
    } else if stalled.len() == INTEGRATORS.len() {
        Outcome::Stalled
    } else {
        Outcome::Finite
    };
    Ok(case(
        "dt = 1e-9",
        "dt = 1e-9 s, 1000 steps at 1 m/s under gravity, from x = 1 m and x = 0, each integrator",
        Outcome::Stalled,
        measured,
        format!(
            "allowed and finite; {} (expected 1e-6 m: v·dt is below half the spacing 6e-8 of \
             floats at 1 m)",
            details.join("; ")
        ),
        stalled,
    ))
}

/// Non-finite scene values are refused when the file is read.
fn scene_non_finite() -> ExtremeCase {
    let dt = 1.0 / 60.0;
    let base = motion_scene(Integrator::Euler, 1, dt, "", "");
    let tries = [
        base.replace(&format!("dt = {dt:?}"), "dt = nan"),
        base.clone() + "[[forces.gravity]]\nacceleration = [inf, 0.0, 0.0]\n",
    ];
    let refused: Vec<String> = tries
        .iter()
        .filter_map(|src| parse(src).err())
        .filter(|e| e.is_bad_input())
        .map(|e| e.to_string())
        .collect();
    case(
        "nan and inf in a scene",
        "time.dt = nan; gravity = [inf, 0, 0]",
        Outcome::Refused,
        if refused.len() == tries.len() {
            Outcome::Refused
        } else {
            Outcome::Finite
        },
        refused.join("; "),
        vec![],
    )
}

/// Every extreme case.
pub fn extremes(
    ctx: &Context,
    opts: &StabilityOptions,
    progress: Progress<'_>,
) -> Result<Vec<ExtremeCase>> {
    let mut v = Vec::new();
    progress("extreme speeds");
    v.push(speed_1e6(ctx)?);
    let (fall, rounding) = half_free_fall(ctx)?;
    v.push(half_overflow(ctx, rounding)?);
    v.push(fall);
    progress("extreme coordinates and steps");
    v.push(large_coordinates(ctx)?);
    v.push(dt_zero(ctx)?);
    v.push(dt_tiny(ctx)?);
    v.push(scene_non_finite());
    progress("identifiers");
    v.push(ids_fp32());
    v.extend(ids_fp24(ctx)?);
    progress("one cell");
    v.push(one_cell(ctx, opts.cell_particles)?);
    Ok(v)
}
