//! The wind flow field (Latta eq. 1): a mean velocity plus divergence-free swirls.

use glam::Vec3;

use super::grid::Grid3;
use crate::error::{Error, Result};
use crate::gl::{Context, Texture3D};
use crate::scene::Wind;

/// A wind flow field in a 3D RGBA32F texture (Latta eq. 1): texel `(vx, vy, vz, 0)`.
///
/// The velocity is `mean + turbulence * curl(psi) / (2 k_max)` with the vector potential
///
/// `psi = (sin(ky y' + 0.5) sin(kz z' + 1.3), sin(kz z' + 2.1) sin(kx x' + 0.7),
///         sin(kx x' + 1.9) sin(ky y' + 0.2))`,
///
/// `x' = x - min x` (and so on), `k = 2 pi / (max - min)` per axis: one period of swirls across
/// the bounds, divergence-free (a curl) before sampling, deterministic, and every component of
/// the variation bounded by `turbulence`.
#[derive(Debug, Clone, PartialEq)]
pub struct FlowField {
    grid: Grid3,
    mean: Vec3,
    turbulence: f32,
}

/// Phases of the vector potential (arbitrary, chosen so that no component vanishes on a plane
/// through the bounds' corner).
const FLOW_PHASES: [f64; 6] = [0.5, 1.3, 2.1, 0.7, 1.9, 0.2];

/// The divergence-free pattern of a wind over `bounds` at `p` (each component in `[-1, 1]`),
/// double precision.
fn flow_pattern(bounds: [[f32; 3]; 2], p: Vec3) -> [f64; 3] {
    let [lo, hi] = bounds;
    let k = [0, 1, 2].map(|a| std::f64::consts::TAU / (hi[a] as f64 - lo[a] as f64));
    let x = [0, 1, 2].map(|a| k[a] * (p[a] as f64 - lo[a] as f64));
    let [ph1, ph2, ph3, ph4, ph5, ph6] = FLOW_PHASES;
    let (s, c) = (f64::sin, f64::cos);
    // curl of psi, with psi as in `FlowField`'s doc.
    let vx = k[1] * s(x[0] + ph5) * c(x[1] + ph6) - k[2] * c(x[2] + ph3) * s(x[0] + ph4);
    let vy = k[2] * s(x[1] + ph1) * c(x[2] + ph2) - k[0] * c(x[0] + ph5) * s(x[1] + ph6);
    let vz = k[0] * s(x[2] + ph3) * c(x[0] + ph4) - k[1] * c(x[1] + ph1) * s(x[2] + ph2);
    let scale = 0.5 / k[0].max(k[1]).max(k[2]);
    [vx * scale, vy * scale, vz * scale]
}

/// `mean + turbulence * flow_pattern(bounds, p)`, rounded once to `f32`.
fn wind_velocity(mean: Vec3, turbulence: f32, bounds: [[f32; 3]; 2], p: Vec3) -> Vec3 {
    let v = flow_pattern(bounds, p);
    Vec3::from_array([0, 1, 2].map(|a| (mean[a] as f64 + turbulence as f64 * v[a]) as f32))
}

impl FlowField {
    /// Samples [`FlowField::analytic`] at the nodes of `w.bounds`, `w.resolution` per axis.
    pub fn new(w: &Wind) -> Result<Self> {
        if !w.turbulence.is_finite() || w.velocity.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidInput(
                "wind: velocity and turbulence must be finite".into(),
            ));
        }
        let r = w.resolution;
        let (mean, turbulence, bounds) = (Vec3::from_array(w.velocity), w.turbulence, w.bounds);
        let grid = Grid3::build("wind", bounds, [r, r, r], 4, |p| {
            wind_velocity(mean, turbulence, bounds, p).extend(0.0)
        })?;
        Ok(FlowField {
            grid,
            mean,
            turbulence,
        })
    }

    /// The wind velocity the texture samples: `mean + turbulence * pattern(p)`.
    pub fn analytic(&self, p: Vec3) -> Vec3 {
        let [lo, hi] = self.grid.bounds();
        wind_velocity(
            self.mean,
            self.turbulence,
            [lo.to_array(), hi.to_array()],
            p,
        )
    }

    /// `[min corner, max corner]`: the `bmin`, `bmax` arguments of `flow_sample`.
    pub fn bounds(&self) -> [Vec3; 2] {
        self.grid.bounds()
    }

    /// Nodes per axis: the texture size and the `res` argument of `flow_sample`.
    pub fn resolution(&self) -> [u32; 3] {
        self.grid.res()
    }

    /// Position of node `(i, j, k)`.
    pub fn node(&self, i: usize, j: usize, k: usize) -> Vec3 {
        self.grid.node([i, j, k])
    }

    /// Texel `(i, j, k)`: the velocity at that node.
    pub fn texel(&self, i: usize, j: usize, k: usize) -> Vec3 {
        self.grid.texel(i, j, k).truncate()
    }

    /// The texture data, RGBA32F, x-fastest.
    pub fn texels(&self) -> &[f32] {
        &self.grid.data
    }

    /// Trilinear interpolation of the velocity. The twin of `flow_sample` in GLSL.
    pub fn sample(&self, p: Vec3) -> Vec3 {
        self.grid.trilinear(p).truncate()
    }

    /// Uploads the velocities to an RGBA32F 3D texture labelled `wind`.
    pub fn upload(&self, ctx: &Context) -> Result<Texture3D> {
        self.grid.upload(ctx, "wind")
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::Rng;
    use super::*;

    fn wind() -> Wind {
        Wind {
            velocity: [1.0, 0.0, -0.5],
            turbulence: 0.8,
            resolution: 12,
            bounds: [[-2.0, 0.0, -1.0], [2.0, 3.0, 1.0]],
            drag: 1.0,
            form: Default::default(),
        }
    }

    #[test]
    fn flow_nodes_are_the_analytic_wind_and_the_pattern_is_divergence_free() {
        let w = wind();
        let f = FlowField::new(&w).unwrap();
        assert_eq!(f.resolution(), [12, 12, 12]);
        let mean = Vec3::from_array(w.velocity);
        let mut spread = 0.0f32;
        for k in 0..12 {
            for j in 0..12 {
                for i in 0..12 {
                    let v = f.texel(i, j, k);
                    assert_eq!(v, f.analytic(f.node(i, j, k)));
                    let dev = (v - mean).abs().max_element();
                    assert!(dev <= w.turbulence * (1.0 + 1e-6), "{v}");
                    spread = spread.max(dev);
                    assert_eq!(f.texels()[((k * 12 + j) * 12 + i) * 4 + 3], 0.0);
                }
            }
        }
        assert!(spread > 0.5 * w.turbulence, "the wind varies: {spread}");
        // The analytic pattern is a curl: central differences of its divergence vanish up to
        // their truncation error.
        let mut rng = Rng(19);
        let e = 1e-3;
        for _ in 0..200 {
            let p = rng.point(Vec3::new(-2.0, 0.0, -1.0), Vec3::new(2.0, 3.0, 1.0));
            let q = p.to_array().map(|v| v as f64);
            let div: f64 = (0..3)
                .map(|a| {
                    let mut hi = q;
                    let mut lo = q;
                    hi[a] += e;
                    lo[a] -= e;
                    let at = |q: [f64; 3]| {
                        flow_pattern(w.bounds, Vec3::from_array(q.map(|v| v as f32)))[a]
                    };
                    (at(hi) - at(lo)) / (2.0 * e)
                })
                .sum();
            assert!(div.abs() < 1e-2, "divergence {div} at {p}");
        }
    }

    #[test]
    fn flow_sampler_reproduces_nodes_and_clamps() {
        // Dyadic bounds: node positions map to integer grid coordinates exactly.
        let mut w = wind();
        w.bounds = [[-2.0, 0.0, -1.0], [2.0, 4.0, 1.0]];
        w.resolution = 9;
        let f = FlowField::new(&w).unwrap();
        for k in 0..9 {
            for j in 0..9 {
                for i in 0..9 {
                    assert_eq!(f.sample(f.node(i, j, k)), f.texel(i, j, k));
                }
            }
        }
        // Linear along an x edge.
        let (a, b) = (f.node(3, 4, 5), f.node(4, 4, 5));
        for s in [0.125f32, 0.5, 0.75] {
            let v = f.sample(a + s * (b - a));
            let want = (1.0 - s) * f.texel(3, 4, 5) + s * f.texel(4, 4, 5);
            assert!((v - want).length() < 1e-6);
        }
        // Outside: clamped per axis.
        let p = Vec3::new(0.3, 1.7, -0.2);
        assert_eq!(
            f.sample(p + Vec3::new(10.0, 0.0, 0.0)),
            f.sample(Vec3::new(2.0, 1.7, -0.2))
        );
        assert_eq!(f.sample(Vec3::splat(-50.0)), f.texel(0, 0, 0));
    }
}
