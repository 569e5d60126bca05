//! The particle type's look as curves of the emitter's time (`sprite_scale`, `tint`): the
//! renderer evaluates them per particle at its birth time (`glsl/render/birth_curves.glsl`), so a
//! curve has at most [`MAX_BIRTH_KEYS`] keys (uniforms per type), and its range over the curve's
//! bounds must make a size above 0 and colour factors of at least 0.

use super::curves::{check, over};
use super::{fail, Check};
use crate::scene::curve::{Animated, CurveValue};
use crate::scene::locate::Key;
use crate::scene::schema::{DrawMode, Emitter, SceneFile, StateModel, MAX_BIRTH_KEYS};

use Key::{Index as I, Name as N};

/// `sprite_scale` and `tint` of the emitter at `at` of kind `kind`.
pub(super) fn type_curves(s: &SceneFile, at: &[Key], kind: &str, e: &Emitter) -> Check {
    let key = |k| [at, &[N(k)]].concat();
    form(key("sprite_scale"), &e.sprite_scale)?;
    form(key("tint"), &e.tint)?;
    let [lo, hi] = e.sprite_scale.bounds()[0];
    if !(lo > 0.0 && hi.is_finite()) {
        return fail(
            key("sprite_scale"),
            format!(
                "sprite_scale must be a finite number above 0{}; it reaches {lo}",
                over(&e.sprite_scale)
            ),
        );
    }
    for (i, [lo, hi]) in e.tint.bounds().into_iter().enumerate() {
        if !(lo >= 0.0 && hi.is_finite()) {
            let channel = ["red", "green", "blue", "alpha"][i];
            return fail(
                key("tint"),
                format!(
                    "tint is a factor of the keyframes' colour and opacity, at least 0 in every \
                     channel{}; its {channel} reaches {lo}",
                    over(&e.tint)
                ),
            );
        }
    }
    if s.render.mode == DrawMode::Surface && e.tint != Animated::Constant([1.0; 4]) {
        return fail(
            key("tint"),
            "tint colours the particles' points and sprites, but mode = \"surface\" draws the \
             connected surface: leave it out, or draw points or sprites",
        );
    }
    let curve = [
        ("sprite_scale", e.sprite_scale.curve()),
        ("tint", e.tint.curve()),
    ];
    let Some((name, _)) = curve.into_iter().find(|(_, c)| c.is_some()) else {
        return Ok(());
    };
    // Each particle keeps the value at its birth: every initial particle is born at time 0.
    if kind == "initial" {
        return fail(
            key(name),
            format!(
                "`{name}` is a curve, but an initial emitter's particles are all born at time 0: \
                 give a constant, or emit over time with [[emitters.allocator]] or \
                 [[emitters.timestamp]]"
            ),
        );
    }
    if s.simulation == StateModel::Stateless {
        return fail(
            key(name),
            format!(
                "`{name}` is a curve, but a stateless simulation keeps no birth time per \
                 particle: give a constant, or use simulation = \"stateful\""
            ),
        );
    }
    Ok(())
}

/// A curve's own form (`curves::check`) and at most [`MAX_BIRTH_KEYS`] keys.
fn form<T: CurveValue>(at: Vec<Key>, v: &Animated<T>) -> Check {
    check::<T>(at.clone(), Some(v))?;
    match v.curve() {
        Some(c) if c.keys.len() > MAX_BIRTH_KEYS => fail(
            [&at[..], &[N("keys"), I(MAX_BIRTH_KEYS)]].concat(),
            format!(
                "{} keys: the renderer evaluates this curve per particle from at most \
                 {MAX_BIRTH_KEYS} keys; merge keys, or use the periodic and noise terms",
                c.keys.len()
            ),
        ),
        _ => Ok(()),
    }
}
