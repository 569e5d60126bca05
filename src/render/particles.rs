//! The general particle renderer: points or rotated, textured point sprites (Latta §3.4.6), fed
//! either by vertex texture fetch (thesis Listing 3) or by a vertex buffer the state textures are
//! copied into on the GPU (UberFlow §4.7, Latta §3.4.5), coloured by four keyframes of relative
//! age, blended additively, multiplicatively, or with the over / under operator.
//!
//! State layout (fixed by the simulation): particle `i` is texel `(i % width, i / width)` of every
//! state texture.
//! - positions (RGBA32F): xyz position, w remaining life in seconds. Drawn only if w > 0 and xyz
//!   is finite (dead: w <= 0 and xyz = +inf; unborn: w < 0).
//! - statics (RGBA32F): x birth time, y type (0..3), z total life (0 or +inf: permanent, relative
//!   age 0), w a random number in [0, 1) (the sprite's angle).
//!
//! Relative age = clamp(1 − position.w / statics.z, 0, 1).

use super::atlas;
use super::keyframes::KeyframeRamp;
use super::{Camera, FrameTarget};
use crate::error::{Error, Result};
use crate::gl::{
    Attribute, Blend, BlendComponent, BlendFactor, Buffer, BufferKind, BufferUsage, Context,
    Defines, Draw, DrawState, PixelPack, PointSize, Primitive, Program, Texture, VertexArray,
};
use crate::scene::{Blending, DrawMode, DrawOrder, Keyframe, Render, RenderPath};

/// How particles are drawn.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ParticleStyle {
    /// Points or sprites.
    pub mode: DrawMode,
    /// Texture fetch or vertex buffer.
    pub path: RenderPath,
    /// Point size, or the base sprite size, in pixels.
    pub point_size: f32,
    /// Opacity scale (applied to the keyframe alpha, then clamped to 1).
    pub intensity: f32,
    /// Blending.
    pub blending: Blending,
    /// Order of alpha blending (the caller draws in this order; it picks over or under).
    pub order: DrawOrder,
    /// Colour and opacity at four relative ages, ascending from 0 to 1.
    pub keyframes: [Keyframe; 4],
    /// Sprite size per particle type, relative to `point_size` (sprites only).
    pub type_scale: [f32; 4],
    /// Atlas tile (0 to 3) of each type.
    pub type_tile: [u32; 4],
    /// Background colour.
    pub background: [f32; 3],
}

/// The keyframes used when a scene gives none: white, fading out over the life.
pub fn default_keyframes() -> [Keyframe; 4] {
    let k = |age: f32, a: f32| Keyframe {
        age,
        rgba: [1.0, 1.0, 1.0, a],
    };
    [k(0.0, 1.0), k(0.5, 0.8), k(0.8, 0.4), k(1.0, 0.0)]
}

impl Default for ParticleStyle {
    fn default() -> Self {
        ParticleStyle {
            mode: DrawMode::Points,
            path: RenderPath::TextureFetch,
            point_size: 2.0,
            intensity: 1.0,
            blending: Blending::Additive,
            order: DrawOrder::BackToFront,
            keyframes: default_keyframes(),
            type_scale: [1.0; 4],
            type_tile: [0, 1, 2, 3],
            background: [0.0; 3],
        }
    }
}

impl ParticleStyle {
    /// Sets the colour and opacity keyframes that `glsl/render/keyframes.glsl` reads on `p`
    /// (bound): the renderer and the CPU engine (E5) draw with the same ramp.
    pub fn set_keyframes(&self, p: &Program) {
        let ramp = self.ramp();
        p.set_vec4("u_key_age", glam::Vec4::from_array(ramp.ages));
        for k in 0..3 {
            p.set_vec4(
                &format!("u_key_offset[{k}]"),
                glam::Vec4::from_array(ramp.offset[k]),
            );
            p.set_vec4(
                &format!("u_key_slope[{k}]"),
                glam::Vec4::from_array(ramp.slope[k]),
            );
        }
    }

    /// The blend state of this style's blending and order (the under operator for front to
    /// back). One table, so that the CPU engine (E5) blends exactly as the renderer does.
    pub fn blend(&self) -> Blend {
        use BlendFactor::{DstColor, One, OneMinusDstAlpha, OneMinusSrcAlpha, SrcAlpha, Zero};
        let (src, dst, src_a, dst_a) = match (self.blending, self.order) {
            // The destination alpha stays as cleared (opaque).
            (Blending::Additive, _) => (SrcAlpha, One, Zero, One),
            (Blending::Multiplicative, _) => (DstColor, Zero, Zero, One),
            (Blending::Alpha, DrawOrder::BackToFront) => {
                (SrcAlpha, OneMinusSrcAlpha, One, OneMinusSrcAlpha)
            }
            (Blending::Alpha, DrawOrder::FrontToBack) => {
                (OneMinusDstAlpha, One, OneMinusDstAlpha, One)
            }
        };
        Blend {
            color: BlendComponent::add(src, dst),
            alpha: BlendComponent::add(src_a, dst_a),
        }
    }

    /// The state particles (and the under operator's background) are drawn with: this style's
    /// [`blend`](Self::blend), point sizes from the vertex shader.
    pub fn draw_state(&self) -> DrawState {
        DrawState {
            blend: Some(self.blend()),
            point_size: PointSize::Program,
        }
    }

    /// The style of a scene's `[render]` section; `type_scales` are the emitters' sprite scales in
    /// type order. A keyframe list that is not exactly four long (validation rejects those; an
    /// empty list is allowed) gives [`default_keyframes`].
    pub fn from_render(r: &Render, type_scales: [f32; 4]) -> Self {
        let keyframes = match <[Keyframe; 4]>::try_from(r.keyframes.clone()) {
            Ok(k) => k,
            Err(_) => default_keyframes(),
        };
        ParticleStyle {
            mode: r.mode,
            path: r.path,
            point_size: r.point_size,
            intensity: r.intensity,
            blending: r.blending,
            order: r.order,
            keyframes,
            type_scale: type_scales,
            type_tile: [0, 1, 2, 3],
            background: r.background,
        }
    }

    /// The keyframes in the form the shader evaluates.
    pub fn ramp(&self) -> KeyframeRamp {
        KeyframeRamp::new(&self.keyframes)
    }

    /// Whether the under operator is used (alpha blending, front to back).
    pub fn under(&self) -> bool {
        self.blending == Blending::Alpha && self.order == DrawOrder::FrontToBack
    }

    /// What the target is cleared to: the background, with alpha 0 for the under operator
    /// (whose background is composited under the particles at the end of the draw, so the
    /// clear colour is transparent black), else opaque.
    pub fn clear_color(&self) -> [f32; 4] {
        if self.under() {
            [0.0; 4]
        } else {
            let [r, g, b] = self.background;
            [r, g, b, 1.0]
        }
    }

    fn blend_name(&self) -> &'static str {
        match (self.blending, self.order) {
            (Blending::Additive, _) => "additive",
            (Blending::Multiplicative, _) => "multiplicative",
            (Blending::Alpha, DrawOrder::BackToFront) => "alpha over, back to front",
            (Blending::Alpha, DrawOrder::FrontToBack) => "alpha under, front to back",
        }
    }
}

/// The vertex-buffer path's objects: the two buffers, the read framebuffer, the vertex array.
struct VertexPath {
    pack: PixelPack,
    positions: Buffer,
    statics: Buffer,
    vao: VertexArray,
}

/// Draws particles from their state textures.
pub struct ParticleRenderer {
    ctx: Context,
    style: ParticleStyle,
    width: u32,
    height: u32,
    program: Program,
    background: Program,
    empty: VertexArray,
    vertex: Option<VertexPath>,
    atlas: Option<Texture>,
}

impl std::fmt::Debug for ParticleRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "ParticleRenderer({}x{}, {:?})",
            self.width,
            self.height,
            self.pass_names()
        )
    }
}

impl ParticleRenderer {
    /// Builds the program variant for `style` and, for the vertex-buffer path, two buffers of
    /// `state_width`×`state_height` RGBA float vertices; for sprites, the atlas.
    pub fn new(
        ctx: &Context,
        style: ParticleStyle,
        state_width: u32,
        state_height: u32,
    ) -> Result<Self> {
        crate::gl::check_size(ctx, "particle state", state_width, state_height)?;
        if !(style.point_size > 0.0 && style.point_size.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "point size {} must be a finite number above 0",
                style.point_size
            )));
        }
        let mut defines = Defines::new();
        let flag = |name: &str| (name.to_owned(), "1".to_owned());
        if style.path == RenderPath::VertexBuffer {
            defines.push(flag("VERTEX_BUFFER"));
        }
        if style.mode == DrawMode::Sprites {
            defines.push(flag("SPRITES"));
        }
        match style.blending {
            Blending::Multiplicative => defines.push(flag("MULTIPLY")),
            Blending::Alpha if style.under() => defines.push(flag("PREMULTIPLIED")),
            _ => {}
        }
        let program = Program::new(
            ctx,
            "render/particle.vert",
            "render/particle.frag",
            &defines,
        )?;
        let background = Program::new(
            ctx,
            crate::gl::FULLSCREEN_VERTEX,
            "render/background.frag",
            &Defines::new(),
        )?;
        let vertex = if style.path == RenderPath::VertexBuffer {
            let bytes = state_width as u64 * state_height as u64 * 16;
            if bytes > i32::MAX as u64 {
                return Err(Error::InvalidInput(format!(
                    "particle state {state_width}x{state_height} needs vertex buffers of {bytes} \
                     bytes, over GL's limit of {} for one buffer: use the texture_fetch path or \
                     a smaller state",
                    i32::MAX
                )));
            }
            let buffer = |label| {
                Buffer::with_size(
                    ctx,
                    label,
                    BufferKind::PixelPack,
                    bytes as usize,
                    BufferUsage::StreamCopy,
                )
            };
            let positions = buffer("position vertices")?;
            let statics = buffer("static vertices")?;
            let attribute = |buffer, location| Attribute {
                buffer,
                location,
                components: 4,
                stride: 16,
                offset: 0,
            };
            let vao = VertexArray::with_attributes(
                ctx,
                "particle vertices",
                &[attribute(&positions, 0), attribute(&statics, 1)],
            )?;
            Some(VertexPath {
                pack: PixelPack::new(ctx)?,
                positions,
                statics,
                vao,
            })
        } else {
            None
        };
        let atlas = if style.mode == DrawMode::Sprites {
            Some(atlas::upload(ctx, &atlas::generate(atlas::DEFAULT_TILE))?)
        } else {
            None
        };
        Ok(ParticleRenderer {
            ctx: ctx.clone(),
            style,
            width: state_width,
            height: state_height,
            program,
            background,
            empty: VertexArray::empty(ctx, "particles")?,
            vertex,
            atlas,
        })
    }

    /// The style.
    pub fn style(&self) -> &ParticleStyle {
        &self.style
    }

    /// The sprite atlas (sprites only).
    pub fn atlas(&self) -> Option<&Texture> {
        self.atlas.as_ref()
    }

    /// Clears `target` to the background (transparent black for the under operator, whose
    /// background is composited at the end of [`draw`](Self::draw)).
    pub fn clear(&self, target: &FrameTarget) {
        target.clear_to(self.style.clear_color());
    }

    /// The passes one [`draw`](Self::draw) runs, in order, for the scene's pass list.
    pub fn pass_names(&self) -> Vec<String> {
        let s = &self.style;
        let mut names = Vec::new();
        if s.path == RenderPath::VertexBuffer {
            names.push("copy positions to vertex buffer (pixel pack)".to_owned());
            names.push("copy statics to vertex buffer (pixel pack)".to_owned());
        }
        let mode = match s.mode {
            DrawMode::Points => "points",
            DrawMode::Sprites => "sprites",
        };
        let path = match s.path {
            RenderPath::TextureFetch => "texture fetch",
            RenderPath::VertexBuffer => "vertex buffer",
        };
        names.push(format!("render {mode} ({path}, {})", s.blend_name()));
        if s.under() {
            names.push("composite background under".to_owned());
        }
        names
    }

    fn check_state(&self, what: &str, t: &Texture) -> Result<()> {
        if t.width() != self.width || t.height() != self.height {
            return Err(Error::InvalidInput(format!(
                "{what} texture is {}x{}, the renderer was made for {}x{}",
                t.width(),
                t.height(),
                self.width,
                self.height
            )));
        }
        if !t.format().is_float() || t.format().channels() != 4 {
            return Err(Error::InvalidInput(format!(
                "{what} texture is {}: the renderer reads RGBA floats",
                t.format().name()
            )));
        }
        Ok(())
    }

    /// Draws particles `0..count` in index order into `target` (not cleared first; see
    /// [`clear`](Self::clear)). Alpha blending needs them already in the style's order (a GPU
    /// sort rearranges the state). With the under operator the background is composited under
    /// the particles at the end, which leaves the frame opaque.
    pub fn draw(
        &self,
        target: &FrameTarget,
        positions: &Texture,
        statics: &Texture,
        camera: &Camera,
        count: usize,
    ) -> Result<()> {
        self.check_state("position", positions)?;
        self.check_state("statics", statics)?;
        let texels = self.width as usize * self.height as usize;
        if count > texels {
            return Err(Error::InvalidInput(format!(
                "{count} particles to draw from a state of {texels}"
            )));
        }
        let s = &self.style;
        if let (Some(v), true) = (&self.vertex, count > 0) {
            let rows = count.div_ceil(self.width as usize) as u32;
            v.pack.copy_rows(positions, &v.positions, rows)?;
            v.pack.copy_rows(statics, &v.statics, rows)?;
        }
        let p = &self.program;
        p.bind();
        let vertices = match &self.vertex {
            Some(v) => &v.vao,
            None => {
                positions.bind(0);
                statics.bind(1);
                p.set_i32("u_position", 0);
                p.set_i32("u_static", 1);
                p.set_i32("u_width", self.width as i32);
                &self.empty
            }
        };
        if let Some(atlas) = &self.atlas {
            atlas.bind(2);
            p.set_i32("u_atlas", 2);
        }
        let aspect = target.width() as f32 / target.height() as f32;
        p.set_mat4("u_view_proj", &camera.view_projection(aspect));
        p.set_f32("u_point_size", s.point_size);
        p.set_f32("u_intensity", s.intensity);
        p.set_vec4("u_type_scale", glam::Vec4::from_array(s.type_scale));
        let t = s.type_tile.map(|t| t.min(3) as i32);
        p.set_ivec4("u_type_tile", t);
        s.set_keyframes(p);
        let state = s.draw_state();
        let gl = &self.ctx;
        gl.draw(&Draw {
            program: p,
            target: target.framebuffer(),
            viewport: None,
            vertices,
            primitive: Primitive::Points,
            count: count as u32,
            state: &state,
        });
        if s.under() {
            let b = &self.background;
            b.bind();
            b.set_vec3("u_background", glam::Vec3::from_array(s.background));
            // The same blend state: the under operator composites the background last.
            gl.draw(&Draw {
                program: b,
                target: target.framebuffer(),
                viewport: None,
                vertices: &self.empty,
                primitive: Primitive::Triangles,
                count: 3,
                state: &state,
            });
        }
        gl.check_error("drawing particles")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(ages: [f32; 4], rgba: [[f32; 4]; 4]) -> [Keyframe; 4] {
        std::array::from_fn(|i| Keyframe {
            age: ages[i],
            rgba: rgba[i],
        })
    }

    #[test]
    fn style_from_render() {
        let mut r = Render::default();
        let s = ParticleStyle::from_render(&r, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.keyframes, default_keyframes());
        assert_eq!(s.type_scale, [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.clear_color(), [0.0, 0.0, 0.0, 1.0]);
        // The default ramp is white and fades out.
        let ramp = s.ramp();
        assert_eq!(ramp.eval(0.0), [1.0; 4]);
        assert!(ramp.eval(1.0)[3].abs() < 1e-6);
        r.keyframes = keys([0.0, 0.3, 0.6, 1.0], [[0.5; 4]; 4]).to_vec();
        r.blending = Blending::Alpha;
        r.order = DrawOrder::FrontToBack;
        r.background = [0.2, 0.3, 0.4];
        let s = ParticleStyle::from_render(&r, [1.0; 4]);
        assert_eq!(s.keyframes[1].age, 0.3);
        assert!(s.under());
        assert_eq!(s.clear_color(), [0.0; 4]);
    }
}
