//! What one [`ParticleRenderer::draw`] runs, named for the scene's pass list.

use super::ParticleRenderer;
use crate::scene::{DrawMode, DrawPrimitive, RenderPath};

impl ParticleRenderer {
    /// The passes one [`draw`](Self::draw) runs, in order, for the scene's pass list.
    pub fn pass_names(&self) -> Vec<String> {
        let s = &self.style;
        let mut names = Vec::new();
        if self.geometry.is_some() {
            names.push(if s.under() {
                "render geometry: depth only (colour kept for the under operator)".to_owned()
            } else {
                "render geometry: opaque, depth written".to_owned()
            });
        }
        if let Some(c) = &self.connected {
            names.push(c.pass_name());
            return names;
        }
        if s.soft > 0.0 && self.geometry.is_some() {
            names.push("render geometry: view depth into a float texture (soft particles)".into());
        }
        if s.path == RenderPath::VertexBuffer {
            names.push("copy positions to vertex buffer (pixel pack)".to_owned());
            names.push("copy statics to vertex buffer (pixel pack)".to_owned());
        }
        let mode = match (s.mode, s.primitive) {
            (DrawMode::Points, DrawPrimitive::Points) => "points",
            (DrawMode::Sprites, DrawPrimitive::Points) => "sprites",
            (DrawMode::Points, DrawPrimitive::Quads) => "quads",
            (DrawMode::Sprites, DrawPrimitive::Quads) => "sprite quads",
            (DrawMode::Points, DrawPrimitive::Stretched) => "stretched quads",
            (DrawMode::Sprites, DrawPrimitive::Stretched) => "stretched sprite quads",
            (DrawMode::Points, DrawPrimitive::Triangles) => "triangles",
            (DrawMode::Sprites, DrawPrimitive::Triangles) => "sprite triangles",
            (DrawMode::Surface, _) => "points (no constraint layout to draw as a surface)",
        };
        let path = match s.path {
            RenderPath::TextureFetch => "texture fetch",
            RenderPath::VertexBuffer => "vertex buffer",
        };
        let depth = if self.geometry.is_some() {
            ", depth-tested against the geometry, no depth write"
        } else {
            ""
        };
        if let Some(f) = s.fire {
            names.push(format!(
                "render {} (thesis Listing 3: texture fetch, {}), coloured by the fire's age ramp",
                if f.soft {
                    "soft round sprites"
                } else {
                    "points"
                },
                s.blend_name()
            ));
            return names;
        }
        let mut line = format!("render {mode} ({path}, {}{depth})", s.blend_name());
        if s.types.iter().any(|t| t.size_range != [1.0; 2]) {
            line.push_str(", sizes random within each type's size_range");
        }
        if self.lookup.is_some() {
            line.push_str(", through the sort's index (Latta §3.4.4: no gather)");
        }
        if self.needs_spins() {
            line.push_str(", turned by the spin's angle");
        }
        if s.mode == DrawMode::Sprites && s.types.iter().any(|t| t.flipbook.0 > 1) {
            line.push_str(", flipbooks (atlas tiles advancing with the particle's age)");
        }
        names.push(line);
        names.extend(self.ribbons.as_ref().map(|r| r.pass_name()));
        if s.under() && self.geometry.is_some() {
            names.push("composite geometry under (its own depth, equal passes)".to_owned());
        }
        if s.under() {
            names.push("composite background under".to_owned());
        }
        names
    }
}
