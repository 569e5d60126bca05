//! `[render]` options of the drawing itself: the index lookup (Latta §3.4.4).

use super::{fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{Blending, DrawMode, Lookup, RenderPath, SceneFile};

use Key::Name as N;

/// `render.lookup`: the index lookup draws through the sort of alpha blending, by texture fetch.
pub(super) fn options(s: &SceneFile) -> Check {
    let r = &s.render;
    if r.lookup == Lookup::Index {
        let at = path(&[N("render"), N("lookup")]);
        let why = if r.blending != Blending::Alpha || s.fire.is_some() {
            "draws through the sort of alpha blending, and this scene does not sort: use \
             blending = \"alpha\", or remove the key"
        } else if r.path != RenderPath::TextureFetch {
            "fetches each particle's state at the id the sort texture names: use path = \
             \"texture_fetch\", or lookup = \"gather\" with the vertex buffer"
        } else if r.mode == DrawMode::Surface {
            "is for points and sprites: the surface draws the layout unsorted"
        } else {
            return Ok(());
        };
        return fail(at, format!("lookup = \"index\" {why}"));
    }
    Ok(())
}
