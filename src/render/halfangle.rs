//! Lit smoke by half-angle slicing (Kniss et al. 2003, "A model for volumetric lighting";
//! Green 2008, "Volumetric particle shadows"): the particles, sorted along the vector halfway
//! between the light's and the view's direction, are drawn in slices; each slice is first drawn
//! into the frame, every fragment lit by the transmittance the slices before it left in a light
//! buffer, then into the light buffer, attenuating it. Both orders hold within a slice: along
//! the half-angle vector, the particles nearest the light come first, and for the eye either
//! the nearest (the light behind the viewer: the under operator) or the farthest (the light
//! facing the viewer: the over operator).
//!
//! The light buffer is an RGBA16F texture holding the transmittance (1 cleared, times 1 − α
//! for every particle drawn over a texel), in an orthographic view along the light centred on
//! the camera's target. A sprite casts a square of the size it has in the scene at its own
//! depth, facing the light.

use glam::{Mat4, Vec3};

use super::{blend_of, clear_of, Camera, FrameState, FrameTarget, ParticleStyle, RenderParams};
use crate::error::{Error, Result};
use crate::gl::{
    Blend, BlendComponent, BlendFactor, Context, Defines, Depth, Draw, DrawState, Framebuffer,
    PointSize, Primitive, Program, Sampled, Texture, TextureDesc, TextureFormat, Uniform,
    VertexArray,
};
use crate::scene::{Blending, DrawMode, DrawOrder, LightSection};

/// A slice draw's uniforms.
type FrameUniforms = Vec<(&'static str, Uniform)>;
/// The axis half-angle slicing sorts along, and the order the eye sees it in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfAngle {
    /// Unit vector: particles are drawn in ascending `dot(x, axis)`, nearest the light first.
    pub axis: Vec3,
    /// The eye looks the way the light goes: ascending order is front to back for the eye too
    /// (the under operator); else back to front (the over operator).
    pub front_to_back: bool,
}

impl HalfAngle {
    /// Kniss et al.: with `view` the direction the camera looks in and `light` the one the light
    /// travels in, the half-angle vector is normalize(view + light) when they point the same
    /// way (dot ≥ 0), else normalize(light − view), the view flipped.
    pub fn new(view: Vec3, light: Vec3) -> Self {
        let (v, l) = (view.normalize(), light.normalize());
        let front_to_back = v.dot(l) >= 0.0;
        let axis = if front_to_back { v + l } else { l - v };
        HalfAngle {
            axis: axis.normalize(),
            front_to_back,
        }
    }

    /// The half-angle of `camera` and the scene's light.
    pub fn of(camera: &Camera, light: &LightSection) -> Self {
        HalfAngle::new(camera.target - camera.eye(), Vec3::from(light.direction))
    }
}

/// The light buffer's view: scene to its [-1, 1]² along the light, centred on `centre`,
/// `extent` scene units from the centre to each edge. Its x axis is horizontal (perpendicular
/// to +y, or for a vertical light to +z).
pub fn light_view(direction: Vec3, centre: Vec3, extent: f32) -> Mat4 {
    let l = direction.normalize();
    let up = if l.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    Mat4::from_scale(Vec3::splat(1.0 / extent)) * Mat4::look_to_rh(centre, l, up)
}

/// The blends and clear of one frame's slices ([`HalfAngleRenderer::slice_draws`]).
#[derive(Debug, Clone, Copy)]
pub struct SliceDraws {
    /// The eye passes composite front to back (the under operator).
    pub under: bool,
    /// The eye passes' blend.
    pub eye_blend: Blend,
    /// What the frame is cleared to before the eye passes.
    pub eye_clear: [f32; 4],
    /// The light passes' blend into the light buffer.
    pub light_blend: Blend,
}

impl SliceDraws {
    /// The eye passes' and the light passes' draw state: their blends, one-pixel points (the
    /// slices draw quads), no depth.
    pub fn states(&self) -> (DrawState, DrawState) {
        let eye = DrawState {
            blend: Some(self.eye_blend),
            point_size: PointSize::One,
            depth: Depth::Off,
            color_writes: true,
        };
        let light = DrawState {
            blend: Some(self.light_blend),
            ..eye
        };
        (eye, light)
    }
}

/// The eye and light passes' own fragment stages.
const OWN_FRAGMENTS: [&str; 2] = ["render/halfangle_eye.frag", "render/halfangle_light.frag"];

/// The particle renderer's lit variant: the same look (keyframes, sprites, sizes), drawn in
/// slices along the half-angle vector.
pub struct HalfAngleRenderer {
    ctx: Context,
    style: ParticleStyle,
    /// The numbers its uniforms carry, packed once from the style.
    params: RenderParams,
    light: LightSection,
    slices: u32,
    extent: f32,
    buffer: Framebuffer,
    eye: Program,
    shadow: Program,
    background: Program,
    empty: VertexArray,
    /// Both passes' fragment stage replaced ([`with_fragment`](Self::with_fragment)): each
    /// draw gives the programs only the textures and uniforms they declare.
    replaced: bool,
}

impl std::fmt::Debug for HalfAngleRenderer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "HalfAngleRenderer({} slices)", self.slices)
    }
}

/// Which passes of the slices [`HalfAngleRenderer::draw_passes`] runs (the benchmark times
/// them apart).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SlicePasses {
    /// Both, interleaved: the frame.
    Both,
    /// Only the eye passes (on the light buffer as it is).
    Eye,
    /// Only the light-buffer passes.
    Light,
}

impl HalfAngleRenderer {
    /// Builds the programs of `style` (points or sprites, drawn as quads) and a light buffer of
    /// the light's resolution covering `extent` scene units around the camera's target.
    pub fn new(
        ctx: &Context,
        style: ParticleStyle,
        light: &LightSection,
        slices: u32,
        extent: f32,
    ) -> Result<Self> {
        if slices == 0 || !(extent > 0.0 && extent.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "half-angle slicing needs at least one slice and an extent above 0 (got {slices} \
                 slices, extent {extent})"
            )));
        }
        let side = light.resolution;
        crate::gl::check_size(ctx, "light buffer (render.light.resolution)", side, side)?;
        let [eye, shadow] = Self::programs(ctx, &style, OWN_FRAGMENTS, &Defines::new())?;
        let background = Program::new(
            ctx,
            crate::gl::FULLSCREEN_VERTEX,
            "render/background.frag",
            &Defines::new(),
        )?;
        let texture = Texture::new(
            ctx,
            TextureDesc {
                width: side,
                height: side,
                format: TextureFormat::Rgba16F,
                label: "light buffer",
            },
        )?;
        Ok(HalfAngleRenderer {
            ctx: ctx.clone(),
            params: RenderParams::of(&style),
            style,
            light: light.clone(),
            slices,
            extent,
            buffer: Framebuffer::new(ctx, "light buffer", vec![texture])?,
            eye,
            shadow,
            background,
            empty: VertexArray::empty(ctx, "half-angle slices")?,
            replaced: false,
        })
    }

    /// The same slices (the same quads through the same vertex stage, the same targets, blends
    /// and order) with `fragment` as both passes' fragment stage and a light buffer of its own:
    /// the benchmarks' fill floor (`bench/fill_floor.frag`) reads no atlas and no light.
    pub fn with_fragment(&self, fragment: &str) -> Result<Self> {
        let mut r = self.again()?;
        [r.eye, r.shadow] = Self::programs(&self.ctx, &self.style, [fragment; 2], &Defines::new())?;
        r.replaced = true;
        Ok(r)
    }

    /// The same slices and passes with their colours made ones that change no pixel under
    /// their blends (`SHADE_FLOOR`), and a light buffer of their own that the light passes
    /// leave as cleared: the benchmarks' shading floor, what the slices cost but for the
    /// blends their colours make.
    pub fn shading_floor(&self) -> Result<Self> {
        let mut r = self.again()?;
        let floor: Defines = vec![("SHADE_FLOOR".into(), "1".into())];
        [r.eye, r.shadow] = Self::programs(&self.ctx, &self.style, OWN_FRAGMENTS, &floor)?;
        Ok(r)
    }

    /// A renderer of the same style, light and slices, with a light buffer of its own.
    fn again(&self) -> Result<Self> {
        Self::new(
            &self.ctx,
            self.style.clone(),
            &self.light,
            self.slices,
            self.extent,
        )
    }

    /// The eye and light passes' programs of `style` with fragment stages `[eye, light]`
    /// under `defines`.
    fn programs(
        ctx: &Context,
        style: &ParticleStyle,
        [eye, light]: [&str; 2],
        defines: &Defines,
    ) -> Result<[Program; 2]> {
        let mut defines = defines.clone();
        if style.mode == DrawMode::Sprites {
            defines.push(("SPRITES".into(), "1".into()));
        }
        let eye = Program::new(ctx, "render/halfangle.vert", eye, &defines)?;
        defines.push(("LIGHT_PASS".into(), "1".into()));
        let light = Program::new(ctx, "render/halfangle.vert", light, &defines)?;
        Ok([eye, light])
    }

    /// The light buffer: transmittance in r after the last draw.
    pub fn light_buffer(&self) -> &Framebuffer {
        &self.buffer
    }

    /// The light.
    pub fn light(&self) -> &LightSection {
        &self.light
    }

    /// The number of slices.
    pub fn slices(&self) -> u32 {
        self.slices
    }

    /// Particles per slice drawn, for `count` particles: ⌈count / slices⌉ (the last slice short).
    fn batch(&self, count: usize) -> usize {
        count.div_ceil(self.slices as usize).max(1)
    }

    /// Slices drawn for `count` particles (each an eye and a light pass): at most `slices`,
    /// fewer where there are fewer particles than slices.
    pub fn slices_drawn(&self, count: usize) -> usize {
        count.div_ceil(self.batch(count))
    }

    /// The passes one draw runs, as the pass list words them.
    pub fn pass_names(&self) -> Vec<String> {
        self.passes().into_iter().map(|p| p.name).collect()
    }

    /// The passes one draw runs, each with its programs: at most `slices` eye and light passes
    /// (fewer where fewer particles can be live), the background only under.
    pub fn passes(&self) -> Vec<crate::gl::PassInfo> {
        use crate::gl::PassInfo;
        let side = self.light.resolution;
        let n = self.slices as u64;
        let mut slices = PassInfo::new(
            "render",
            format!(
                "{} slices along the half-angle vector, each: eye pass (quads lit by the light \
                 buffer's transmittance, alpha over or under) then light pass (quads facing the \
                 light, transmittance times 1 - opacity)",
                self.slices
            ),
        )
        .draws(&self.eye, n)
        .draws(&self.shadow, n);
        slices.varies = true;
        let mut background = PassInfo::new(
            "render",
            "composite background under (when the eye looks the way the light goes)",
        )
        .draws(&self.background, 1);
        background.varies = true;
        vec![
            PassInfo::new(
                "render",
                format!("clear light buffer ({side}x{side} RGBA16F, transmittance 1)"),
            ),
            slices,
            background,
        ]
    }

    /// The light buffer's view for `camera`.
    pub fn light_view(&self, camera: &Camera) -> Mat4 {
        light_view(Vec3::from(self.light.direction), camera.target, self.extent)
    }

    /// Clears `target` and the light buffer and draws particles `0..state.count`, already
    /// sorted along [`HalfAngle::of`] `camera`, in slices of equal counts.
    pub fn draw(
        &self,
        target: &FrameTarget,
        state: &FrameState<'_>,
        camera: &Camera,
        atlas: Option<&Texture>,
    ) -> Result<()> {
        self.draw_passes(target, state, camera, atlas, SlicePasses::Both)
    }

    /// What the slices seen from `camera` draw with: the eye passes' blend and clear (the under
    /// operator where the slices run front to back for the eye, else the over operator, from
    /// the one blend table of the particle passes) and the light passes' blend (the
    /// transmittance multiplied by 1 − the colour). The benchmarks' floors read the same.
    pub fn slice_draws(&self, camera: &Camera) -> SliceDraws {
        let under = HalfAngle::of(camera, &self.light).front_to_back;
        let order = if under {
            DrawOrder::FrontToBack
        } else {
            DrawOrder::BackToFront
        };
        let keep = BlendComponent::add(BlendFactor::Zero, BlendFactor::OneMinusSrcColor);
        SliceDraws {
            under,
            eye_blend: blend_of(Blending::Alpha, order),
            eye_clear: clear_of(under, self.params.background.to_array()),
            light_blend: Blend {
                color: keep,
                alpha: keep,
            },
        }
    }

    /// [`draw`](Self::draw), running only `passes` of each slice (the eye passes without the
    /// light passes read the light buffer as it was left).
    pub fn draw_passes(
        &self,
        target: &FrameTarget,
        state: &FrameState<'_>,
        camera: &Camera,
        atlas: Option<&Texture>,
        passes: SlicePasses,
    ) -> Result<()> {
        let draws = self.slice_draws(camera);
        if passes != SlicePasses::Eye {
            self.buffer.clear([1.0; 4]);
        }
        if passes != SlicePasses::Light {
            target.clear_to(draws.eye_clear);
        }
        let (mut eye_frame, frame) = self.frame_uniforms(target, state, camera, atlas)?;
        eye_frame.push(("u_premultiplied", Uniform::I32(draws.under as i32)));
        let (eye_state, light_state) = draws.states();
        let mut textures: Vec<(&str, Sampled)> = vec![
            ("u_position", state.positions.into()),
            ("u_static", state.statics.into()),
        ];
        if let Some(a) = atlas {
            textures.push(("u_atlas", a.into()));
        }
        let mut shadow_textures = textures.clone();
        textures.push(("u_light", self.buffer.only_texture().into()));
        let mut frame = frame;
        if self.replaced {
            // Once a frame, not once a slice: a floor's draws cost the CPU what the slices' do.
            let (eye, shadow) = (&self.eye, &self.shadow);
            eye_frame.retain(|(name, _)| eye.declares(name));
            textures.retain(|(name, _)| eye.declares(name));
            frame.retain(|(name, _)| shadow.declares(name));
            shadow_textures.retain(|(name, _)| shadow.declares(name));
        }
        let batch = self.batch(state.count);
        let mut first = 0;
        while first < state.count {
            let n = batch.min(state.count - first);
            if passes != SlicePasses::Light {
                let fb = target.framebuffer();
                let eye = (&self.eye, &eye_frame[..]);
                self.slice(eye, &textures, fb, (first, n), &eye_state);
            }
            if passes != SlicePasses::Eye {
                let fb = &self.buffer;
                let shadow = (&self.shadow, &frame[..]);
                self.slice(shadow, &shadow_textures, fb, (first, n), &light_state);
            }
            first += n;
        }
        if draws.under && passes != SlicePasses::Light {
            self.ctx.draw(&Draw {
                program: &self.background,
                target: target.framebuffer(),
                viewport: None,
                vertices: &self.empty,
                primitive: Primitive::Triangles,
                count: 3,
                state: &eye_state,
                textures: &[],
                uniforms: &[("u_background", Uniform::Vec3(self.params.background))],
            });
        }
        self.ctx.check_error("drawing half-angle slices")
    }

    /// Draws particles `first..first + n` of the sorted state with `program` and this frame's
    /// uniforms, reading `textures`.
    fn slice(
        &self,
        (program, frame): (&Program, &[(&str, Uniform)]),
        textures: &[(&str, Sampled)],
        fb: &Framebuffer,
        (first, n): (usize, usize),
        st: &DrawState,
    ) {
        self.ctx.draw(&Draw {
            program,
            target: fb,
            viewport: None,
            vertices: &self.empty,
            primitive: Primitive::Triangles,
            count: (n * super::QUAD_VERTICES) as u32,
            state: st,
            textures,
            uniforms: &[frame, &[("u_first", Uniform::I32(first as i32))]].concat(),
        });
    }

    /// Checks this frame's state and returns the uniforms of the eye's and the light's draws:
    /// the frame's own (the camera, the light's view, the clock) and the look's.
    fn frame_uniforms(
        &self,
        target: &FrameTarget,
        state: &FrameState<'_>,
        camera: &Camera,
        atlas: Option<&Texture>,
    ) -> Result<(FrameUniforms, FrameUniforms)> {
        let (positions, statics) = (state.positions, state.statics);
        if positions.texels() < state.count || statics.texels() < state.count {
            return Err(Error::InvalidInput(format!(
                "{} particles to draw from a state of {}",
                state.count,
                positions.texels()
            )));
        }
        if self.style.mode == DrawMode::Sprites && atlas.is_none() && !self.replaced {
            return Err(Error::InvalidInput("lit sprites need the atlas".into()));
        }
        let b = &self.params;
        let (w, h) = (target.width() as f32, target.height() as f32);
        let view = camera.view();
        let light_view = self.light_view(camera);
        let mut frame = vec![
            ("u_view_proj", Uniform::Mat4(camera.view_projection(w / h))),
            ("u_viewport", Uniform::Vec2(glam::Vec2::new(w, h))),
            ("u_proj_y", Uniform::F32(camera.projection(w / h).y_axis.y)),
            ("u_camera_right", Uniform::Vec3(view.row(0).truncate())),
            ("u_camera_up", Uniform::Vec3(view.row(1).truncate())),
            ("u_light_view", Uniform::Mat4(light_view)),
            ("u_time", Uniform::F32(state.time)),
            ("u_width", Uniform::I32(positions.width() as i32)),
            ("u_light_scale", Uniform::F32(1.0 / self.extent)),
            ("u_density", Uniform::F32(self.light.density)),
        ];
        frame.extend(b.size_uniforms());
        frame.extend(b.type_uniforms());
        frame.extend(b.keyframe_uniforms());
        let mut eye = frame.clone();
        let l = &self.light;
        eye.extend([
            ("u_light_colour", Uniform::Vec3(Vec3::from_array(l.colour))),
            ("u_ambient", Uniform::Vec3(Vec3::from_array(l.ambient))),
        ]);
        Ok((eye, frame))
    }
}
