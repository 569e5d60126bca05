//! Child trails drawn as ribbons (`render.trails = "ribbon"`; as bevy_hanabi's ribbons, Unity's
//! trails, Niagara's ribbon renderer): camera-facing quads between consecutive children of one
//! parent's trail. No sort by birth time: a trail's texels are a ring in birth order
//! (`glsl/sim/child_birth.glsl`), so the ring's neighbours are the pairs to connect; the vertex
//! stage (`glsl/render/ribbon.vert`) fetches both ends and drops a pair that is not two live
//! children born one trail interval apart. The index buffer is built once on the CPU.

use super::{Camera, FrameState, FrameTarget, ParticleStyle, RenderParams};
use crate::error::{Error, Result};
use crate::gl::{
    Buffer, BufferKind, BufferUsage, Context, Draw, DrawState, Primitive, Program, Uniform,
    VertexArray,
};
use crate::scene::ChildLayout;

/// Vertices of one ribbon segment: two triangles.
pub const SEGMENT_VERTICES: u32 = 6;

/// Child ranges a ribbon index can name (2 bits; particle types are at most 4).
const MAX_RANGES: usize = 4;

/// The index buffer's entries for `layout`: per trail segment (ring texel `a` to its successor),
/// six vertices numbered `((a·2 + wrap)·4 + range)·8 + corner`, which `ribbon.vert` decodes.
/// Ranges without a trail, or of fewer than 2 trail texels, have no segment.
pub fn indices(layout: &ChildLayout) -> Result<Vec<u32>> {
    if layout.ranges.len() > MAX_RANGES || layout.used() >= 1 << 26 {
        return Err(Error::InvalidInput(format!(
            "ribbons name at most {MAX_RANGES} child emitters of 2^26 texels; this layout has \
             {} of {} texels: use fewer child emitters or particles, or trails = \"none\"",
            layout.ranges.len(),
            layout.used()
        )));
    }
    let mut out = Vec::new();
    for (r, range) in layout.ranges.iter().enumerate() {
        let ring = range.per_parent.saturating_sub(range.on_death);
        if range.trail_rate <= 0.0 || ring < 2 {
            continue;
        }
        for p in 0..layout.parent_slots {
            let first = range.start + p * range.per_parent + range.on_death;
            for k in 0..ring {
                let wrap = u32::from(k + 1 == ring);
                let base = (((first + k) * 2 + wrap) * 4 + r as u32) * 8;
                out.extend((0..SEGMENT_VERTICES).map(|c| base + c));
            }
        }
    }
    Ok(out)
}

/// Draws the ribbons of a scene's trails, after its particles, in their blend.
pub struct RibbonRenderer {
    ctx: Context,
    program: Program,
    vao: VertexArray,
    // Kept alive: the vertex array reads it.
    _indices: Buffer,
    count: u32,
    ring: [i32; MAX_RANGES],
    gap: [f32; MAX_RANGES],
    width_m: f32,
}

impl std::fmt::Debug for RibbonRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RibbonRenderer({} vertices)", self.count)
    }
}

impl RibbonRenderer {
    /// The program each draw runs, for the pass list.
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// Builds the index buffer for `layout` and the program for `style`'s blend; `dt` is the
    /// scene's step, at least the integration step (births fall on steps, so consecutive
    /// children may be up to one trail interval plus a step apart); `width_m`: `render.ribbon_width`, or 0 for the point size.
    pub fn new(
        ctx: &Context,
        layout: &ChildLayout,
        style: &ParticleStyle,
        dt: f32,
        width_m: Option<f32>,
    ) -> Result<Self> {
        let list = indices(layout)?;
        if list.is_empty() {
            return Err(Error::InvalidInput(
                "trails = \"ribbon\" found no trail of 2 texels or more to draw: give a child \
                 emitter a trail_rate and per_parent at least on_death + 2"
                    .into(),
            ));
        }
        let bytes: Vec<u8> = list.iter().flat_map(|i| i.to_ne_bytes()).collect();
        let buffer = Buffer::with_data(
            ctx,
            "ribbon indices",
            BufferKind::Vertex,
            &bytes,
            BufferUsage::StaticDraw,
        )?;
        let vao = VertexArray::with_indices(ctx, "ribbons", &[], &buffer)?;
        let defines = style.blend_defines();
        let program = Program::new(ctx, "render/ribbon.vert", "render/ribbon.frag", &defines)?;
        let mut ring = [0; MAX_RANGES];
        let mut gap = [0.0; MAX_RANGES];
        for (r, range) in layout.ranges.iter().enumerate() {
            ring[r] = range.per_parent.saturating_sub(range.on_death) as i32;
            if range.trail_rate > 0.0 {
                // A step of slack, and a little for the rounding of the remaining lives.
                gap[r] = 1.0 / range.trail_rate + dt * 1.01 + 1e-5;
            }
        }
        Ok(RibbonRenderer {
            ctx: ctx.clone(),
            program,
            vao,
            _indices: buffer,
            count: list.len() as u32,
            ring,
            gap,
            width_m: width_m.unwrap_or(0.0),
        })
    }

    /// The pass's name in the scene's pass list.
    pub fn pass_name(&self) -> String {
        format!(
            "render trail ribbons (texture fetch over an index buffer: a quad between \
             consecutive trail children, {} segments, drawn where both live and were born one \
             trail interval apart)",
            self.count / SEGMENT_VERTICES
        )
    }

    /// Draws the ribbons of `state` into `target` with `draw_state` (the particles').
    pub fn draw(
        &self,
        target: &FrameTarget,
        state: &FrameState<'_>,
        camera: &Camera,
        params: &RenderParams,
        draw_state: &DrawState,
    ) -> Result<()> {
        let p = &self.program;
        let aspect = target.width() as f32 / target.height() as f32;
        let viewport = glam::Vec2::new(target.width() as f32, target.height() as f32);
        // The camera and the clock change from frame to frame: they travel with the draw.
        let mut per_frame = vec![
            ("u_view_proj", Uniform::Mat4(camera.view_projection(aspect))),
            ("u_viewport", Uniform::Vec2(viewport)),
            ("u_eye", Uniform::Vec3(camera.eye())),
            ("u_time", Uniform::F32(state.time)),
            ("u_ribbon_width", Uniform::F32(self.width_m)),
            ("u_sprites", Uniform::I32(i32::from(params.sprites))),
            ("u_width", Uniform::I32(state.positions.width() as i32)),
            ("u_ring", Uniform::I32s(self.ring[..].into())),
            ("u_gap", Uniform::F32s(self.gap[..].into())),
        ];
        per_frame.extend(params.size_uniforms());
        per_frame.extend(params.type_uniforms());
        per_frame.extend(params.keyframe_uniforms());
        self.ctx.draw(&Draw {
            program: p,
            target: target.framebuffer(),
            viewport: None,
            vertices: &self.vao,
            primitive: Primitive::Triangles,
            count: self.count,
            state: draw_state,
            textures: &[
                ("u_position", state.positions.into()),
                ("u_static", state.statics.into()),
            ],
            uniforms: &per_frame,
        });
        self.ctx.check_error("drawing ribbons")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::ChildRange;

    #[test]
    fn indices_close_each_ring() {
        let range = ChildRange {
            start: 2,
            per_parent: 4,
            parent: 0,
            kind: 1,
            on_death: 1,
            trail_rate: 10.0,
        };
        let layout = ChildLayout {
            parent_slots: 2,
            ranges: vec![range],
        };
        let firsts: Vec<u32> = (indices(&layout).unwrap().chunks(6))
            .map(|c| c[0] / 8)
            .collect();
        // Parent 0's ring is texels 3, 4, 5; parent 1's 7, 8, 9; the last of each wraps.
        let want: Vec<u32> = [(3, 0), (4, 0), (5, 1), (7, 0), (8, 0), (9, 1)]
            .iter()
            .map(|(a, w)| (a * 2 + w) * 4)
            .collect();
        assert_eq!(firsts, want);
    }
}
