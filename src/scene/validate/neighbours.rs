//! `[collisions] response = "dem"` with `[collisions.dem]`, and `[[forces.pair]]`: what the
//! neighbour forces over the sorted grid ask of the rest of the scene.

use super::{bounded, fail, forces::lightest, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{
    Collisions, Dem, Detection, PairForce, Response, SceneFile, MAX_PAIR_FORCES,
};

use Key::{Index as I, Name as N};

/// Largest ω dt of one contact between two of the lightest particles,
/// ω = sqrt(2 (spring + attraction) / m)
/// (the explicit step of a spring is stable below 2; a particle in a pile feels several
/// springs at once, so the limit leaves a margin of 2).
pub const MAX_DEM_OMEGA_DT: f32 = 1.0;

/// `[collisions.dem]` and `[[forces.pair]]`.
pub(super) fn neighbours(s: &SceneFile) -> Check {
    let exact = s
        .collisions
        .as_ref()
        .is_some_and(|c| c.detection == Detection::Exact);
    if let Some(c) = &s.collisions {
        let at = |k| path(&[N("collisions"), N(k)]);
        match (c.response, &c.dem) {
            (Response::Impulse, Some(_)) => {
                return fail(
                    at("dem"),
                    "[collisions.dem] applies to response = \"dem\" only: add it, or remove \
                     the table",
                )
            }
            (Response::Dem, None) => {
                return fail(
                    at("response"),
                    "response = \"dem\" needs its contact force: add [collisions.dem] with \
                     spring (N/m) and optionally damping, shear (kg/s) and attraction (N/m)",
                )
            }
            (Response::Dem, Some(d)) => dem(s, c, d, exact)?,
            (Response::Impulse, None) => {}
        }
    }
    let pair = &s.forces.pair;
    if pair.len() > MAX_PAIR_FORCES {
        return fail(
            path(&[N("forces"), N("pair"), I(MAX_PAIR_FORCES)]),
            format!("at most {MAX_PAIR_FORCES} pair forces per scene"),
        );
    }
    for (i, p) in pair.iter().enumerate() {
        pair_force(s, i, p, exact)?;
    }
    Ok(())
}

/// `[collisions.dem]` of `response = "dem"`: the exact search, one iteration, and a contact
/// force that the explicit step keeps stable for the lightest mass.
fn dem(s: &SceneFile, c: &Collisions, d: &Dem, exact: bool) -> Check {
    let at = |k| path(&[N("collisions"), N(k)]);
    if !exact {
        return fail(
            at("response"),
            "response = \"dem\" sums the force of every neighbour, which only the \
             exact detection finds: add detection = \"exact\"",
        );
    }
    if c.iterations != 1 {
        return fail(
            at("iterations"),
            "the dem response searches once per step and iterations apply to the \
             impulse only: remove iterations",
        );
    }
    let dem = |k| path(&[N("collisions"), N("dem"), N(k)]);
    for (k, v) in [
        ("spring", d.spring),
        ("damping", d.damping),
        ("shear", d.shear),
        ("attraction", d.attraction),
    ] {
        bounded(dem(k), k, &[v])?;
        if v < 0.0 {
            return fail(dem(k), format!("{k} {v} must not be negative"));
        }
    }
    if d.spring <= 0.0 {
        return fail(dem("spring"), "spring must be above 0 N/m");
    }
    let m = lightest(s);
    let dt = s.time.dt;
    // The attraction is a spring too (towards the partner), as stiff per metre.
    let stiffness = d.spring + d.attraction;
    let omega_dt = (2.0 * stiffness / m).sqrt() * dt;
    if omega_dt > MAX_DEM_OMEGA_DT {
        let largest = m / (2.0 * dt * dt) * MAX_DEM_OMEGA_DT.powi(2);
        return fail(
            dem("spring"),
            format!(
                "spring + attraction {stiffness} N/m is too stiff for dt {dt} s and \
                 the lightest mass {m} kg (ω dt = {omega_dt:.3}, at most \
                 {MAX_DEM_OMEGA_DT}): use a spring of at most {largest:.4e} N/m \
                 together, or a shorter dt"
            ),
        );
    }
    let rate_dt = 2.0 * (d.damping + d.shear) / m * dt;
    if rate_dt > 1.0 {
        return fail(
            dem("damping"),
            format!(
                "damping + shear {} kg/s damp a contact of the lightest mass {m} kg \
                 by {rate_dt:.3} per step of {dt} s (at most 1, or the relative \
                 velocity overshoots): lower them to at most {:.4e} kg/s together",
                d.damping + d.shear,
                m / (2.0 * dt)
            ),
        );
    }
    Ok(())
}

/// `[[forces.pair]]` number `i`: a GLSL file, and a reach within the exact search's cell.
fn pair_force(s: &SceneFile, i: usize, p: &PairForce, exact: bool) -> Check {
    let at = |k| path(&[N("forces"), N("pair"), I(i), N(k)]);
    if p.glsl.trim().is_empty() || p.glsl.contains('"') || p.glsl.contains('\n') {
        return fail(
            at("glsl"),
            "glsl must name a GLSL file (relative to the scene file), e.g. \"boids.glsl\"",
        );
    }
    let Some(c) = s.collisions.as_ref().filter(|_| exact) else {
        return fail(
            path(&[N("forces"), N("pair"), I(i)]),
            "a pair force reads the neighbours the exact collision detection finds: add \
             [collisions] with detection = \"exact\" (its cell is the force's reach)",
        );
    };
    bounded(at("radius"), "radius", &[p.radius])?;
    let cell = c.cell();
    if !(p.radius > 0.0 && p.radius <= cell) {
        return fail(
            at("radius"),
            format!(
                "radius {} m must be above 0 and at most the collision cell {cell} m, the \
                 reach of the search of the 27 cells around a particle (raise \
                 collisions.cell, up to the largest the exact detection allows)",
                p.radius
            ),
        );
    }
    Ok(())
}
