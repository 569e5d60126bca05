//! The render parameter block: every number the particle renderer's uniforms carry, packed once
//! from the scene's style ([`ParticleStyle::from_scene`]). The particle renderer, its ribbons,
//! the half-angle renderer and the CPU engine's point draw upload this block and nothing else of
//! the style's numbers, so the scene is encoded for `glsl/render/` in one place. Each field names
//! the uniforms it becomes.

use glam::{Vec3, Vec4};

use super::birth_curves::BirthCurves;
use super::keyframes::MAX_KEYFRAMES;
use super::ParticleStyle;
use crate::gl::{Blend, Depth, DrawState, PointSize, Uniform};
use crate::scene::DrawMode;

/// The uniforms of the particle look (`glsl/render/particle.vert`, `particle.frag` and what they
/// include), packed from a [`ParticleStyle`].
#[derive(Debug, Clone, PartialEq)]
pub struct RenderParams {
    /// Point size, or the base sprite size, in pixels: `u_point_size`.
    pub point_size: f32,
    /// Opacity scale of the keyframe alpha: `u_intensity`.
    pub intensity: f32,
    /// The fire's cycle length, for its ramp (`None` without a fire): `u_max_age`.
    pub max_age: Option<f32>,
    /// Exposure of stretched quads in seconds: `u_stretch`.
    pub stretch: f32,
    /// Soft particles' fade distance in metres (0: off): `u_soft`.
    pub soft: f32,
    /// Whether ribbons take the sprites' look: `u_sprites`.
    pub sprites: bool,
    /// The background colour: `u_background`.
    pub background: Vec3,
    /// What the target is cleared to ([`ParticleStyle::clear_color`]).
    pub clear_color: [f32; 4],
    /// The blend state ([`ParticleStyle::blend`]).
    pub blend: Blend,
    /// Each type's colour keyframes, two ages per vec4 pair: `u_key_age`.
    pub key_age: Vec<Vec4>,
    /// Each type's keyframe segments, colour at age 0: `u_key_offset`.
    pub key_offset: Vec<Vec4>,
    /// Each type's keyframe segments, colour per unit of age: `u_key_slope`.
    pub key_slope: Vec<Vec4>,
    /// Each type's atlas tile (0 to 3): `u_type_tile`.
    pub tile: [i32; 4],
    /// Each type's slowest rotation, radians per second: `u_spin_min`.
    pub spin_min: Vec4,
    /// Each type's fastest rotation, radians per second: `u_spin_max`.
    pub spin_max: Vec4,
    /// Each type's smallest random size factor: `u_size_min`.
    pub size_min: Vec4,
    /// Each type's largest random size factor: `u_size_max`.
    pub size_max: Vec4,
    /// Each type's flipbook tiles: `u_flip_frames`.
    pub flip_frames: Vec4,
    /// Each type's flipbook tiles per second of age: `u_flip_rate`.
    pub flip_rate: Vec4,
    /// Each type's size-over-life ages: `u_size_age`.
    pub size_age: [Vec4; 4],
    /// Each type's size-over-life scales: `u_size_scale`.
    pub size_scale: [Vec4; 4],
    /// Each type's sprite scale and tint curves (`glsl/render/birth_curves.glsl`).
    pub curves: BirthCurves,
}

impl RenderParams {
    /// The block of `style`.
    pub fn of(style: &ParticleStyle) -> Self {
        let (mut key_age, mut key_offset, mut key_slope) = (Vec::new(), Vec::new(), Vec::new());
        for t in 0..4 {
            let ramp = style.ramp_of(t);
            for half in 0..2 {
                let ages: [f32; 4] = std::array::from_fn(|i| ramp.ages[4 * half + i]);
                key_age.push(Vec4::from_array(ages));
            }
            for k in 0..MAX_KEYFRAMES {
                key_offset.push(Vec4::from_array(ramp.offset[k]));
                key_slope.push(Vec4::from_array(ramp.slope[k]));
            }
        }
        let types = &style.types;
        let each = |f: &dyn Fn(&super::TypeLook) -> f32| Vec4::from_array(types.each_ref().map(f));
        RenderParams {
            point_size: style.point_size,
            intensity: style.intensity,
            max_age: style.fire.map(|f| f.max_age),
            stretch: style.stretch,
            soft: style.soft,
            sprites: style.mode == DrawMode::Sprites,
            background: Vec3::from_array(style.background),
            clear_color: style.clear_color(),
            blend: style.blend(),
            key_age,
            key_offset,
            key_slope,
            tile: types.each_ref().map(|t| t.tile.min(3) as i32),
            spin_min: each(&|t| t.spin[0].to_radians()),
            spin_max: each(&|t| t.spin[1].to_radians()),
            size_min: each(&|t| t.size_range[0]),
            size_max: each(&|t| t.size_range[1]),
            flip_frames: each(&|t| t.flipbook.0 as f32),
            flip_rate: each(&|t| t.flipbook.1),
            size_age: types.each_ref().map(|t| Vec4::from_array(t.size.ages)),
            size_scale: types.each_ref().map(|t| Vec4::from_array(t.size.scales)),
            curves: BirthCurves::of(types),
        }
    }

    /// The state particles (and the under operator's background) are drawn with: the
    /// [`blend`](Self::blend), point sizes from the vertex shader, and with drawn geometry
    /// (`depth_test`) a depth test without a depth write.
    pub fn draw_state(&self, depth_test: bool) -> DrawState {
        DrawState {
            blend: Some(self.blend),
            point_size: PointSize::Program,
            depth: if depth_test { Depth::Test } else { Depth::Off },
            color_writes: true,
        }
    }

    /// `u_point_size` and `u_intensity`, for a draw's uniforms.
    pub fn size_uniforms(&self) -> [(&'static str, Uniform); 2] {
        [
            ("u_point_size", Uniform::F32(self.point_size)),
            ("u_intensity", Uniform::F32(self.intensity)),
        ]
    }

    /// The colour and opacity keyframes of every type that `glsl/render/keyframes.glsl`
    /// reads, for a draw's uniforms: the renderer and the CPU engine draw with the same ramps.
    pub fn keyframe_uniforms(&self) -> [(&'static str, Uniform); 3] {
        [
            ("u_key_age", Uniform::Vec4s(self.key_age[..].into())),
            ("u_key_offset", Uniform::Vec4s(self.key_offset[..].into())),
            ("u_key_slope", Uniform::Vec4s(self.key_slope[..].into())),
        ]
    }

    /// Everything the particle renderer's draw reads of the look: sizes, the fire's cycle
    /// (`u_max_age`, when the ramp is the fire's), the types' sprites and the keyframes.
    pub fn sprite_uniforms(&self) -> Vec<(&'static str, Uniform)> {
        let mut out: Vec<_> = self.size_uniforms().into();
        out.extend(self.max_age.map(|a| ("u_max_age", Uniform::F32(a))));
        out.extend(self.type_uniforms());
        out.extend(self.keyframe_uniforms());
        out
    }

    /// The per-type sprite uniforms of `glsl/render/sprite.glsl`, for a draw's uniforms: tile,
    /// rotation speed range, size over life, and the scale and tint curves.
    pub fn type_uniforms(&self) -> Vec<(&'static str, Uniform)> {
        let mut out = self.curves.uniforms();
        out.extend([
            ("u_type_tile", Uniform::IVec4(self.tile.into())),
            ("u_spin_min", Uniform::Vec4(self.spin_min)),
            ("u_spin_max", Uniform::Vec4(self.spin_max)),
            ("u_size_min", Uniform::Vec4(self.size_min)),
            ("u_size_max", Uniform::Vec4(self.size_max)),
            ("u_flip_frames", Uniform::Vec4(self.flip_frames)),
            ("u_flip_rate", Uniform::Vec4(self.flip_rate)),
            ("u_size_age", Uniform::Vec4s(self.size_age[..].into())),
            ("u_size_scale", Uniform::Vec4s(self.size_scale[..].into())),
        ]);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The block carries the style's ramps and per-type numbers in the shader's form.
    #[test]
    fn block_of_a_scene_packs_each_types_look() {
        let src = crate::scene::builtin_source("fountain").expect("a built-in scene");
        let scene = crate::scene::parse("fountain", src).expect("valid");
        let style = ParticleStyle::from_scene(&scene);
        let b = RenderParams::of(&style);
        assert_eq!(b.point_size, scene.render.point_size);
        assert_eq!(b.key_age.len(), 8);
        assert_eq!(b.key_offset.len(), 4 * MAX_KEYFRAMES);
        for t in 0..4 {
            let ramp = style.ramp_of(t);
            assert_eq!(b.key_age[2 * t].x, ramp.ages[0]);
            assert_eq!(b.key_slope[t * MAX_KEYFRAMES + 1].to_array(), ramp.slope[1]);
            assert_eq!(b.tile[t], style.types[t].tile.min(3) as i32);
            assert_eq!(b.size_scale[t].to_array(), style.types[t].size.scales);
        }
        assert_eq!(b.clear_color, style.clear_color());
    }
}
