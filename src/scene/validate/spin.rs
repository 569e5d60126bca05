//! `collisions.spin`, `collisions.friction` and `render.rotate = "spin"`: spinning spheres
//! (UberFlow §4.5) and what they ask of the rest of the scene.

use super::{fail, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{DrawMode, RenderPath, Response, Rotate, SceneFile, UpdatePasses};

use Key::Name as N;

/// Largest friction coefficient: far beyond any material (rubber on rubber is about 1-2); a
/// larger one only says "never slip", which this already does.
const MAX_FRICTION: f32 = 100.0;

/// The spin keys: a friction coefficient in [0, [`MAX_FRICTION`]] that only spin uses, one MRT
/// pass (the spin texture is a third render target), and a sprite rotation from the spin only
/// where there is one to read.
pub(super) fn spin(s: &SceneFile) -> Check {
    let spin = s.collisions.as_ref().is_some_and(|c| c.spin);
    if let Some(c) = &s.collisions {
        let at = vec![N("collisions"), N("friction")];
        if !(0.0..=MAX_FRICTION).contains(&c.friction) {
            return fail(
                at,
                format!(
                    "friction {} is outside [0, {MAX_FRICTION}]: give a Coulomb coefficient \
                     (0 frictionless, about 0.5 for rough spheres)",
                    c.friction
                ),
            );
        }
        if c.friction > 0.0 && !c.spin {
            return fail(
                at,
                "friction between particles acts through their spin: add `spin = true` to \
                 [collisions], or remove `friction`",
            );
        }
        if c.spin && (c.response == Response::Dem || !s.forces.pair.is_empty()) {
            return fail(
                vec![N("collisions"), N("spin")],
                "the neighbour-force passes (response = \"dem\", [[forces.pair]]) carry position \
                 and velocity, not the spin: remove `spin`, or use response = \"impulse\" \
                 without pair forces",
            );
        }
        if c.spin && s.passes == UpdatePasses::Separate {
            return fail(
                vec![N("passes")],
                "spinning spheres write position, velocity and spin through multiple render \
                 targets: remove `passes = \"separate\"`",
            );
        }
    }
    if s.render.rotate == Rotate::Spin {
        let at = vec![N("render"), N("rotate")];
        if !spin {
            return fail(
                at,
                "rotate = \"spin\" turns sprites by the particles' spin: add `spin = true` to \
                 [collisions], or use rotate = \"age\"",
            );
        }
        if s.render.mode != DrawMode::Sprites {
            return fail(
                at,
                "only sprites have a rotation: set render.mode = \"sprites\", or remove `rotate`",
            );
        }
        if s.render.path != RenderPath::TextureFetch {
            return fail(
                at,
                "rotate = \"spin\" fetches the angle from the spin texture: use path = \
                 \"texture_fetch\"",
            );
        }
    }
    Ok(())
}
