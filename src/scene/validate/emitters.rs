//! `[[emitters.*]]`: one kind per scene, at most four, each with what its kind needs.

use super::curves::over;
use super::{
    bounded, direction, duration, fail, mass, nonzero, path, Check, MAX_COORDINATE, MIN_DIRECTION,
};
use glam::Vec3;

use crate::scene::curve::{Animated, Curve, CurveValue};
use crate::scene::locate::Key;
use crate::scene::schema::{Emitter, EmitterKind, Emitters, SceneFile, Shape, MAX_EMITTERS};

use Key::{Index as I, Name as N};

/// `[[emitters.allocator]]`, `[[emitters.timestamp]]`, `[[emitters.initial]]` (the child
/// emitters' own keys: `children.rs`).
pub(super) fn emitters(s: &SceneFile) -> Check {
    let em = &s.emitters;
    one_kind_and_count(em)?;
    let at = |kind: EmitterKind, i| [N("emitters"), N(kind.key()), I(i)];
    for (kind, i, e) in em.by_kind() {
        super::curves::emitter_curves(s, &at(kind, i), kind, e)?;
        super::type_curves::type_curves(s, &at(kind, i), kind.key(), e)?;
    }
    for (kind, i, e) in em.by_kind() {
        if kind.births_need_life() && e.life.is_none() {
            return fail(
                at(kind, i).to_vec(),
                format!("a {} emitter needs `life` = [min, max] seconds", kind.key()),
            );
        }
    }
    // The keys of each kind: those that need no other section first, then the fire's rule,
    // then those that weigh the rate against the state.
    for (kind, i, e) in em.by_kind() {
        match kind {
            EmitterKind::Initial => initial(i, e)?,
            EmitterKind::Allocator | EmitterKind::Timestamp | EmitterKind::Child => {}
        }
    }
    if s.fire.is_some() && !em.is_empty() {
        return fail(
            path(&[N("fire")]),
            "[fire] respawns its particles in the shader: remove the emitters, or [fire]",
        );
    }
    for (kind, i, e) in em.by_kind() {
        match kind {
            EmitterKind::Allocator => allocator(s, i, e)?,
            EmitterKind::Timestamp => timestamp(s, i, e)?,
            // Checked above; a child's keys in `children.rs`.
            EmitterKind::Initial | EmitterKind::Child => {}
        }
    }
    Ok(())
}

/// One kind of parent emitter per scene, and at most [`MAX_EMITTERS`] with the child emitters.
fn one_kind_and_count(em: &Emitters) -> Check {
    let present: Vec<EmitterKind> = (EmitterKind::ALL.into_iter())
        .filter(|k| k.owns_texels() && !em.of_kind(*k).is_empty())
        .collect();
    if let Some(second) = present.get(1) {
        return fail(
            path(&[N("emitters"), N(second.key())]),
            "use one kind of emitter per scene (allocator, timestamp or initial): they \
             manage the state texture in different ways",
        );
    }
    if em.len() > MAX_EMITTERS {
        // Only one kind besides children is present here: the first emitter over the limit is
        // its element, or a child emitter's.
        if em.parents() < MAX_EMITTERS {
            return fail(
                path(&[N("emitters"), N("child"), I(MAX_EMITTERS - em.parents())]),
                format!(
                    "{} emitters with the child emitters: at most {MAX_EMITTERS} (one particle \
                     type and atlas tile each)",
                    em.len()
                ),
            );
        }
        let kind = present.first().map_or("initial", |k| k.key());
        return fail(
            path(&[N("emitters"), N(kind), I(MAX_EMITTERS)]),
            format!(
                "{} emitters: at most {MAX_EMITTERS} (one particle type and atlas tile each)",
                em.len()
            ),
        );
    }
    Ok(())
}

/// `[[emitters.initial]]` number `i`: no keys of the emitting kinds.
fn initial(i: usize, e: &Emitter) -> Check {
    let at = [N("emitters"), N("initial"), I(i)];
    if let Some(k) = [
        ("rate", e.rate.is_some()),
        ("allocator", e.allocator.is_some()),
        ("cycle", e.cycle.is_some()),
        ("release_spread", e.release_spread.is_some()),
        ("release_cloud", e.release_cloud.is_some()),
    ]
    .iter()
    .find(|k| k.1)
    {
        return fail(
            [&at[..], &[N(k.0)]].concat(),
            format!("`{}` does not apply to initial emitters", k.0),
        );
    }
    check_spawn(&at, e)
}

/// `[[emitters.allocator]]` number `i`: a rate (or bursts) the state can hold, no timestamp keys.
fn allocator(s: &SceneFile, i: usize, e: &Emitter) -> Check {
    let at = [N("emitters"), N("allocator"), I(i)];
    let key = |k| [&at[..], &[N(k)]].concat();
    if let Some(r @ Animated::Curve(_)) = &e.rate {
        rate_curve(s, key("rate"), r)?;
    }
    match e.rate.as_ref().map(|r| r.at(0.0)) {
        // A curve's range is checked above.
        _ if e.rate.as_ref().is_some_and(|r| r.curve().is_some()) => {}
        // Bursts alone are a way to emit too.
        r if !e.bursts.is_empty() && r.unwrap_or(0.0) == 0.0 => {}
        None => {
            return fail(
                at.to_vec(),
                "an allocator emitter needs `rate` (particles per second)",
            )
        }
        Some(r) if r <= 0.0 => {
            return fail(
                key("rate"),
                "rate must be above 0 particles per second (0 only with `bursts`)",
            )
        }
        Some(r) if r as f64 * s.time.dt as f64 > s.particle_count() as f64 => {
            return fail(
                key("rate"),
                format!(
                    "rate {r} per second times dt {} s is {} births per step, more than \
                     the {} particles of the state: lower the rate or dt",
                    s.time.dt,
                    r as f64 * s.time.dt as f64,
                    s.particle_count()
                ),
            )
        }
        _ => {}
    }
    if e.cycle.is_some() || e.release_spread.is_some() || e.release_cloud.is_some() {
        let k = if e.cycle.is_some() {
            "cycle"
        } else if e.release_spread.is_some() {
            "release_spread"
        } else {
            "release_cloud"
        };
        return fail(
            key(k),
            format!("`{k}` belongs to timestamp emitters ([[emitters.timestamp]])"),
        );
    }
    check_spawn(&at, e)
}

/// A rate curve: never below 0, and never more births per step than the state holds.
fn rate_curve(s: &SceneFile, at: Vec<Key>, r: &Animated<f32>) -> Check {
    let [lo, hi] = r.bounds()[0];
    if lo < 0.0 {
        return fail(
            at,
            format!(
                "rate may reach {lo} particles per second{}: keep it at 0 or above",
                over(r)
            ),
        );
    }
    if hi as f64 * s.time.dt as f64 > s.particle_count() as f64 {
        return fail(
            at,
            format!(
                "rate may reach {hi} per second{}: times dt {} s that is more births per step \
                 than the {} particles of the state; lower the curve or dt",
                over(r),
                s.time.dt,
                s.particle_count()
            ),
        );
    }
    Ok(())
}

/// `[[emitters.timestamp]]` number `i`: a cycle no shorter than the life, release keys in range.
fn timestamp(s: &SceneFile, i: usize, e: &Emitter) -> Check {
    let at = [N("emitters"), N("timestamp"), I(i)];
    let key = |k| [&at[..], &[N(k)]].concat();
    if e.rate.is_some() || e.allocator.is_some() {
        return fail(
            key(if e.rate.is_some() {
                "rate"
            } else {
                "allocator"
            }),
            "`rate` and `allocator` belong to allocator emitters ([[emitters.allocator]])",
        );
    }
    check_spawn(&at, e)?;
    match e.cycle {
        None => return fail(at.to_vec(), "a timestamp emitter needs `cycle` (seconds)"),
        Some(c) if e.longest_life().is_some_and(|l| c < l) => {
            return fail(key("cycle"), "cycle must be at least the longest life")
        }
        Some(c) => duration(key("cycle"), "cycle", c)?,
    }
    if let Some(r) = e.release_spread {
        if r.iter().any(|v| !v.is_finite() || *v < 0.0 || *v > 1e6) {
            return fail(
                key("release_spread"),
                "release_spread takes three sizes in metres from 0 to 1e6, e.g. [4.0, 4.0, 4.0]",
            );
        }
    }
    match (e.release_cloud, e.release_spread) {
        (Some(_), None) => {
            return fail(
                key("release_cloud"),
                "release_cloud splits the releases that release_spread places: add \
                 release_spread = [x, y, z]",
            )
        }
        (Some(c), _) if c == 0 || c as u64 > s.particle_count() => {
            return fail(
                key("release_cloud"),
                format!(
                    "release_cloud is a count of texels from 1 to the {} particles",
                    s.particle_count()
                ),
            )
        }
        _ => {}
    }
    Ok(())
}

/// What every emitter shares: shape, velocity cone, life, mass, sprite.
pub(super) fn check_spawn(at: &[Key], s: &Emitter) -> Check {
    let p = |k| {
        let mut v = at.to_vec();
        v.push(N(k));
        v
    };
    if s.tile.is_some_and(|t| t > 3) {
        return fail(
            p("tile"),
            "tile must be 0, 1, 2 or 3 (the atlas has four tiles)",
        );
    }
    if let Some(life) = &s.life {
        super::curves::life(p("life"), life)?;
    }
    spawn_mass(p, s)?;
    spawn_velocity(&p, s)?;
    bounded_over(p("center"), "center", &s.center)?;
    bounded(p("size"), "size", &s.size)?;
    let [r_lo, r_hi] = s.radius.bounds()[0];
    if r_hi > MAX_COORDINATE {
        return fail(
            p("radius"),
            format!(
                "radius {r_hi} m{} is above {MAX_COORDINATE:e} m",
                over(&s.radius)
            ),
        );
    }
    if let Some(n) = s.normal.filter(|n| nonzero(*n)) {
        direction(p("normal"), "normal", n)?;
    }
    match s.shape {
        Shape::Sphere | Shape::Disc if r_lo <= 0.0 => fail(
            p("radius"),
            format!(
                "a sphere or disc emitter needs a radius above 0{}",
                over(&s.radius)
            ),
        ),
        Shape::Box if s.size.iter().any(|x| *x < 0.0) => {
            fail(p("size"), "box size must not be negative")
        }
        Shape::Disc if s.normal.is_some_and(|n| !nonzero(n)) => {
            fail(p("normal"), "normal must not be zero")
        }
        _ => Ok(()),
    }
}

/// Every component of a constant or a curve within ±[`MAX_COORDINATE`] (a curve: over its
/// bounds, reported at the curve).
fn bounded_over<T: CurveValue>(at: Vec<Key>, what: &str, v: &Animated<T>) -> Check {
    match v {
        Animated::Constant(c) => bounded(at, what, &c.components()),
        Animated::Curve(_) => {
            for [lo, hi] in v.bounds() {
                let x = if lo.abs() > hi.abs() { lo } else { hi };
                if x.is_nan() || x.abs() > MAX_COORDINATE {
                    return fail(
                        at,
                        format!(
                            "{what} may reach {x}{}: keep it within ±{MAX_COORDINATE:e}",
                            over(v)
                        ),
                    );
                }
            }
            Ok(())
        }
    }
}

/// The velocity cone: speed range, direction and half-angle, over their curves' bounds.
fn spawn_velocity(p: &impl Fn(&'static str) -> Vec<Key>, s: &Emitter) -> Check {
    let speed_at_keys = match &s.speed {
        Animated::Constant(v) => vec![*v],
        Animated::Curve(c) => c
            .keys
            .iter()
            .map(|k| <[f32; 2]>::from_components(&k.1 .0).unwrap_or([0.0; 2]))
            .collect(),
    };
    let min_lo = s.speed.bounds()[0][0];
    if !(min_lo >= 0.0 && speed_at_keys.iter().all(|v| v[0] <= v[1])) {
        return fail(
            p("speed"),
            format!(
                "speed must be [min, max] with 0 <= min <= max{}",
                over(&s.speed)
            ),
        );
    }
    bounded_over(p("speed"), "speed", &s.speed)?;
    match &s.direction {
        Animated::Constant(d) => {
            if !nonzero(*d) {
                return fail(p("direction"), "direction must not be zero");
            }
            direction(p("direction"), "direction", *d)?;
        }
        Animated::Curve(c) => {
            let keys = c.key_values::<[f32; 3]>();
            for (i, d) in keys.iter().enumerate() {
                direction(
                    [&p("direction")[..], &[N("keys"), I(i)]].concat(),
                    "direction",
                    *d,
                )?;
            }
            bounded_over(p("direction"), "direction", &s.direction)?;
            never_zero(p("direction"), c, &keys)?;
        }
    }
    let [lo, hi] = s.cone_degrees.bounds()[0];
    if !(lo >= 0.0 && hi <= 180.0) {
        return fail(
            p("cone_degrees"),
            format!("cone_degrees must lie in [0, 180]{}", over(&s.cone_degrees)),
        );
    }
    Ok(())
}

/// A direction curve never passes through zero: every segment between keys (linear or smooth,
/// both on the straight line between them) stays farther from 0 than the terms can move it.
fn never_zero(at: Vec<Key>, c: &Curve, keys: &[[f32; 3]]) -> Check {
    let reach = Vec3::from_array([0, 1, 2].map(|i| c.reach(i))).length();
    let closest = |a: Vec3, b: Vec3| {
        let d = b - a;
        let s = if d.length_squared() > 0.0 {
            (-a.dot(d) / d.length_squared()).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a + s * d).length()
    };
    let v: Vec<Vec3> = keys.iter().map(|k| Vec3::from_array(*k)).collect();
    let near = match v.len() {
        1 => v[0].length(),
        _ => v
            .windows(2)
            .map(|w| closest(w[0], w[1]))
            .fold(f32::INFINITY, f32::min),
    };
    if near <= reach + MIN_DIRECTION {
        return fail(
            at,
            format!(
                "the direction curve may pass through zero: between its keys it comes within \
                 {near} of 0, and its periodic and noise terms reach {reach}; keep the keys \
                 apart from opposite directions, or lower the amplitudes"
            ),
        );
    }
    Ok(())
}

/// An emitter's `mass` (one for the type) or `mass_range` (one per particle), never both.
fn spawn_mass(p: impl Fn(&'static str) -> Vec<Key>, s: &Emitter) -> Check {
    if let Some(m) = s.mass.filter(|m| *m <= 0.0) {
        return fail(p("mass"), format!("mass {m} must be above 0 kg"));
    }
    if let Some(m) = s.mass {
        mass(p("mass"), m)?;
    }
    if let Some([lo, hi]) = s.mass_range {
        if s.mass.is_some() {
            return fail(
                p("mass_range"),
                "give mass (one mass for the type) or mass_range (a mass per particle), not both",
            );
        }
        if !(lo > 0.0 && lo <= hi && hi.is_finite()) {
            return fail(
                p("mass_range"),
                format!("mass_range [{lo}, {hi}] must be [lo, hi] with 0 < lo <= hi (kg)"),
            );
        }
        for (i, m) in [lo, hi].into_iter().enumerate() {
            mass([&p("mass_range")[..], &[I(i)]].concat(), m)?;
        }
    }
    Ok(())
}

/// What [`SceneFile::capacity_check`] predicts: allocator emitters that want more live particles
/// than the state texture has texels, so that births will be dropped (Latta §3.4.1: a birth
/// needs a free index).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CapacityWarning {
    /// Live particles in the steady state: the sum over allocator emitters of rate × mean life
    /// (Little's law), after the first life has passed.
    pub live: f64,
    /// Texels of the state texture (`particles.size`).
    pub slots: u64,
    /// The smallest power-of-two square texture side that holds `live`.
    pub side: u32,
    /// Births per second that find no free index in the steady state: `(live - slots) / mean
    /// life`, summed as rate × (1 - slots / live).
    pub dropped_per_second: f64,
}

impl std::fmt::Display for CapacityWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the allocator emitters want about {:.0} live particles (rate × mean life) but the \
             state texture has {} texels: about {:.0} births per second will be dropped; use \
             particles.size = [{s}, {s}] or lower the rate or the life",
            self.live,
            self.slots,
            self.dropped_per_second,
            s = self.side
        )
    }
}

impl SceneFile {
    /// Predicts whether allocator births will be dropped for want of a free index: the steady
    /// state holds rate × mean life particles per allocator emitter (a uniform life in
    /// `[lo, hi]` has mean `(lo + hi) / 2`). `None` when they fit, or without allocator
    /// emitters. A pure function of the scene: `scene check` prints it, and the run's count is
    /// `ParticleSim::dropped_births`.
    pub fn capacity_check(&self) -> Option<CapacityWarning> {
        let mut live = 0.0f64;
        let mut rate = 0.0f64;
        for e in &self.emitters.allocator {
            // A curve's mean over its first life is unknown here: its peak, to be safe.
            let r = e.rate.as_ref().map_or(0.0, |r| r.bounds()[0][1].max(0.0)) as f64;
            // A life curve: its longest lives, to be safe as with the rate.
            let [lo, hi] = e.life.as_ref().map_or([0.0; 2], |l| {
                let b = l.bounds();
                [b[0][1], b[1][1]]
            });
            live += r * 0.5 * (lo as f64 + hi as f64);
            rate += r;
        }
        // Child emitters keep texels of their own: the allocator hands out the others.
        let slots = self.parent_slots();
        if live <= slots as f64 {
            return None;
        }
        let mut side = 1u32;
        while (side as f64) * (side as f64) < live && side < 1 << 16 {
            side *= 2;
        }
        Some(CapacityWarning {
            live,
            slots,
            side,
            dropped_per_second: rate * (1.0 - slots as f64 / live),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::load;

    #[test]
    fn capacity_check_predicts_the_fountain_overflowing_at_128() {
        let mut s = load("fountain").unwrap();
        assert_eq!(s.capacity_check(), None, "256² holds 12,000/s × 3 s");
        s.particles.size = [128, 128];
        let w = s.capacity_check().expect("36,000 live > 16,384 texels");
        // 12,000/s × mean life (2.5 + 3.5) / 2 = 36,000 live particles.
        assert!((w.live - 36_000.0).abs() < 1e-6, "{w:?}");
        assert_eq!((w.slots, w.side), (16_384, 256));
        let drop = 12_000.0 * (1.0 - 16_384.0 / 36_000.0);
        assert!((w.dropped_per_second - drop).abs() < 1e-6, "{w:?}");
        let text = w.to_string();
        assert!(
            text.contains("16384 texels") && text.contains("[256, 256]"),
            "{text}"
        );
        // Without allocator emitters there is nothing to predict.
        assert_eq!(load("smoke").unwrap().capacity_check(), None);
    }
}
