//! Emitter values given as curves (`src/scene/curve.rs`): the curve's own form (keys present,
//! ascending, of the value's length; periods and frequencies above 0) and the emitter kinds and
//! simulations that can follow a value changing in time. The value's range is checked by the
//! emitter's checks over the curve's bounds.

use super::{duration, fail, Check};
use crate::scene::curve::{Animated, Components, Curve, CurveValue};
use crate::scene::locate::Key;
use crate::scene::schema::{Emitter, EmitterKind, SceneFile, StateModel};

use Key::{Index as I, Name as N};

/// The emitter's keys that may be curves, by name.
fn animated(e: &Emitter) -> [(&'static str, Option<&Curve>); 7] {
    [
        ("rate", e.rate.as_ref().and_then(Animated::curve)),
        ("life", e.life.as_ref().and_then(Animated::curve)),
        ("center", e.center.curve()),
        ("radius", e.radius.curve()),
        ("direction", e.direction.curve()),
        ("cone_degrees", e.cone_degrees.curve()),
        ("speed", e.speed.curve()),
    ]
}

/// Whether any emitter of the scene has a curve (the GPU then sets its spawn uniforms every
/// step).
pub fn has_curves(s: &SceneFile) -> bool {
    s.emitters
        .all()
        .any(|e| animated(e).iter().any(|(_, c)| c.is_some()))
}

/// The curves of the emitter at `at` of kind `kind`: well formed, and where a curve can act.
pub(super) fn emitter_curves(s: &SceneFile, at: &[Key], ek: EmitterKind, e: &Emitter) -> Check {
    let (key, kind) = (|k| [at, &[N(k)]].concat(), ek.key());
    check::<f32>(key("rate"), e.rate.as_ref())?;
    check::<[f32; 3]>(key("center"), Some(&e.center))?;
    check::<f32>(key("radius"), Some(&e.radius))?;
    check::<[f32; 3]>(key("direction"), Some(&e.direction))?;
    check::<f32>(key("cone_degrees"), Some(&e.cone_degrees))?;
    check::<[f32; 2]>(key("speed"), Some(&e.speed))?;
    check::<[f32; 2]>(key("life"), e.life.as_ref())?;
    if e.life.as_ref().and_then(Animated::curve).is_some() && !ek.life_per_birth() {
        // Time stamps and children draw a texel's life once, into the static texture the
        // integration pass only reads: a later birth could not take the curve's value.
        return fail(
            key("life"),
            format!(
                "`life` is a curve, but a {kind} emitter draws each texel's life once, at the \
                 start: give a constant [min, max], or emit with [[emitters.allocator]]"
            ),
        );
    }
    let Some((name, _)) = animated(e).into_iter().find(|(_, c)| c.is_some()) else {
        return Ok(());
    };
    if !ek.spawns_over_time() {
        return fail(
            key(name),
            format!(
                "`{name}` is a curve, but an initial emitter spawns once at time 0: give a \
                 constant, or emit over time with [[emitters.allocator]] or \
                 [[emitters.timestamp]]"
            ),
        );
    }
    if s.simulation == StateModel::Stateless {
        return fail(
            key(name),
            format!(
                "`{name}` is a curve, but a stateless simulation recomputes every particle from \
                 the emitter's constants: give a constant, or use simulation = \"stateful\""
            ),
        );
    }
    Ok(())
}

/// One value's curve, if it is one: keys present, finite, ascending and of `T`'s length; the
/// terms' amplitudes of a matching length, periods and frequencies above 0.
pub(super) fn check<T: CurveValue>(at: Vec<Key>, v: Option<&Animated<T>>) -> Check {
    let Some(c) = v.and_then(Animated::curve) else {
        return Ok(());
    };
    let sub = |k: &[Key]| [&at[..], k].concat();
    if c.keys.is_empty() {
        return fail(
            sub(&[N("keys")]),
            "a curve needs at least one key: keys = [[time, value], ...]",
        );
    }
    for (i, (t, value)) in c.keys.iter().enumerate() {
        let here = sub(&[N("keys"), I(i)]);
        if !t.is_finite() || value.0.iter().any(|x| !x.is_finite()) {
            return fail(here, "curve keys must be finite numbers");
        }
        if T::from_components(&value.0).is_none() {
            return fail(
                here,
                format!(
                    "key {i} has {} numbers: give [time, value] with a value of {}",
                    value.0.len(),
                    T::WHAT
                ),
            );
        }
        if i > 0 && *t <= c.keys[i - 1].0 {
            return fail(
                here,
                format!(
                    "key times must ascend: key {i} at {t} s is not after key {} at {} s",
                    i - 1,
                    c.keys[i - 1].0
                ),
            );
        }
    }
    if let Some(p) = &c.periodic {
        amplitude::<T>(sub(&[N("periodic"), N("amplitude")]), &p.amplitude)?;
        if !(p.period.is_finite() && p.period > 0.0) {
            return fail(
                sub(&[N("periodic"), N("period")]),
                format!("period {} s must be above 0", p.period),
            );
        }
        if !p.phase.is_finite() {
            return fail(sub(&[N("periodic"), N("phase")]), "phase must be finite");
        }
    }
    if let Some(n) = &c.noise {
        amplitude::<T>(sub(&[N("noise"), N("amplitude")]), &n.amplitude)?;
        if !(n.frequency.is_finite() && n.frequency > 0.0 && n.frequency <= 1e3) {
            return fail(
                sub(&[N("noise"), N("frequency")]),
                format!(
                    "noise frequency {} must lie in (0, 1000] values per second",
                    n.frequency
                ),
            );
        }
    }
    Ok(())
}

/// An amplitude: one finite number, or (vectors) one per component.
fn amplitude<T: CurveValue>(at: Vec<Key>, a: &Components) -> Check {
    let fits = a.0.len() == 1 || (!T::SHARED && a.0.len() == T::LEN);
    if !fits {
        let want = if T::SHARED {
            "one number".to_owned()
        } else {
            format!("one number or {}", T::WHAT)
        };
        return fail(
            at,
            format!("amplitude has {} numbers: give {want}", a.0.len()),
        );
    }
    if a.0.iter().any(|x| !x.is_finite()) {
        return fail(at, "amplitude must be finite");
    }
    Ok(())
}

/// `life`: [min, max] with 0 < min <= max at every key (min and max share the terms, so the
/// order holds between keys) and min above 0 over the curve's bounds; the longest life a time
/// the state can store.
pub(super) fn life(at: Vec<Key>, life: &Animated<[f32; 2]>) -> Check {
    let keys = match life {
        Animated::Constant(v) => vec![*v],
        Animated::Curve(c) => c.key_values::<[f32; 2]>(),
    };
    let [lo, _] = life.bounds()[0];
    if !(lo > 0.0 && keys.iter().all(|v| v[0] <= v[1])) {
        return fail(
            at,
            format!("life must be [min, max] with 0 < min <= max{}", over(life)),
        );
    }
    let longest = life.bounds()[1][1];
    match life {
        Animated::Constant(_) => duration([&at[..], &[I(1)]].concat(), "life", longest),
        Animated::Curve(_) => duration(at, "life", longest),
    }
}

/// "over its curve" for a curve's range errors, nothing for a constant's.
pub(super) fn over<T>(v: &Animated<T>) -> &'static str {
    match v {
        Animated::Constant(_) => "",
        Animated::Curve(_) => {
            " over the curve's range (its keys' extremes widened by the periodic and noise \
             amplitudes)"
        }
    }
}
