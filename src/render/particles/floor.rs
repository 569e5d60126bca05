//! The benchmarks' floors of a render pass drawn by the same renderer: the fill floor (its
//! fragment stages replaced by one that writes a constant and fetches nothing) and the shading
//! floor (its own fragment stage, every fetch and computation, writing a colour that its blend
//! leaves unchanged).

use super::ParticleRenderer;
use crate::error::Result;
use crate::gl::{Defines, Program};

impl ParticleRenderer {
    /// This renderer with its fragment stage replaced by `fragment` and no atlas: the same
    /// vertex stage (points, sprites, quads, their sizes), blend and passes, for a benchmark's
    /// fill floor whose fragments write a constant and fetch nothing. The colliders' geometry is
    /// drawn as the renderer draws it (its depth hides the same fragments); a connected render
    /// (a surface, strands) keeps its vertex stage and depth write, its fragments `fragment`.
    pub fn with_fragment(&self, fragment: &str) -> Result<Self> {
        let mut r = self.replaced(fragment, &[], "render/particle.vert".into())?;
        r.atlas = None;
        if let Some(c) = &self.connected {
            r.set_connected(c.with_fragment(fragment)?);
        }
        Ok(r)
    }

    /// This renderer with its own fragment stage built with `SHADE_FLOOR`: every fragment
    /// shaded as the pass shades it (the atlas fetch, the keyframes, the soft depth, the fire's
    /// ramp), its colour then multiplied by a zero the compiler cannot see, so that the blend
    /// leaves the frame as it was. The benchmarks' shading floor: what the pass costs but for
    /// the blends its colours make. `None` for a connected render (a surface, strands), whose
    /// fragment stage is not the particles'.
    pub fn shading_floor(&self) -> Result<Option<Self>> {
        if self.connected.is_some() {
            return Ok(None);
        }
        let floor = [("SHADE_FLOOR".to_owned(), "1".to_owned())];
        // The pass's own vertex stage, a user colour's included.
        let vertex = match &self.style.user_color {
            Some(u) => u.root(),
            None => "render/particle.vert".into(),
        };
        let mut r = self.replaced("render/particle.frag", &floor, vertex)?;
        r.atlas = self.atlas.clone();
        Ok(Some(r))
    }

    /// A renderer of the same style, geometry and index lookup whose particle program is
    /// `vertex` and `fragment` (its index lookup's, `render/particle.vert` and `fragment`),
    /// built with the style's defines and `extra`.
    fn replaced(&self, fragment: &str, extra: &[(String, String)], vertex: String) -> Result<Self> {
        let mut defines: Defines = super::super::style::style_defines(&self.ctx, &self.style)?;
        defines.extend(extra.iter().cloned());
        let mut r = Self::new(&self.ctx, self.style.clone(), self.width, self.height)?;
        r.program = Program::new(&self.ctx, &vertex, fragment, &defines)?;
        if let Some((_, layout)) = &self.lookup {
            let mut d = defines.clone();
            d.extend(layout.defines());
            let p = Program::new(&self.ctx, "render/particle.vert", fragment, &d)?;
            r.lookup = Some((p, *layout));
        }
        // The same geometry, moved colliders and all (its style already tests depth).
        r.geometry = self.geometry.clone();
        Ok(r)
    }
}
