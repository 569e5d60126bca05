//! Initial particle data drawn from an emitter: the CPU side of Latta's allocator emission
//! (§3.4.1) and the twin of `glsl/sim/spawn.glsl`, which the GPU uses for the initial fill and
//! UberFlow's time-stamp emission. Same hash (PCG), same stream layout, same distributions.

use glam::{Vec3, Vec4};

use crate::scene::{Emitter, Shape};

/// The PCG hash of `glsl/common/rng.glsl`.
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

/// The random stream of one particle at one step (`rng_seed` in GLSL).
#[derive(Debug, Clone, Copy)]
pub struct Rng(u32);

impl Rng {
    /// The stream of particle `index` at `step` for `seed`.
    pub fn new(index: u32, step: u32, seed: u32) -> Self {
        Rng(pcg_hash(index ^ pcg_hash(step ^ pcg_hash(seed))))
    }

    /// Uniform in [0, 1), 24 bits.
    pub fn uniform(&mut self) -> f32 {
        self.0 = pcg_hash(self.0);
        (self.0 >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

/// An emitter in the form the shaders take it (five vec4 uniforms, see `spawn.glsl`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EmitterUniforms {
    /// Centre, shape code.
    pub center: Vec4,
    /// Box size, radius.
    pub size: Vec4,
    /// Disc normal, cone half-angle (radians).
    pub normal: Vec4,
    /// Velocity direction.
    pub dir: Vec4,
    /// Speed min, max; life min, max.
    pub range: Vec4,
}

impl EmitterUniforms {
    /// Converts a scene emitter at time 0 (see [`at`](Self::at)).
    pub fn new(e: &Emitter) -> Self {
        Self::at(e, 0.0)
    }

    /// Converts a scene emitter with its curves at time `t` in seconds (normal and direction
    /// normalised; permanent particles get life [0, 0]).
    pub fn at(e: &Emitter, t: f32) -> Self {
        let shape = match e.shape {
            Shape::Point => 0.0,
            Shape::Box => 1.0,
            Shape::Sphere => 2.0,
            Shape::Disc => 3.0,
        };
        let normal = Vec3::from(e.normal.unwrap_or([0.0, 1.0, 0.0])).normalize();
        let life = e.life_at(t).unwrap_or([0.0, 0.0]);
        let speed = e.speed.at(t);
        EmitterUniforms {
            center: Vec3::from(e.center.at(t)).extend(shape),
            size: Vec3::from(e.size).extend(e.radius.at(t)),
            normal: normal.extend(e.cone_degrees.at(t).to_radians()),
            dir: Vec3::from(e.direction.at(t)).normalize().extend(0.0),
            range: Vec4::new(speed[0], speed[1], life[0], life[1]),
        }
    }
}

const TAU: f32 = std::f32::consts::TAU;

fn basis(n: Vec3) -> (Vec3, Vec3) {
    let a = if n.x.abs() < 0.9 { Vec3::X } else { Vec3::Y };
    let t = n.cross(a).normalize();
    (t, n.cross(t))
}

fn mix(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

impl EmitterUniforms {
    /// A position inside the emitter's shape.
    pub fn position(&self, rng: &mut Rng) -> Vec3 {
        let c = self.center.truncate();
        match self.center.w as i32 {
            1 => {
                let u = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                c + (u - 0.5) * self.size.truncate()
            }
            2 => {
                let z = 2.0 * rng.uniform() - 1.0;
                let phi = TAU * rng.uniform();
                let r = self.size.w * rng.uniform().powf(1.0 / 3.0);
                let s = (1.0 - z * z).max(0.0).sqrt();
                c + r * Vec3::new(s * phi.cos(), s * phi.sin(), z)
            }
            3 => {
                let (t, b) = basis(self.normal.truncate());
                let r = self.size.w * rng.uniform().sqrt();
                let phi = TAU * rng.uniform();
                c + r * (phi.cos() * t + phi.sin() * b)
            }
            _ => c,
        }
    }

    /// A velocity in the emitter's cone.
    pub fn velocity(&self, rng: &mut Rng) -> Vec3 {
        let d = self.dir.truncate();
        let z = mix(self.normal.w.cos(), 1.0, rng.uniform());
        let phi = TAU * rng.uniform();
        let s = (1.0 - z * z).max(0.0).sqrt();
        let (t, b) = basis(d);
        let dir = z * d + s * (phi.cos() * t + phi.sin() * b);
        mix(self.range.x, self.range.y, rng.uniform()) * dir
    }

    /// A life length.
    pub fn life(&self, rng: &mut Rng) -> f32 {
        mix(self.range.z, self.range.w, rng.uniform())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn emitter(shape: Shape) -> Emitter {
        Emitter {
            rate: Some(10.0.into()),
            allocator: None,
            cycle: None,
            release_spread: None,
            release_cloud: None,
            shape,
            center: [1.0, 2.0, 3.0].into(),
            size: [2.0, 1.0, 0.5],
            radius: 0.5.into(),
            normal: Some([0.0, 0.0, 2.0]),
            direction: [0.0, 3.0, 0.0].into(),
            cone_degrees: 20.0.into(),
            speed: [1.0, 2.0].into(),
            life: Some([0.5, 1.5].into()),
            mass: None,
            mass_range: None,
            sprite_scale: 1.0.into(),
            tint: [1.0; 4].into(),
            tile: None,
            rotation_speed: None,
            size_over_life: Vec::new(),
            keyframes: Vec::new(),
            bursts: Vec::new(),
            size_range: None,
            flipbook: None,
            forces: Default::default(),
            parent: None,
            per_parent: None,
            on_death: None,
            trail_rate: None,
            inherit_velocity: None,
        }
    }

    #[test]
    fn shapes_contain_their_samples() {
        let c = Vec3::new(1.0, 2.0, 3.0);
        for shape in [Shape::Point, Shape::Box, Shape::Sphere, Shape::Disc] {
            let u = EmitterUniforms::new(&emitter(shape));
            for i in 0..2000 {
                let mut rng = Rng::new(i, 7, 42);
                let p = u.position(&mut rng) - c;
                match shape {
                    Shape::Point => assert_eq!(p, Vec3::ZERO),
                    Shape::Box => assert!(p.abs().cmple(Vec3::new(1.0, 0.5, 0.25)).all()),
                    Shape::Sphere => assert!(p.length() <= 0.5 + 1e-5),
                    // Disc normal +z: samples lie in the xy plane.
                    Shape::Disc => assert!(p.z.abs() < 1e-6 && p.length() <= 0.5 + 1e-5),
                }
                let v = u.velocity(&mut rng);
                let speed = v.length();
                assert!((1.0 - 1e-5..=2.0 + 1e-5).contains(&speed), "{speed}");
                let angle = (v.y / speed).clamp(-1.0, 1.0).acos().to_degrees();
                assert!(angle <= 20.0 + 1e-2, "{angle}");
                let l = u.life(&mut rng);
                assert!((0.5..=1.5).contains(&l));
            }
        }
    }

    #[test]
    fn ball_samples_are_uniform_in_volume() {
        // Uniform in a ball: the fraction within half the radius is 1/8.
        let u = EmitterUniforms::new(&emitter(Shape::Sphere));
        let n = 20_000;
        let inner = (0..n)
            .filter(|&i| {
                let mut rng = Rng::new(i, 0, 1);
                (u.position(&mut rng) - Vec3::new(1.0, 2.0, 3.0)).length() < 0.25
            })
            .count();
        let f = inner as f64 / n as f64;
        assert!((f - 0.125).abs() < 0.01, "{f}");
    }
}
