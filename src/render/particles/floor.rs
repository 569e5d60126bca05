//! The benchmarks' fill floor of a render pass: the same renderer, its fragment stages replaced
//! by one that writes a constant and fetches nothing.

use super::ParticleRenderer;
use crate::error::Result;
use crate::gl::Program;

impl ParticleRenderer {
    /// This renderer with its fragment stage replaced by `fragment` and no atlas: the same
    /// vertex stage (points, sprites, quads, their sizes), blend and passes, for a benchmark's
    /// fill floor whose fragments write a constant and fetch nothing. The colliders' geometry is
    /// drawn as the renderer draws it (its depth hides the same fragments); a connected render
    /// (a surface, strands) keeps its vertex stage and depth write, its fragments `fragment`.
    pub fn with_fragment(&self, fragment: &str) -> Result<Self> {
        let defines = super::super::style::style_defines(&self.ctx, &self.style)?;
        let mut r = Self::new(&self.ctx, self.style.clone(), self.width, self.height)?;
        r.program = Program::new(&self.ctx, "render/particle.vert", fragment, &defines)?;
        r.atlas = None;
        if let Some((_, layout)) = &self.lookup {
            let mut d = defines.clone();
            d.extend(layout.defines());
            let p = Program::new(&self.ctx, "render/particle.vert", fragment, &d)?;
            r.lookup = Some((p, *layout));
        }
        // The same geometry, moved colliders and all (its style already tests depth).
        r.geometry = self.geometry.clone();
        if let Some(c) = &self.connected {
            r.set_connected(c.with_fragment(fragment)?);
        }
        Ok(r)
    }
}
