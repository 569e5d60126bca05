//! `[render]` options of the drawing itself and its sort: the index lookup (Latta §3.4.4) and
//! the order of a spread sort's passes, soft particles.

use super::{fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{Blending, DrawMode, Lookup, RenderPath, SceneFile, Spread, Variant};

use Key::Name as N;

/// `render.lookup`: the index lookup draws through the sort of alpha blending, by texture fetch.
pub(super) fn options(s: &SceneFile) -> Check {
    let r = &s.render;
    if r.lookup == Lookup::Index {
        let at = path(&[N("render"), N("lookup")]);
        let why = if r.blending != Blending::Alpha || s.fire.is_some() {
            Some(
                "draws through the sort of alpha blending, and this scene does not sort: use \
                 blending = \"alpha\", or remove the key",
            )
        } else if r.path != RenderPath::TextureFetch {
            Some(
                "fetches each particle's state at the id the sort texture names: use path = \
                 \"texture_fetch\", or lookup = \"gather\" with the vertex buffer",
            )
        } else if r.mode == DrawMode::Surface {
            Some("is for points and sprites: the surface draws the layout unsorted")
        } else {
            None
        };
        // An accepted lookup goes on to the checks of soft particles and the spread below.
        if let Some(why) = why {
            return fail(at, format!("lookup = \"index\" {why}"));
        }
    }
    if r.soft != 0.0 {
        let at = path(&[N("render"), N("soft")]);
        if !(r.soft > 0.0 && r.soft.is_finite()) {
            return fail(
                at,
                format!(
                    "soft {} must be a finite number of metres above 0 (0: off)",
                    r.soft
                ),
            );
        }
        if !r.geometry || s.fire.is_some() || r.mode == DrawMode::Surface {
            return fail(
                at,
                "soft fades particles near the drawn geometry: set geometry = true (points or \
                 sprites), or remove the key",
            );
        }
    }
    let sort = &r.sort;
    if sort.spread == Spread::Local {
        let at = path(&[N("render"), N("sort"), N("spread")]);
        if sort.passes_per_frame.is_none() {
            return fail(
                at,
                "spread = \"local\" orders the passes of a sort spread over frames: set \
                 passes_per_frame, or remove the key",
            );
        }
        if sort.variant.is_some_and(|v| v != Variant::OddEven) {
            return fail(
                at,
                "spread = \"local\" re-runs the odd-even merge sort's first stages, whose runs \
                 all ascend: use variant = \"oddeven\"",
            );
        }
    }
    Ok(())
}
