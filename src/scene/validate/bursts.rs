//! `bursts` of allocator and timestamp emitters: when, and how many.

use super::{fail, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{SceneFile, MAX_BURSTS};

use Key::{Index as I, Name as N};

/// At most [`MAX_BURSTS`] per emitter, at a time of at least 0 (a timestamp emitter's within
/// its first cycle), each of at least one particle; a timestamp emitter's bursts fit its texels.
pub(super) fn bursts(s: &SceneFile) -> Check {
    let em = &s.emitters;
    for (i, e) in em.initial.iter().enumerate() {
        if !e.bursts.is_empty() {
            return fail(
                vec![N("emitters"), N("initial"), I(i), N("bursts")],
                "`bursts` belong to allocator and timestamp emitters: initial emitters fill the \
                 state once, at the start",
            );
        }
    }
    // Child emitters take texels of their own (validate/children.rs): the others share the rest.
    let types = em.parents().max(1) as u64;
    let slots = s.parent_slots();
    for (kind, list) in [("allocator", &em.allocator), ("timestamp", &em.timestamp)] {
        for (i, e) in list.iter().enumerate() {
            let at = |more: &[Key]| [&[N("emitters"), N(kind), I(i), N("bursts")], more].concat();
            if e.bursts.len() > MAX_BURSTS {
                return fail(
                    at(&[I(MAX_BURSTS)]),
                    format!(
                        "{} bursts: at most {MAX_BURSTS} per emitter",
                        e.bursts.len()
                    ),
                );
            }
            for (b, burst) in e.bursts.iter().enumerate() {
                let cycle = e.cycle.unwrap_or(f32::INFINITY);
                if !(burst.time >= 0.0 && burst.time < cycle && burst.time <= 1e6) {
                    let within = if kind == "timestamp" {
                        format!(" and below the cycle of {cycle} s (it repeats every cycle)")
                    } else {
                        " and at most 1e6".to_owned()
                    };
                    return fail(
                        at(&[I(b), N("time")]),
                        format!("burst time {} s must be at least 0{within}", burst.time),
                    );
                }
                if burst.count == 0 {
                    return fail(
                        at(&[I(b), N("count")]),
                        "a burst needs a count of at least 1 particle",
                    );
                }
            }
            if kind == "timestamp" {
                // Texel k of the state is of type k mod (number of emitters).
                let texels = (slots + types - 1 - i as u64) / types;
                let total: u64 = e.bursts.iter().map(|b| b.count as u64).sum();
                if total > texels {
                    return fail(
                        at(&[]),
                        format!(
                            "the bursts ask for {total} particles, more than the {texels} texels \
                             of this emitter (a timestamp emitter's particles are its texels): \
                             lower the counts or give more particles.size"
                        ),
                    );
                }
            }
        }
    }
    Ok(())
}
