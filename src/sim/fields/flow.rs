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
    curl: Option<CurlNoise>,
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
    /// Samples [`FlowField::analytic`] at the nodes of `w.bounds`, `w.resolution` per axis; or
    /// takes the nodes of `w.data` (a file's field, read by `scene::parse`) plus the mean.
    pub fn new(w: &Wind) -> Result<Self> {
        if !w.turbulence.is_finite() || w.velocity.iter().any(|v| !v.is_finite()) {
            return Err(Error::InvalidInput(
                "wind: velocity and turbulence must be finite".into(),
            ));
        }
        let (mean, turbulence, bounds) = (Vec3::from_array(w.velocity), w.turbulence, w.bounds);
        if let Some(d) = &w.data {
            let axes = super::grid::axes("wind", bounds, d.size)?;
            let data: Vec<f32> = d
                .data
                .chunks_exact(3)
                .flat_map(|v| [v[0] + mean.x, v[1] + mean.y, v[2] + mean.z, 0.0])
                .collect();
            return Ok(FlowField {
                grid: Grid3::from_data("wind", axes, 4, data)?,
                mean,
                turbulence: 0.0,
                curl: None,
            });
        }
        let r = w.resolution;
        let axes = super::grid::axes("wind", bounds, [r, r, r])?;
        let curl = (w.curl > 0.0).then(|| CurlNoise {
            amplitude: w.curl as f64,
            scale: w.curl_scale as f64,
            step: axes.map(|a| a.spacing_f64()),
        });
        let grid = Grid3::from_axes(axes, 4, |p| {
            let mut v = wind_velocity(mean, turbulence, bounds, p);
            if let Some(c) = &curl {
                v += c.velocity(p);
            }
            v.extend(0.0)
        });
        Ok(FlowField {
            grid,
            mean,
            turbulence,
            curl,
        })
    }

    /// The wind velocity the texture samples: `mean + turbulence * pattern(p)`, plus the curl
    /// noise (a field from a file: the mean alone; its nodes are the file's).
    pub fn analytic(&self, p: Vec3) -> Vec3 {
        let [lo, hi] = self.grid.bounds();
        let v = wind_velocity(
            self.mean,
            self.turbulence,
            [lo.to_array(), hi.to_array()],
            p,
        );
        match &self.curl {
            Some(c) => v + c.velocity(p),
            None => v,
        }
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

/// Curl noise (Bridson et al. 2007, as the dli/flow wind uses it): the curl of a vector
/// potential whose components are gradient noise, so the wind swirls without sources or sinks.
/// The curl is taken by central differences with the grid's own spacing, so that the central
/// differences of its divergence at every interior node cancel exactly (the difference operators
/// commute): the texture's discrete divergence is rounding alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurlNoise {
    /// Speed scale, m/s.
    pub amplitude: f64,
    /// Noise period, m.
    pub scale: f64,
    /// Difference step per axis (the grid's spacing), m.
    pub step: [f64; 3],
}

impl CurlNoise {
    /// Component `a` of the vector potential at `q` (each component a noise of its own).
    fn potential(&self, a: usize, q: [f64; 3]) -> f64 {
        const OFFSET: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [31.7, 11.3, 47.1], [73.9, 59.3, 17.7]];
        let u = [0, 1, 2].map(|k| q[k] / self.scale + OFFSET[a][k]);
        self.scale / std::f64::consts::TAU * gradient_noise(u)
    }

    /// The velocity at `p`: `amplitude * curl(potential)` by central differences.
    pub fn velocity(&self, p: Vec3) -> Vec3 {
        let q = p.to_array().map(|v| v as f64);
        // d(psi_a)/d(x_b)
        let d = |a: usize, b: usize| {
            let (mut hi, mut lo) = (q, q);
            hi[b] += self.step[b];
            lo[b] -= self.step[b];
            (self.potential(a, hi) - self.potential(a, lo)) / (2.0 * self.step[b])
        };
        let v = [d(2, 1) - d(1, 2), d(0, 2) - d(2, 0), d(1, 0) - d(0, 1)];
        Vec3::from_array(v.map(|c| (self.amplitude * c) as f32))
    }
}

/// Smooth (quintic-faded) 3D gradient noise in about [-1, 1], from a hash of the lattice corner.
fn gradient_noise(u: [f64; 3]) -> f64 {
    let cell = u.map(f64::floor);
    let f = [0, 1, 2].map(|k| u[k] - cell[k]);
    let fade = |t: f64| t * t * t * (t * (t * 6.0 - 15.0) + 10.0);
    let mut sum = 0.0;
    for corner in 0..8u32 {
        let o = [corner & 1, (corner >> 1) & 1, (corner >> 2) & 1].map(|b| b as f64);
        let c = [0, 1, 2].map(|k| (cell[k] + o[k]) as i64 as u64);
        let mut h = c[0]
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(c[1].wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
            .wrapping_add(c[2].wrapping_mul(0x1656_67B1_9E37_79F9));
        h ^= h >> 31;
        h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 29;
        // One of the 12 edge directions of a cube, Perlin's gradient set.
        const G: [[f64; 3]; 12] = [
            [1.0, 1.0, 0.0],
            [-1.0, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [-1.0, -1.0, 0.0],
            [1.0, 0.0, 1.0],
            [-1.0, 0.0, 1.0],
            [1.0, 0.0, -1.0],
            [-1.0, 0.0, -1.0],
            [0.0, 1.0, 1.0],
            [0.0, -1.0, 1.0],
            [0.0, 1.0, -1.0],
            [0.0, -1.0, -1.0],
        ];
        let g = G[(h % 12) as usize];
        let r = [0, 1, 2].map(|k| f[k] - o[k]);
        let w: f64 = (0..3)
            .map(|k| {
                if o[k] > 0.0 {
                    fade(f[k])
                } else {
                    1.0 - fade(f[k])
                }
            })
            .product();
        sum += w * (g[0] * r[0] + g[1] * r[1] + g[2] * r[2]);
    }
    sum
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
            curl: 0.0,
            curl_scale: 1.0,
            field: None,
            data: None,
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

    /// Curl noise is divergence-free on the grid: at every interior node the central-difference
    /// divergence of the texels is rounding (below 1e-5 of the largest velocity derivative), while
    /// a field of gradient noise of the same size (the potential's own gradient, not a curl) has
    /// a divergence of the order of its derivatives: the check can fail.
    #[test]
    fn curl_noise_has_no_divergence() {
        let mut w = wind();
        w.velocity = [0.0; 3];
        w.turbulence = 0.0;
        w.curl = 1.5;
        w.curl_scale = 0.8;
        w.resolution = 24;
        let f = FlowField::new(&w).unwrap();
        let n = 24;
        let h = [0, 1, 2].map(|a| (w.bounds[1][a] - w.bounds[0][a]) as f64 / (n - 1) as f64);
        let c = f.curl.unwrap();
        let (mut div_max, mut grad_max, mut src_max) = (0.0f64, 0.0f64, 0.0f64);
        for k in 1..n - 1 {
            for j in 1..n - 1 {
                for i in 1..n - 1 {
                    let v = |di: i32, dj: i32, dk: i32| {
                        let (a, b, cc) = (i as i32 + di, j as i32 + dj, k as i32 + dk);
                        f.texel(a as usize, b as usize, cc as usize).as_dvec3()
                    };
                    let dx = (v(1, 0, 0) - v(-1, 0, 0)) / (2.0 * h[0]);
                    let dy = (v(0, 1, 0) - v(0, -1, 0)) / (2.0 * h[1]);
                    let dz = (v(0, 0, 1) - v(0, 0, -1)) / (2.0 * h[2]);
                    div_max = div_max.max((dx.x + dy.y + dz.z).abs());
                    grad_max = grad_max
                        .max(dx.abs().max_element())
                        .max(dy.abs().max_element())
                        .max(dz.abs().max_element());
                    // The same differences of the potential's gradient (a source field).
                    let p = f.node(i, j, k).to_array().map(|v| v as f64);
                    let lap: f64 = (0..3)
                        .map(|a| {
                            let (mut hi, mut lo) = (p, p);
                            hi[a] += h[a];
                            lo[a] -= h[a];
                            (c.potential(0, hi) - 2.0 * c.potential(0, p) + c.potential(0, lo))
                                / (h[a] * h[a])
                        })
                        .sum();
                    src_max = src_max.max(lap.abs() * c.amplitude);
                }
            }
        }
        assert!(grad_max > 0.5, "the wind varies: {grad_max}");
        assert!(
            div_max < 1e-5 * grad_max,
            "divergence {div_max} of {grad_max}"
        );
        assert!(
            src_max > 0.1 * grad_max,
            "a gradient field has sources: {src_max}"
        );
    }
}
