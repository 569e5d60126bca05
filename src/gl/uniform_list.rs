//! A list of uniform values by name, built once and given with every draw that reads it: the
//! scene's constants (emitters, masses, forces, colliders) and the sort network's. With the
//! context's uniform cache on, a draw that gives a value its program already holds uploads
//! nothing, so constants in every draw cost no GL call after the first.

use std::cell::RefCell;
use std::collections::HashMap;

use super::{Program, Uniform};

/// Uniform values by name, in the order given (a later value of a name overrides an earlier
/// one when a draw sets them). Array setters skip empty arrays, as GL would set nothing.
#[derive(Debug, Clone, Default)]
pub struct UniformList {
    values: Vec<(&'static str, Uniform)>,
    /// The values each program declares, by [`Program::serial`]: found once per program.
    declared: RefCell<HashMap<u64, Vec<(&'static str, Uniform)>>>,
}

impl PartialEq for UniformList {
    fn eq(&self, other: &Self) -> bool {
        self.values == other.values
    }
}

impl UniformList {
    /// An empty list.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `name = value`.
    pub fn push(&mut self, name: &'static str, value: Uniform) {
        self.values.push((name, value));
        self.declared.get_mut().clear();
    }

    /// The values, in order.
    pub fn values(&self) -> &[(&'static str, Uniform)] {
        &self.values
    }

    /// The values that `p` declares, for a draw of `p`, followed by `more` (this draw's own,
    /// those `p` declares), which replace the list's values of the same names: each name is
    /// set once (an orbiting sphere's place is not uploaded as the start's, then as its own).
    pub fn for_draw(
        &self,
        p: &Program,
        more: impl IntoIterator<Item = (&'static str, Uniform)>,
    ) -> Vec<(&'static str, Uniform)> {
        let mut declared = self.declared.borrow_mut();
        let own = declared.entry(p.serial()).or_insert_with(|| {
            (self.values.iter())
                .filter(|(n, _)| p.declares(n))
                .cloned()
                .collect()
        });
        let more: Vec<_> = (more.into_iter()).filter(|(n, _)| p.declares(n)).collect();
        let mut out: Vec<_> = (own.iter())
            .filter(|(n, _)| !more.iter().any(|(m, _)| m == n))
            .cloned()
            .collect();
        out.extend(more);
        out
    }

    /// Adds an `int`.
    pub fn i32(&mut self, name: &'static str, v: i32) {
        self.push(name, Uniform::I32(v));
    }
    /// Adds a `uint`.
    pub fn u32(&mut self, name: &'static str, v: u32) {
        self.push(name, Uniform::U32(v));
    }
    /// Adds a `float`.
    pub fn f32(&mut self, name: &'static str, v: f32) {
        self.push(name, Uniform::F32(v));
    }
    /// Adds a `vec2`.
    pub fn vec2(&mut self, name: &'static str, v: glam::Vec2) {
        self.push(name, Uniform::Vec2(v));
    }
    /// Adds a `vec3`.
    pub fn vec3(&mut self, name: &'static str, v: glam::Vec3) {
        self.push(name, Uniform::Vec3(v));
    }
    /// Adds a `vec4`.
    pub fn vec4(&mut self, name: &'static str, v: glam::Vec4) {
        self.push(name, Uniform::Vec4(v));
    }
    /// Adds an `ivec2`.
    pub fn ivec2(&mut self, name: &'static str, x: i32, y: i32) {
        self.push(name, Uniform::IVec2(glam::IVec2::new(x, y)));
    }
    /// Adds an `ivec3`.
    pub fn ivec3(&mut self, name: &'static str, x: i32, y: i32, z: i32) {
        self.push(name, Uniform::IVec3(glam::IVec3::new(x, y, z)));
    }
    /// Adds an `int[]` (nothing when empty).
    pub fn i32s(&mut self, name: &'static str, v: &[i32]) {
        if !v.is_empty() {
            self.push(name, Uniform::I32s(v.into()));
        }
    }
    /// Adds a `vec2[]` (nothing when empty).
    pub fn vec2s(&mut self, name: &'static str, v: &[glam::Vec2]) {
        if !v.is_empty() {
            self.push(name, Uniform::Vec2s(v.into()));
        }
    }
    /// Adds a `vec3[]` (nothing when empty).
    pub fn vec3s(&mut self, name: &'static str, v: &[glam::Vec3]) {
        if !v.is_empty() {
            self.push(name, Uniform::Vec3s(v.into()));
        }
    }
    /// Adds a `vec4[]` (nothing when empty).
    pub fn vec4s(&mut self, name: &'static str, v: &[glam::Vec4]) {
        if !v.is_empty() {
            self.push(name, Uniform::Vec4s(v.into()));
        }
    }
    /// Adds an `ivec4[]` (nothing when empty).
    pub fn ivec4s(&mut self, name: &'static str, v: &[[i32; 4]]) {
        if !v.is_empty() {
            self.push(name, Uniform::IVec4s(v.into()));
        }
    }
}

impl Extend<(&'static str, Uniform)> for UniformList {
    fn extend<I: IntoIterator<Item = (&'static str, Uniform)>>(&mut self, iter: I) {
        self.values.extend(iter);
        self.declared.get_mut().clear();
    }
}
