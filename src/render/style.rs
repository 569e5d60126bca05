//! How particles look: the style of a scene's `[render]` section and of each emitter's particle
//! type (Latta §3.4.6: size, rotation, colour and opacity keyframes per type), its blending, and
//! the program variant's defines; `src/render/params.rs` packs its numbers for `glsl/render/`.

use super::keyframes::KeyframeRamp;
use super::sprite::SizeCurve;
use crate::error::{Error, Result};
use crate::gl::{Blend, BlendComponent, BlendFactor, Context, Defines};
use crate::scene::curve::{Animated, Curve};
use crate::scene::{
    Blending, DrawMode, DrawOrder, DrawPrimitive, Keyframe, Render, RenderPath, Rotate, SceneFile,
};

/// The keyframes given, or `None` when there are none.
fn given(keys: &[Keyframe]) -> Option<Vec<Keyframe>> {
    (!keys.is_empty()).then(|| keys.to_vec())
}

/// How particles are drawn.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ParticleStyle {
    /// Points or sprites.
    pub mode: DrawMode,
    /// One point, a camera-facing quad or a velocity-stretched quad per particle (Latta §3.4.5).
    pub primitive: DrawPrimitive,
    /// Exposure of stretched quads in seconds: from x − v·stretch to x.
    pub stretch: f32,
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
    /// Colour and opacity at 1 to 8 relative ages, ascending (the types without their own).
    pub keyframes: Vec<Keyframe>,
    /// What each particle type (emitter) looks like.
    pub types: [TypeLook; 4],
    /// Background colour.
    pub background: [f32; 3],
    /// Whether particles are depth-tested against drawn geometry (`render.geometry`); they
    /// never write depth, so none hides another and the blending alone composites them.
    pub depth_test: bool,
    /// What turns sprites: each type's rotation speed over the age, or the simulation's spin
    /// ([`FrameState::spins`](super::FrameState::spins)).
    #[serde(skip_serializing_if = "by_age")]
    pub rotate: Rotate,
    /// The thesis's fire look instead of keyframes: each particle coloured by its own age ramp
    /// (Listing 3), its age from the fire's state (see [`FireRamp`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fire: Option<FireRamp>,
    /// `render.color`: the colour by the user's expression of the user states.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub user_color: Option<super::user_color::UserColor>,
    /// Soft particles (`render.soft`): metres in front of the drawn geometry over which the
    /// opacity fades to 0; 0 is off.
    #[serde(skip_serializing_if = "is_off")]
    pub soft: f32,
}

fn is_off(v: &f32) -> bool {
    *v == 0.0
}

/// The fire's colouring, a variant of the one particle renderer: white-yellow at birth, orange,
/// red, fading out, additive. The statics the renderer is given are the fire's velocities,
/// whose w is the wait; a particle's total life is `max_age` − wait, its relative age
/// 1 − remaining life / total life (`glsl/render/fire_ramp.glsl`).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FireRamp {
    /// The fire's cycle length (`fire.max_age`).
    pub max_age: f32,
    /// Soft round sprites (`render.mode = "sprites"`), opacity (1 − r²)² to the rim, instead of
    /// the thesis's square points (it names their look a flaw, §4.1, §4.5.1).
    pub soft: bool,
}

/// The keyframes used when a scene gives none: white, fading out over the life.
pub fn default_keyframes() -> Vec<Keyframe> {
    let k = |age: f32, a: f32| Keyframe {
        age,
        rgba: [1.0, 1.0, 1.0, a],
    };
    vec![k(0.0, 1.0), k(0.5, 0.8), k(0.8, 0.4), k(1.0, 0.0)]
}

/// What one particle type (one emitter) looks like (Latta §3.4.6: the particle type's
/// parameters). Scale, rotation and size over life apply to sprites only.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TypeLook {
    /// Sprite size relative to `point_size` (with `scale_curve`, unused).
    pub scale: f32,
    /// `sprite_scale` as a curve of the emitter's time: each particle takes its value at its
    /// birth (`glsl/render/birth_curves.glsl`), in place of `scale`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scale_curve: Option<Curve>,
    /// `tint`: a factor of the keyframes' colour and opacity, a constant or a curve of the
    /// emitter's time taken at each particle's birth.
    #[serde(skip_serializing_if = "is_white")]
    pub tint: Animated<[f32; 4]>,
    /// Atlas tile (0 to 3).
    pub tile: u32,
    /// Rotation speed range [min, max] in degrees per second.
    pub spin: [f32; 2],
    /// Size over life (times `scale`).
    pub size: SizeCurve,
    /// This type's own colour keyframes, or `None`: the style's.
    pub keyframes: Option<Vec<Keyframe>>,
    /// Range of the random size factor per particle (Latta §3.4.6); [1, 1]: none.
    pub size_range: [f32; 2],
    /// Flipbook: tiles (1: none) and tiles per second of age (0: the tiles over the life).
    pub flipbook: (u32, f32),
}

fn is_white(t: &Animated<[f32; 4]>) -> bool {
    *t == Animated::Constant([1.0; 4])
}

impl TypeLook {
    /// The sprite scale: `scale`, or the curve.
    pub fn sprite_scale(&self) -> Animated<f32> {
        match &self.scale_curve {
            Some(c) => Animated::Curve(c.clone()),
            None => Animated::Constant(self.scale),
        }
    }

    /// Type `k`'s default: scale 1, tile k, no rotation, constant size, the style's keyframes.
    pub fn new(k: u32) -> Self {
        TypeLook {
            scale: 1.0,
            scale_curve: None,
            tint: Animated::Constant([1.0; 4]),
            tile: k,
            spin: [0.0; 2],
            size: SizeCurve::default(),
            keyframes: None,
            size_range: [1.0; 2],
            flipbook: (1, 0.0),
        }
    }
}

impl Default for ParticleStyle {
    fn default() -> Self {
        ParticleStyle {
            mode: DrawMode::Points,
            primitive: DrawPrimitive::Points,
            stretch: 1.0 / 30.0,
            path: RenderPath::TextureFetch,
            point_size: 2.0,
            intensity: 1.0,
            blending: Blending::Additive,
            order: DrawOrder::BackToFront,
            keyframes: default_keyframes(),
            types: std::array::from_fn(|k| TypeLook::new(k as u32)),
            background: [0.0; 3],
            depth_test: false,
            rotate: Rotate::Age,
            fire: None,
            user_color: None,
            soft: 0.0,
        }
    }
}

fn by_age(r: &Rotate) -> bool {
    *r == Rotate::Age
}

impl ParticleStyle {
    /// The blend state of this style's blending and order (the under operator for front to
    /// back). One table ([`blend_of`]), so that the CPU engine (E5) and the half-angle slices
    /// blend exactly as the renderer does.
    pub fn blend(&self) -> Blend {
        blend_of(self.blending, self.order)
    }

    /// The style of a scene's `[render]` section; `type_scales` are the emitters' sprite scales in
    /// type order. An empty keyframe list gives [`default_keyframes`].
    pub fn from_render(r: &Render, type_scales: [f32; 4]) -> Self {
        ParticleStyle {
            mode: r.mode,
            primitive: r.primitive,
            stretch: r.stretch,
            path: r.path,
            point_size: r.point_size,
            intensity: r.intensity,
            blending: r.blending,
            order: r.order,
            keyframes: given(&r.keyframes).unwrap_or_else(default_keyframes),
            types: std::array::from_fn(|k| TypeLook {
                scale: type_scales[k],
                ..TypeLook::new(k as u32)
            }),
            background: r.background,
            depth_test: r.geometry,
            rotate: r.rotate,
            fire: None,
            user_color: None,
            soft: r.soft,
        }
    }

    /// The style of a whole scene: `[render]`, and each emitter's look (its type): sprite scale,
    /// tile, rotation speed, size over life and keyframes.
    pub fn from_scene(scene: &SceneFile) -> Self {
        let mut style = ParticleStyle::from_render(&scene.render, [1.0; 4]);
        if let Some(f) = &scene.fire {
            // The fire's sprites are soft discs of its ramp, not atlas tiles.
            style.fire = Some(FireRamp {
                max_age: f.max_age,
                soft: scene.render.mode == DrawMode::Sprites,
            });
            style.mode = DrawMode::Points;
            return style;
        }
        style.user_color = super::user_color::UserColor::of(scene);
        for (k, e) in scene.emitters.all().take(4).enumerate() {
            style.types[k] = TypeLook {
                scale: e.sprite_scale.at(0.0),
                scale_curve: e.sprite_scale.curve().cloned(),
                tint: e.tint.clone(),
                tile: e.tile.unwrap_or(k as u32),
                spin: e.rotation_speed.unwrap_or([0.0; 2]),
                size: SizeCurve::from_points(&e.size_over_life),
                keyframes: given(&e.keyframes),
                size_range: e.size_range.unwrap_or([1.0; 2]),
                flipbook: e
                    .flipbook
                    .map_or((1, 0.0), |f| (f.frames, f.rate.unwrap_or(0.0))),
            };
        }
        style
    }

    /// Whether some type has its own keyframes (the CPU engine, E5, draws one set).
    pub fn keyframes_per_type(&self) -> bool {
        self.types.iter().any(|t| t.keyframes.is_some())
    }

    /// Type `t`'s keyframes in the form the shader evaluates.
    pub fn ramp_of(&self, t: usize) -> KeyframeRamp {
        KeyframeRamp::new(self.types[t].keyframes.as_ref().unwrap_or(&self.keyframes))
    }

    /// The style's own keyframes (types without their own) in the form the shader evaluates.
    pub fn ramp(&self) -> KeyframeRamp {
        KeyframeRamp::new(&self.keyframes)
    }

    /// The fragment stage's defines for this blending (`MULTIPLY`, `PREMULTIPLIED`), shared with
    /// the CPU engine's points.
    pub fn blend_defines(&self) -> crate::gl::Defines {
        let flag = |name: &str| (name.to_owned(), "1".to_owned());
        match self.blending {
            Blending::Multiplicative => vec![flag("MULTIPLY")],
            Blending::Alpha if self.under() => vec![flag("PREMULTIPLIED")],
            Blending::Alpha | Blending::Additive => Vec::new(),
        }
    }

    /// The widest particle in pixels: `point_size` times the largest random size factor, for
    /// sprites also times the largest type scale and size-over-life scale.
    pub fn largest_size(&self) -> f32 {
        let widest = self
            .types
            .iter()
            .map(|t| {
                let sprite = if self.mode == DrawMode::Sprites {
                    let scale = t.sprite_scale().bounds()[0][1];
                    scale * t.size.scales.iter().copied().fold(0.0, f32::max)
                } else {
                    1.0
                };
                sprite * t.size_range[1].max(t.size_range[0])
            })
            .fold(0.0, f32::max);
        self.point_size * widest
    }

    /// Whether the under operator is used (alpha blending, front to back).
    pub fn under(&self) -> bool {
        self.blending == Blending::Alpha && self.order == DrawOrder::FrontToBack
    }

    /// What the target is cleared to: the background, with alpha 0 for the under operator
    /// (whose background is composited under the particles at the end of the draw, so the
    /// clear colour is transparent black), else opaque ([`clear_of`]).
    pub fn clear_color(&self) -> [f32; 4] {
        clear_of(self.under(), self.background)
    }

    /// The blending's name, as pass lists print it.
    pub fn blend_name(&self) -> &'static str {
        match (self.blending, self.order) {
            (Blending::Additive, _) => "additive",
            (Blending::Multiplicative, _) => "multiplicative",
            (Blending::Alpha, DrawOrder::BackToFront) => "alpha over, back to front",
            (Blending::Alpha, DrawOrder::FrontToBack) => "alpha under, front to back",
        }
    }
}

/// Checks `style` against what the pipeline and this driver can draw, and gives the defines of
/// its program variant.
pub(super) fn style_defines(ctx: &Context, style: &ParticleStyle) -> Result<Defines> {
    if !(style.point_size > 0.0 && style.point_size.is_finite()) {
        return Err(Error::InvalidInput(format!(
            "point size {} must be a finite number above 0",
            style.point_size
        )));
    }
    if style.primitive != DrawPrimitive::Points && style.path != RenderPath::TextureFetch {
        return Err(Error::InvalidInput(
            "triangles, quads and stretched quads replicate each particle's vertex by \
             fetching its texel (Latta §3.4.5): use path = \"texture_fetch\""
                .into(),
        ));
    }
    if !(style.stretch >= 0.0 && style.stretch.is_finite()) {
        return Err(Error::InvalidInput(format!(
            "stretch {} must be a finite number of seconds, at least 0",
            style.stretch
        )));
    }
    let largest = style.largest_size();
    let [_, max_point] = ctx.limits().point_size_range;
    if style.primitive == DrawPrimitive::Points && largest > max_point {
        return Err(Error::InvalidInput(format!(
            "sprites up to {largest} pixels wide exceed this driver's largest point, {max_point} \
             pixels (GL_ALIASED_POINT_SIZE_RANGE): use render.primitive = \"quads\", which has \
             no such limit, or a smaller point_size"
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
    if style.soft > 0.0 {
        defines.push(flag("SOFT"));
    }
    if let Some(f) = style.fire {
        defines.push(flag("FIRE_RAMP"));
        if f.soft {
            defines.push(flag("FIRE_SOFT"));
        }
    }
    if style.rotate == Rotate::Spin {
        if style.path != RenderPath::TextureFetch {
            return Err(Error::InvalidInput(
                "sprites turned by the spin fetch it from the spin texture: use path = \
                 \"texture_fetch\""
                    .into(),
            ));
        }
        defines.push(flag("ROTATE_SPIN"));
    }
    match style.primitive {
        DrawPrimitive::Points => {}
        DrawPrimitive::Quads => defines.push(flag("QUADS")),
        DrawPrimitive::Stretched => defines.push(flag("STRETCHED")),
        DrawPrimitive::Triangles => defines.push(flag("TRIANGLES")),
    }
    defines.extend(style.blend_defines());
    Ok(defines)
}

/// The blend state of a blending and a draw order: the one table of the particle passes'
/// blends (the under operator for alpha front to back, the over operator back to front).
pub fn blend_of(blending: Blending, order: DrawOrder) -> Blend {
    use BlendFactor::{DstColor, One, OneMinusDstAlpha, OneMinusSrcAlpha, SrcAlpha, Zero};
    let (src, dst, src_a, dst_a) = match (blending, order) {
        // The destination alpha stays as cleared (opaque).
        (Blending::Additive, _) => (SrcAlpha, One, Zero, One),
        (Blending::Multiplicative, _) => (DstColor, Zero, Zero, One),
        (Blending::Alpha, DrawOrder::BackToFront) => {
            (SrcAlpha, OneMinusSrcAlpha, One, OneMinusSrcAlpha)
        }
        (Blending::Alpha, DrawOrder::FrontToBack) => (OneMinusDstAlpha, One, OneMinusDstAlpha, One),
    };
    Blend {
        color: BlendComponent::add(src, dst),
        alpha: BlendComponent::add(src_a, dst_a),
    }
}

/// What a frame is cleared to: transparent black under the under operator (the background is
/// composited under the particles at the end), else the opaque background.
pub fn clear_of(under: bool, background: [f32; 3]) -> [f32; 4] {
    if under {
        [0.0; 4]
    } else {
        let [r, g, b] = background;
        [r, g, b, 1.0]
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
        assert_eq!(s.types.each_ref().map(|t| t.scale), [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(s.types.each_ref().map(|t| t.tile), [0, 1, 2, 3]);
        assert!(!s.keyframes_per_type());
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

    #[test]
    fn style_from_scene_takes_each_emitters_look() {
        let src = crate::scene::builtin_source("fountain").expect("a built-in scene");
        let mut scene = crate::scene::parse("fountain", src).expect("valid");
        let e = scene.emitters.all().count();
        assert!(e >= 1);
        let first = scene
            .emitters
            .allocator
            .iter_mut()
            .chain(scene.emitters.timestamp.iter_mut())
            .chain(scene.emitters.initial.iter_mut())
            .next()
            .unwrap();
        first.rotation_speed = Some([10.0, 20.0]);
        first.size_over_life = vec![[0.0, 1.0], [1.0, 3.0]];
        first.keyframes = keys([0.0, 0.3, 0.6, 1.0], [[0.25; 4]; 4]).to_vec();
        let s = ParticleStyle::from_scene(&scene);
        assert_eq!(s.types[0].spin, [10.0, 20.0]);
        assert_eq!(s.types[0].size.eval(0.5), 2.0);
        assert!(s.keyframes_per_type());
        assert_eq!(s.ramp_of(0).eval(0.5), [0.25; 4]);
        assert_eq!(s.ramp_of(3), s.ramp());
    }
}
