//! The CPU twin of a constrained scene's step: the Verlet step of [`Reference`] for every
//! particle, then the relaxation passes (`glsl/sim/constrain.frag` for Jacobi,
//! `glsl/sim/constrain_set.frag` per Gauss-Seidel set, `glsl/sim/attach.frag` for the long-range
//! attachments), in `f32`, with the same operations in the same order (the GPU may fuse multiply-adds and take square roots its own
//! way, so the two agree to rounding, not bit for bit).
//!
//! Covers what [`Reference`] covers (forces and colliders, with orbiting spheres moved as the
//! GPU moves them) for `fp32` scenes.

use glam::Vec3;

use super::Reference;
use crate::error::{Error, Result};
use crate::scene::{Precision, RelaxScheme, SceneFile};
use crate::sim::constraints::{neighbours, set_count, set_partner, ConstraintError, Layout};
use crate::sim::params;

/// A constrained scene stepped on the CPU.
#[derive(Debug, Clone)]
pub struct Twin {
    reference: Reference,
    layout: Layout,
    /// The relaxation's numbers, the block the GPU's passes read (`crate::sim::params`).
    relax: params::Constraints,
    /// The spheres that orbit (all of them, when one does).
    colliders: params::Colliders,
    dt: f32,
    x: Vec<Vec3>,
    previous: Vec<Vec3>,
    life: Vec<f32>,
    step: u64,
}

impl Twin {
    /// The twin of `ParticleSim::new(scene)` for a scene with `[constraints]`: every particle at
    /// rest in its layout.
    pub fn new(scene: &SceneFile) -> Result<Self> {
        let reference = Reference::new(scene)?;
        let (Some(relax), Some(layout)) = (params::Constraints::of(scene), Layout::of(scene))
        else {
            return Err(Error::InvalidInput(format!(
                "scene `{}` has no [constraints]",
                scene.name
            )));
        };
        if scene.particles.precision != Precision::Fp32 {
            return Err(Error::InvalidInput(format!(
                "scene `{}`: the constraint twin models fp32 state only",
                scene.name
            )));
        }
        let x: Vec<Vec3> = layout
            .rest
            .iter()
            .map(|r| Vec3::new(r[0], r[1], r[2]))
            .collect();
        Ok(Twin {
            reference,
            relax,
            colliders: params::Colliders::of(&scene.colliders),
            dt: scene.time.dt,
            previous: x.clone(),
            life: vec![1.0; x.len()],
            x,
            layout,
            step: 0,
        })
    }

    /// Changes the relaxation passes per step (for measuring the error against them).
    pub fn set_iterations(&mut self, n: u32) {
        self.relax.iterations = n;
    }

    /// Changes the scheme and whether the long-range attachments run.
    pub fn set_scheme(&mut self, scheme: RelaxScheme, attachments: bool) {
        self.relax.scheme = scheme;
        self.relax.attachments = attachments;
    }

    fn move_spheres(&mut self, t: f64) {
        for (i, s) in self.colliders.moving_spheres.iter().enumerate() {
            if s.orbit.is_some() {
                self.reference.move_sphere(i, Vec3::from(s.center_at(t)));
            }
        }
    }

    /// One step: Verlet for every particle, then `iterations` relaxation passes.
    pub fn step(&mut self) {
        let dt = self.dt as f64;
        // The GPU's clocks: the step ends at time + dt; then time = steps × dt.
        let time = self.step as f64 * dt;
        self.move_spheres(time + dt);
        let mut next = Vec::with_capacity(self.x.len());
        for k in 0..self.x.len() {
            let (xn, life) =
                self.reference
                    .step_verlet(self.x[k], self.previous[k], self.life[k], 0);
            next.push(xn);
            self.life[k] = life;
        }
        self.previous = std::mem::replace(&mut self.x, next);
        self.step += 1;
        let t = self.step as f64 * dt;
        self.move_spheres(t);
        let offset = self.relax.pin_offset(t);
        for _ in 0..self.relax.iterations {
            match self.relax.scheme {
                RelaxScheme::Jacobi => self.x = self.relax_once(offset),
                RelaxScheme::GaussSeidel => {
                    for set in 0..set_count(self.layout.kind) {
                        self.x = self.relax_set(set, offset);
                    }
                }
            }
            if self.relax.attachments {
                self.x = self.attach(offset);
            }
        }
    }

    /// The rest position of texel `k` and whether it is pinned.
    fn rest(&self, k: usize) -> (Vec3, bool) {
        let r = self.layout.rest[k];
        (Vec3::new(r[0], r[1], r[2]), r[3] > 0.5)
    }

    /// One Gauss-Seidel pass: `glsl/sim/constrain_set.frag` for every texel, the constraints of
    /// `set` (which share no particle) each moving its two ends.
    fn relax_set(&self, set: u32, offset: Vec3) -> Vec<Vec3> {
        let size = self.layout.size;
        let w = size[0] as i32;
        let mut out = Vec::with_capacity(self.x.len());
        for k in 0..self.x.len() {
            let (r, pinned) = self.rest(k);
            if pinned {
                out.push(r + offset);
                continue;
            }
            let x = self.x[k];
            let t = [k as i32 % w, k as i32 / w];
            let mut xn = x;
            if let Some([qx, qy]) = set_partner(self.layout.kind, set, t, size) {
                let q = (qy * w + qx) as usize;
                let (rq, q_pinned) = self.rest(q);
                let rest_length = (rq - r).length();
                let d = self.x[q] - x;
                let len = d.length();
                let share = if q_pinned { 1.0 } else { 0.5 };
                if len > 0.0 {
                    xn = x + self.relax.stiffness * ((share * (len - rest_length) / len) * d);
                }
            }
            out.push(self.reference.keep_outside_position(xn));
        }
        out
    }

    /// The long-range attachments' pass (`glsl/sim/attach.frag`): every free texel pulled back
    /// onto the sphere of its rest distance around each pin it is attached to, where it lies
    /// outside.
    fn attach(&self, offset: Vec3) -> Vec<Vec3> {
        let mut out = Vec::with_capacity(self.x.len());
        let pins = self.layout.pins();
        for k in 0..self.x.len() {
            let (r, pinned) = self.rest(k);
            if pinned {
                out.push(r + offset);
                continue;
            }
            let mut x = self.x[k];
            for &p in self.layout.attachments(k, &pins).iter() {
                let (rp, _) = self.rest(p);
                let reach = (r - rp).length();
                let pin = rp + offset;
                let d = x - pin;
                let len = d.length();
                if len > reach {
                    x = pin + (reach / len) * d;
                }
            }
            out.push(self.reference.keep_outside_position(x));
        }
        out
    }

    /// One Jacobi pass: `glsl/sim/constrain.frag` for every texel.
    fn relax_once(&self, offset: Vec3) -> Vec<Vec3> {
        let [w, h] = self.layout.size.map(|s| s as i32);
        let rest = |k: usize| {
            let r = self.layout.rest[k];
            (Vec3::new(r[0], r[1], r[2]), r[3] > 0.5)
        };
        let mut out = Vec::with_capacity(self.x.len());
        for j in 0..h {
            for i in 0..w {
                let k = (j * w + i) as usize;
                let (r, pinned) = rest(k);
                if pinned {
                    out.push(r + offset);
                    continue;
                }
                let x = self.x[k];
                let mut sum = Vec3::ZERO;
                let mut n = 0;
                for [dx, dy] in neighbours(self.layout.kind) {
                    let (qx, qy) = (i + dx, j + dy);
                    if qx < 0 || qy < 0 || qx >= w || qy >= h {
                        continue;
                    }
                    let q = (qy * w + qx) as usize;
                    let (rq, q_pinned) = rest(q);
                    let rest_length = (rq - r).length();
                    let d = self.x[q] - x;
                    let len = d.length();
                    let share = if q_pinned { 1.0 } else { 0.5 };
                    if len > 0.0 {
                        sum += (share * (len - rest_length) / len) * d;
                    }
                    n += 1;
                }
                let xn = x + (self.relax.stiffness / n.max(1) as f32) * sum;
                out.push(self.reference.keep_outside_position(xn));
            }
        }
        out
    }

    /// Positions as the GPU's position texture holds them (x, y, z, life; 4 floats per texel).
    pub fn positions(&self) -> Vec<f32> {
        self.x
            .iter()
            .zip(&self.life)
            .flat_map(|(x, l)| [x.x, x.y, x.z, *l])
            .collect()
    }

    /// The layout.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The relative constraint error now.
    pub fn error(&self) -> ConstraintError {
        self.layout.error(&self.positions())
    }
}
