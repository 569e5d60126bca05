//! `[[forces.*]]`: springs, vortices, attractors and the one wind field.

use super::{fail, nonzero, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::SceneFile;

use Key::{Index as I, Name as N};

/// `[[forces.spring]]`, `[[forces.vortex]]`, `[[forces.attractor]]`, `[[forces.wind]]`.
pub(super) fn forces(s: &SceneFile) -> Check {
    for (i, sp) in s.forces.spring.iter().enumerate() {
        if sp.stiffness < 0.0 {
            return fail(
                path(&[N("forces"), N("spring"), I(i), N("stiffness")]),
                format!("stiffness {} N/m must not be negative", sp.stiffness),
            );
        }
    }
    for (i, v) in s.forces.vortex.iter().enumerate() {
        if !nonzero(v.axis) {
            return fail(
                path(&[N("forces"), N("vortex"), I(i), N("axis")]),
                "axis must not be zero",
            );
        }
    }
    for (i, a) in s.forces.attractor.iter().enumerate() {
        if a.softening <= 0.0 {
            return fail(
                path(&[N("forces"), N("attractor"), I(i), N("softening")]),
                "softening must be above 0",
            );
        }
        if a.max_distance.is_some_and(|d| d <= 0.0) {
            return fail(
                path(&[N("forces"), N("attractor"), I(i), N("max_distance")]),
                "max_distance must be above 0",
            );
        }
    }
    for (i, wnd) in s.forces.wind.iter().enumerate() {
        let at = |k| path(&[N("forces"), N("wind"), I(i), N(k)]);
        if wnd.drag < 0.0 {
            return fail(at("drag"), "drag must not be negative");
        }
        if wnd.turbulence < 0.0 {
            return fail(at("turbulence"), "turbulence must not be negative");
        }
        if !(2..=256).contains(&wnd.resolution) {
            return fail(at("resolution"), "resolution must lie in 2..=256");
        }
        if (0..3).any(|k| wnd.bounds[0][k] >= wnd.bounds[1][k]) {
            return fail(
                at("bounds"),
                "bounds must be [min corner, max corner] with min < max",
            );
        }
    }
    if s.forces.wind.len() > 1 {
        return fail(
            path(&[N("forces"), N("wind"), I(1)]),
            "one wind field per scene (it is one 3D texture)",
        );
    }
    Ok(())
}
