//! A particle type's sprite scale and tint as curves of the emitter's time, each particle keeping
//! the value at its birth time: the uniforms of `glsl/render/birth_curves.glsl`, which evaluates
//! them in the vertex stage as [`Curve::component_at`](crate::scene::curve::Curve::component_at)
//! does on the CPU (the periodic term and the value noise ported bit for bit but for the float
//! precision of time).

use glam::Vec4;

use super::TypeLook;
use crate::gl::Uniform;
use crate::scene::curve::{Animated, CurveValue};
use crate::scene::MAX_BIRTH_KEYS;

/// One curve in the shader's form.
#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    time: [f32; 4],
    values: [[f32; 4]; 4],
    /// Keys, smooth (1) or linear (0), period (0: no sine), phase.
    form: [f32; 4],
    periodic: [f32; 4],
    noise: [f32; 4],
    frequency: f32,
    seed: [i32; 4],
}

/// `v` in the shader's form: a constant is one key; a curve's components past `T::LEN` are 0.
fn slot<T: CurveValue>(v: &Animated<T>) -> Slot {
    let pad =
        |c: Vec<f32>| -> [f32; 4] { std::array::from_fn(|i| c.get(i).copied().unwrap_or(0.0)) };
    let mut s = Slot::default();
    let c = match v {
        Animated::Constant(x) => {
            s.values[0] = pad(x.components());
            s.form[0] = 1.0;
            return s;
        }
        Animated::Curve(c) => c,
    };
    // Validation keeps curves read per particle within MAX_BIRTH_KEYS keys.
    let values = c.key_values::<T>();
    for (k, (key, value)) in c.keys.iter().zip(&values).take(MAX_BIRTH_KEYS).enumerate() {
        s.time[k] = key.0;
        s.values[k] = pad(value.components());
    }
    s.form[0] = c.keys.len().min(MAX_BIRTH_KEYS) as f32;
    s.form[1] = (c.interpolation == crate::scene::curve::Interpolation::Smooth) as u8 as f32;
    let each = |a: &crate::scene::curve::Components| -> [f32; 4] {
        std::array::from_fn(|i| if i < T::LEN { a.get(i) } else { 0.0 })
    };
    if let Some(p) = &c.periodic {
        s.form[2] = p.period;
        s.form[3] = p.phase;
        s.periodic = each(&p.amplitude);
    }
    if let Some(n) = &c.noise {
        s.noise = each(&n.amplitude);
        s.frequency = n.frequency;
        // As Curve::terms_at: every component of a shared value has component 0's noise.
        s.seed = std::array::from_fn(|i| {
            let i = if T::SHARED { 0 } else { i as u32 };
            n.seed.wrapping_add(i) as i32
        });
    }
    s
}

/// Every type's sprite scale and tint curves in the shader's form: the uniforms
/// `u_curve_*`, one slot per type and curve (scale, then tint).
#[derive(Debug, Clone, PartialEq)]
pub struct BirthCurves {
    time: Vec<Vec4>,
    value: Vec<Vec4>,
    form: Vec<Vec4>,
    periodic: Vec<Vec4>,
    noise: Vec<Vec4>,
    frequency: Vec<Vec4>,
    seed: Vec<[i32; 4]>,
}

impl BirthCurves {
    /// The curves of `types`.
    pub(super) fn of(types: &[TypeLook; 4]) -> Self {
        let slots: Vec<Slot> = types
            .iter()
            .flat_map(|t| [slot(&t.sprite_scale()), slot(&t.tint)])
            .collect();
        let vec4s = |f: &dyn Fn(&Slot) -> [f32; 4]| -> Vec<Vec4> {
            slots.iter().map(|s| Vec4::from_array(f(s))).collect()
        };
        BirthCurves {
            time: vec4s(&|s| s.time),
            value: (slots.iter())
                .flat_map(|s| s.values.map(Vec4::from_array))
                .collect(),
            form: vec4s(&|s| s.form),
            periodic: vec4s(&|s| s.periodic),
            noise: vec4s(&|s| s.noise),
            frequency: (slots.chunks(4))
                .map(|c| Vec4::from_array(std::array::from_fn(|i| c[i].frequency)))
                .collect(),
            seed: slots.iter().map(|s| s.seed).collect(),
        }
    }

    /// The curves, for a draw's uniforms.
    pub(super) fn uniforms(&self) -> Vec<(&'static str, Uniform)> {
        vec![
            ("u_curve_time", Uniform::Vec4s(self.time[..].into())),
            ("u_curve_value", Uniform::Vec4s(self.value[..].into())),
            ("u_curve_form", Uniform::Vec4s(self.form[..].into())),
            ("u_curve_periodic", Uniform::Vec4s(self.periodic[..].into())),
            ("u_curve_noise", Uniform::Vec4s(self.noise[..].into())),
            (
                "u_curve_frequency",
                Uniform::Vec4s(self.frequency[..].into()),
            ),
            ("u_curve_seed", Uniform::IVec4s(self.seed[..].into())),
        ]
    }
}
