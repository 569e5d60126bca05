//! `[constraints]` (cloth and hair) and the sphere orbits they ride on.

use super::{bounded, direction, fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{
    ConstraintKind, Constraints, Integrator, SceneFile, MAX_CONSTRAINT_ITERATIONS,
};

use Key::{Index as I, Name as N};

/// Sphere orbits: a radius that is a coordinate, a period above 0; only where the passes that
/// read the sphere follow it (Verlet, no collision stage).
pub(super) fn orbits(s: &SceneFile) -> Check {
    for (i, sp) in s.colliders.sphere.iter().enumerate() {
        let Some(o) = &sp.orbit else { continue };
        let at = |k| path(&[N("colliders"), N("sphere"), I(i), N("orbit"), N(k)]);
        bounded(at("radius"), "orbit radius", &[o.radius])?;
        if o.radius < 0.0 {
            return fail(at("radius"), "orbit radius must not be negative");
        }
        if o.period <= 0.0 {
            return fail(at("period"), "orbit period must be above 0 s");
        }
        super::duration(at("period"), "orbit period", o.period)?;
        if s.integrator != Integrator::Verlet || s.collisions.is_some() {
            return fail(
                path(&[N("colliders"), N("sphere"), I(i), N("orbit")]),
                "only Verlet scenes without [collisions] move their spheres: set integrator = \
                 \"verlet\" and remove [collisions], or remove the orbit",
            );
        }
    }
    Ok(())
}

/// `[constraints]`, and what it asks of the rest of the scene.
pub(super) fn constraints(s: &SceneFile) -> Check {
    let Some(c) = &s.constraints else {
        return Ok(());
    };
    let at = |k| path(&[N("constraints"), N(k)]);
    sheet(c)?;
    let [w, h] = s.particles.size;
    for (i, p) in c.pinned.iter().enumerate() {
        if crate::scene::Constraints::pinned_texel(*p, [w, h]).is_none() {
            return fail(
                path(&[N("constraints"), N("pinned"), I(i)]),
                format!(
                    "pinned texel [{}, {}] is outside the {w}x{h} state texture (x in -{w}..{w}, \
                     y in -{h}..{h}; negative counts from the far side)",
                    p[0], p[1]
                ),
            );
        }
    }
    match (c.kind, c.root_sphere) {
        (ConstraintKind::Hair, None) => {
            return fail(
                path(&[N("constraints")]),
                "hair needs root_sphere: the [[colliders.sphere]] (0, 1, ...) its roots sit on",
            );
        }
        (ConstraintKind::Hair, Some(k)) if k >= s.colliders.sphere.len() => {
            return fail(
                at("root_sphere"),
                format!(
                    "root_sphere {k} names no sphere: the scene has {} [[colliders.sphere]]",
                    s.colliders.sphere.len()
                ),
            );
        }
        (ConstraintKind::Cloth, Some(_)) => {
            return fail(
                at("root_sphere"),
                "root_sphere is for hair: pin cloth with pinned = [[x, y], ...]",
            );
        }
        _ => {}
    }
    if c.kind == ConstraintKind::Hair && w < 2 {
        return fail(
            path(&[N("particles"), N("size"), I(0)]),
            "hair strands are rows: give at least 2 texels per row",
        );
    }
    if s.integrator != Integrator::Verlet {
        return fail(
            path(&[N("integrator")]),
            "constraints move positions and let Verlet imply the velocities: set integrator = \
             \"verlet\"",
        );
    }
    if !s.emitters.is_empty() {
        return fail(
            path(&[N("emitters")]),
            "the constraint layout places every particle: remove the emitters",
        );
    }
    if s.collisions.is_some() {
        return fail(
            path(&[N("collisions")]),
            "collisions need an explicit integrator and constraints need Verlet: remove one",
        );
    }
    Ok(())
}

/// `[constraints]` relaxation keys and the sheet's spacing, origin and two directions.
fn sheet(c: &Constraints) -> Check {
    let at = |k| path(&[N("constraints"), N(k)]);
    if !(1..=MAX_CONSTRAINT_ITERATIONS).contains(&c.iterations) {
        return fail(
            at("iterations"),
            format!(
                "iterations {} must lie in 1..={MAX_CONSTRAINT_ITERATIONS} relaxation passes per \
                 step",
                c.iterations
            ),
        );
    }
    if !(c.stiffness > 0.0 && c.stiffness <= 1.0) {
        return fail(
            at("stiffness"),
            format!(
                "stiffness {} is outside (0, 1]: it is the share of the averaged correction \
                 applied per pass",
                c.stiffness
            ),
        );
    }
    if !(c.stretch_bound > 0.0 && c.stretch_bound <= 100.0) {
        return fail(
            at("stretch_bound"),
            format!(
                "stretch_bound {} is outside (0, 100]: it is the relative stretch past which an \
                 edge is counted (0.1 is 10 %)",
                c.stretch_bound
            ),
        );
    }
    bounded(at("spacing"), "spacing", &[c.spacing])?;
    if c.spacing <= 0.0 {
        return fail(
            at("spacing"),
            format!("spacing {} m must be above 0", c.spacing),
        );
    }
    bounded(at("origin"), "origin", &c.origin)?;
    direction(at("u"), "u", c.u)?;
    direction(at("v"), "v", c.v)?;
    let (u, v) = (glam::Vec3::from(c.u), glam::Vec3::from(c.v));
    if u.normalize().cross(v.normalize()).length() < 1e-3 {
        return fail(
            at("v"),
            "u and v are parallel: the sheet would have no area; give two directions across it",
        );
    }
    Ok(())
}
