//! `render.trails = "ribbon"`: ribbons between consecutive trail children of one parent
//! (`src/render/ribbons.rs`), and their `render.ribbon_width`.

use super::{fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{Blending, DrawMode, RenderPath, SceneFile, Trails};

use Key::Name as N;

/// Ribbons need trails to connect, and the texture-fetch path of points or sprites.
pub(super) fn ribbons(s: &SceneFile) -> Check {
    let r = &s.render;
    if let Some(w) = r.ribbon_width {
        let at = path(&[N("render"), N("ribbon_width")]);
        if r.trails != Trails::Ribbon {
            return fail(
                at,
                "ribbon_width is the width of trails = \"ribbon\": set trails, or remove the key",
            );
        }
        if !(w > 0.0 && w.is_finite()) {
            return fail(
                at,
                format!("ribbon_width {w} must be a finite number of metres above 0"),
            );
        }
    }
    if r.trails != Trails::Ribbon {
        return Ok(());
    }
    let at = path(&[N("render"), N("trails")]);
    let trails = (s.emitters.child.iter()).any(|c| c.trail_rate.is_some_and(|t| t > 0.0));
    let why = if !trails {
        "connects the children of a trail: add an [[emitters.child]] with trail_rate above 0, \
         or remove the key"
    } else if r.path != RenderPath::TextureFetch {
        "fetches each ribbon end's state from the textures: use path = \"texture_fetch\", or \
         remove the key"
    } else if r.mode == DrawMode::Surface {
        "is for points and sprites: use mode = \"points\" or \"sprites\", or remove the key"
    } else if r.blending == Blending::Alpha {
        // Ribbons are one unsorted batch over the simulation's own layout: alpha blending's
        // gathered (re-ordered) state and its depth order, lit or not, do not fit them.
        "is drawn in one unsorted batch after the particles: use blending = \"additive\" or \
         \"multiplicative\", or remove the key"
    } else if r.color.is_some() {
        "colours ribbons by the keyframes, not by render.color: remove one of the two keys"
    } else {
        return Ok(());
    };
    fail(at, format!("trails = \"ribbon\" {why}"))
}
