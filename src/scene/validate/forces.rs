//! `[[forces.*]]`: springs, vortices, attractors and the one wind field.

use super::{bounded, direction, fail, nonzero, Check, MAX_COORDINATE};
use crate::scene::locate::Key;
use crate::scene::schema::{
    Attractor, Falloff, Force, ForceKind, Forces, SceneFile, Spring, StateModel, Vortex,
    VortexForm, Wind, WindForm, MAX_CUSTOM_FORCES, MAX_EMITTER_FORCES,
};

use Key::{Index as I, Name as N};

/// Largest |rate × dt| of a damping rate or a wind drag (see [`forces`]).
pub const MAX_RATE_DT: f32 = 4.0;

/// A rate (1/s) whose explicit step multiplies the velocity by about 1 - rate·dt: |rate·dt| > 2
/// grows it every step. The stability report runs just past 2 on purpose (its drag sweep ends at
/// 2.1), so the limit is [`MAX_RATE_DT`]: at most 3 times per step, finite over a short run,
/// refusing ±1e30.
pub(super) fn per_step(dt: f32, at: Vec<Key>, what: &str, rate: f32) -> Check {
    if (rate * dt).is_nan() || (rate * dt).abs() > MAX_RATE_DT {
        return fail(
            at,
            format!(
                "{what} {rate} 1/s times dt {dt} s is {}: |{what} × dt| must be at most \
                 {MAX_RATE_DT}, or the velocity overflows; lower it or dt",
                rate * dt
            ),
        );
    }
    Ok(())
}

/// `[[forces.spring]]`, `[[forces.vortex]]`, `[[forces.attractor]]`, `[[forces.wind]]`, and
/// the forces of every emitter (`[[emitters.<kind>.forces.*]]`).
pub(super) fn forces(s: &SceneFile) -> Check {
    kinds(s, &[N("forces")], &s.forces)?;
    for (kind, i, e) in s.emitters.by_kind() {
        emitter_forces(
            s,
            &[N("emitters"), N(kind.key()), I(i), N("forces")],
            &e.forces,
        )?;
    }
    Ok(())
}

/// An emitter's own forces: the kinds that are uniforms of the integration pass, a few of each.
fn emitter_forces(s: &SceneFile, base: &[Key], f: &Forces) -> Check {
    for kind in ForceKind::ALL {
        let n = f.count(kind);
        let scene_only = match kind {
            ForceKind::Gravity | ForceKind::Damping => None,
            ForceKind::Attractor | ForceKind::Spring | ForceKind::Vortex => {
                if n > MAX_EMITTER_FORCES {
                    let kind = kind.key();
                    return fail(
                        at(base, &[N(kind), I(MAX_EMITTER_FORCES)]),
                        format!(
                            "{n} {kind} forces on one emitter are too many: at most \
                             {MAX_EMITTER_FORCES} of each kind per emitter (each is uniforms of \
                             the integration pass, whose total the GL limits); move the ones \
                             shared by every emitter to [[forces.{kind}]]"
                        ),
                    );
                }
                None
            }
            ForceKind::Wind => Some(
                "a wind is one 3D flow-field texture for the whole scene: give it in \
                 [[forces.wind]] (it acts on every emitter's particles)",
            ),
            ForceKind::Custom => Some(
                "a custom force is compiled once for the whole scene and gets each particle's \
                 `type` (its emitter's place): give it in [[forces.custom]] and act on the \
                 types it is for",
            ),
            ForceKind::Pair => Some(
                "a pair force acts between neighbours that the collision stage finds, whatever \
                 their emitter: give it in [[forces.pair]] (with [collisions]) and act on the \
                 `type` and `type_j` it is for",
            ),
        };
        if let Some(why) = scene_only.filter(|_| n > 0) {
            return fail(at(base, &[N(kind.key()), I(0)]), why);
        }
    }
    if s.simulation == StateModel::Stateless && *f != Forces::default() {
        return fail(
            base.to_vec(),
            "a stateless simulation has one closed form for every particle: give its gravity \
             and damping in [[forces.*]], or use simulation = \"stateful\"",
        );
    }
    kinds(s, base, f)
}

fn at(base: &[Key], more: &[Key]) -> Vec<Key> {
    [base, more].concat()
}

/// The forces of one list (the scene's, or an emitter's), at `base`.
fn kinds(s: &SceneFile, base: &[Key], f: &Forces) -> Check {
    let dt = s.time.dt;
    for (i, force) in f.indexed() {
        let at = |k| at(base, &[N(force.kind().key()), I(i), N(k)]);
        match force {
            Force::Gravity(g) => bounded(at("acceleration"), "acceleration", &g.acceleration)?,
            Force::Damping(d) => per_step(dt, at("rate"), "rate", d.rate)?,
            Force::Wind(wnd) => wind(s, base, i, wnd)?,
            Force::Attractor(a) => attractor(base, i, a)?,
            Force::Spring(sp) => spring(base, i, sp)?,
            Force::Vortex(v) => vortex(base, i, v)?,
            Force::Custom(c) => {
                if c.glsl.trim().is_empty() || c.glsl.contains('"') || c.glsl.contains('\n') {
                    return fail(
                        at("glsl"),
                        "glsl must name a GLSL file (relative to the scene file), e.g. \
                         \"wind.glsl\"",
                    );
                }
            }
            // Checked with the collision stage they need (`neighbours.rs`).
            Force::Pair(_) => {}
        }
    }
    if f.custom.len() > MAX_CUSTOM_FORCES {
        return fail(
            at(base, &[N("custom"), I(MAX_CUSTOM_FORCES)]),
            format!("at most {MAX_CUSTOM_FORCES} custom forces per scene"),
        );
    }
    if f.wind.len() > 1 {
        return fail(
            at(base, &[N("wind"), I(1)]),
            "one wind field per scene (it is one 3D texture)",
        );
    }
    Ok(())
}

/// `spring` number `i` under `base`.
fn spring(base: &[Key], i: usize, sp: &Spring) -> Check {
    let at = |k| at(base, &[N("spring"), I(i), N(k)]);
    if sp.stiffness < 0.0 {
        return fail(
            at("stiffness"),
            format!("stiffness {} N/m must not be negative", sp.stiffness),
        );
    }
    bounded(at("anchor"), "anchor", &sp.anchor)?;
    if sp.stiffness > MAX_COORDINATE {
        return fail(
            at("stiffness"),
            format!("stiffness {} N/m is above {MAX_COORDINATE:e}", sp.stiffness),
        );
    }
    Ok(())
}

/// `vortex` number `i` under `base`.
fn vortex(base: &[Key], i: usize, v: &Vortex) -> Check {
    if !nonzero(v.axis) {
        return fail(
            at(base, &[N("vortex"), I(i), N("axis")]),
            "axis must not be zero",
        );
    }
    let at = |k| at(base, &[N("vortex"), I(i), N(k)]);
    direction(at("axis"), "axis", v.axis)?;
    if v.softening <= 0.0 {
        return fail(at("softening"), "softening must be above 0");
    }
    if v.max_distance.is_some_and(|d| d <= 0.0) {
        return fail(at("max_distance"), "max_distance must be above 0");
    }
    if v.form == VortexForm::Swirl
        && (v.max_distance.is_some() || v.falloff != Falloff::InverseSquare)
    {
        return fail(
            at("form"),
            "falloff and max_distance belong to form = \"latta\" (Latta §3.4.2: towards \
             the closest point on the line); the swirl has a fixed core",
        );
    }
    bounded(at("point"), "point", &v.point)?;
    bounded(at("strength"), "strength", &[v.strength])?;
    Ok(())
}

/// `attractor` number `i` under `base`.
fn attractor(base: &[Key], i: usize, a: &Attractor) -> Check {
    if a.softening <= 0.0 {
        return fail(
            at(base, &[N("attractor"), I(i), N("softening")]),
            "softening must be above 0",
        );
    }
    if a.max_distance.is_some_and(|d| d <= 0.0) {
        return fail(
            at(base, &[N("attractor"), I(i), N("max_distance")]),
            "max_distance must be above 0",
        );
    }
    let at = |k| at(base, &[N("attractor"), I(i), N(k)]);
    bounded(at("position"), "position", &a.position)?;
    bounded(at("strength"), "strength", &[a.strength])?;
    Ok(())
}

/// `wind` number `i` under `base`: drag per form, procedural or file field, its box.
fn wind(s: &SceneFile, base: &[Key], i: usize, wnd: &Wind) -> Check {
    let per_step = |at, what: &str, rate| per_step(s.time.dt, at, what, rate);
    let at = |k| at(base, &[N("wind"), I(i), N(k)]);
    if wnd.drag < 0.0 {
        return fail(at("drag"), "drag must not be negative");
    }
    if wnd.form == WindForm::Uberflow && wnd.drag != 0.0 {
        return fail(
            at("drag"),
            "form = \"uberflow\" adds the wind velocity to the velocity (UberFlow eq. 1) and \
             has no drag: remove drag, or use form = \"drag\" or \"latta\"",
        );
    }
    per_step(at("drag"), "drag", wnd.drag)?;
    if wnd.form == WindForm::Latta {
        // Latta eq. 1-2: the drag is a force, divided by the mass: its rate per step is
        // drag / mass for the lightest particle.
        let m = lightest(s);
        per_step(at("drag"), "drag / lightest mass", wnd.drag / m)?;
    }
    bounded(at("velocity"), "velocity", &wnd.velocity)?;
    bounded(at("turbulence"), "turbulence", &[wnd.turbulence])?;
    for (c, corner) in wnd.bounds.iter().enumerate() {
        bounded([&at("bounds")[..], &[I(c)]].concat(), "bounds", corner)?;
    }
    if wnd.turbulence < 0.0 {
        return fail(at("turbulence"), "turbulence must not be negative");
    }
    bounded(at("curl"), "curl", &[wnd.curl])?;
    if wnd.curl < 0.0 {
        return fail(at("curl"), "curl must not be negative");
    }
    if !(wnd.curl_scale > 0.0 && wnd.curl_scale <= super::MAX_COORDINATE) {
        return fail(at("curl_scale"), "curl_scale must be above 0 m");
    }
    if wnd.field.is_some() && (wnd.turbulence != 0.0 || wnd.curl != 0.0) {
        return fail(
            at(if wnd.curl != 0.0 {
                "curl"
            } else {
                "turbulence"
            }),
            "a wind from a file is the file's field plus the mean velocity: remove the key",
        );
    }
    if wnd.field.is_some() && wnd.resolution != 32 {
        return fail(
            at("resolution"),
            "a wind from a file takes its resolution from the file's shape: remove resolution",
        );
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
    Ok(())
}

/// The smallest mass any particle of `s` has (kg): `particles.mass`, or an emitter's `mass` or
/// the low end of its `mass_range`.
pub(super) fn lightest(s: &SceneFile) -> f32 {
    let em = &s.emitters;
    em.allocator
        .iter()
        .chain(&em.timestamp)
        .chain(&em.initial)
        .flat_map(|e| [e.mass, e.mass_range.map(|r| r[0])])
        .flatten()
        .fold(s.particles.mass, f32::min)
}

impl SceneFile {
    /// Makes the relative `[[forces.custom]]`, `[[forces.pair]]` and `[[state]]` paths relative to `dir`, the directory of the
    /// scene file (a scene's paths are relative to the file, not to the working directory).
    /// Call it after parsing a scene read from a file; absolute paths are kept.
    pub fn resolve_custom_paths(&mut self, dir: &std::path::Path) {
        let files = (self.forces.custom.iter_mut().map(|c| &mut c.glsl))
            .chain(self.forces.pair.iter_mut().map(|c| &mut c.glsl))
            .chain(self.state.iter_mut().filter_map(|c| c.glsl.as_mut()));
        for glsl in files {
            let p = std::path::Path::new(glsl.as_str());
            if p.is_relative() {
                *glsl = dir.join(p).to_string_lossy().into_owned();
            }
        }
    }
}
