//! What one [`ParticleRenderer::draw`] runs, named for the scene's pass list.

use super::ParticleRenderer;
use crate::gl::PassInfo;
use crate::scene::{DrawMode, DrawPrimitive, RenderPath};

/// A render pass that draws `program` once.
fn pass(name: impl Into<String>, program: &crate::gl::Program) -> PassInfo {
    PassInfo::new("render", name).draws(program, 1)
}

impl ParticleRenderer {
    /// The passes one [`draw`](Self::draw) runs, in order, for the scene's pass list.
    pub fn pass_names(&self) -> Vec<String> {
        self.passes().into_iter().map(|p| p.name).collect()
    }

    /// The passes one [`draw`](Self::draw) runs, in order, each with the program it draws.
    pub fn passes(&self) -> Vec<PassInfo> {
        let s = &self.style;
        let mut names = Vec::new();
        if let Some(g) = &self.geometry {
            names.push(pass(
                if s.under() {
                    "render geometry: depth only (colour kept for the under operator)"
                } else {
                    "render geometry: opaque, depth written"
                },
                g.program(),
            ));
        }
        if let Some(c) = &self.connected {
            names.push(pass(c.pass_name(), c.program()));
            return names;
        }
        if s.soft > 0.0 && self.geometry.is_some() {
            let mut p = PassInfo::new(
                "render",
                "render geometry: view depth into a float texture (soft particles)",
            );
            p.add(&crate::render::GeometryRenderer::depth_program_name(), 1);
            names.push(p);
        }
        if s.path == RenderPath::VertexBuffer {
            // Pixel packs: copies into buffers, not draws.
            names.push(PassInfo::new(
                "render",
                "copy positions to vertex buffer (pixel pack)",
            ));
            names.push(PassInfo::new(
                "render",
                "copy statics to vertex buffer (pixel pack)",
            ));
        }
        let program = match &self.lookup {
            Some((p, _)) => p,
            None => &self.program,
        };
        names.push(pass(self.particle_line(), program));
        if s.fire.is_some() {
            return names;
        }
        names.extend(
            self.ribbons
                .as_ref()
                .map(|r| pass(r.pass_name(), r.program())),
        );
        if let (true, Some(g)) = (s.under(), &self.geometry) {
            names.push(pass(
                "composite geometry under (its own depth, equal passes)",
                g.program(),
            ));
        }
        if s.under() {
            names.push(pass("composite background under", &self.background));
        }
        names
    }

    /// The particles' draw, in the pass list's words.
    fn particle_line(&self) -> String {
        let s = &self.style;
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
            return format!(
                "render {} (thesis Listing 3: texture fetch, {}), coloured by the fire's age ramp",
                if f.soft {
                    "soft round sprites"
                } else {
                    "points"
                },
                s.blend_name()
            );
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
        line
    }
}
