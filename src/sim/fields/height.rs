//! The height field (UberFlow §4.6): a landscape over the xz plane with its normals.

use glam::{Vec3, Vec4};

use super::grid::{lerp, Axis};
use crate::error::{Error, Result};
use crate::gl::{Context, Texture, TextureDesc, TextureFormat};
use crate::scene::HeightFieldCollider;

/// A height field over the xz plane (UberFlow §4.6): RGBA32F texels
/// `(height, normal.x, normal.y, normal.z)`.
///
/// The normal of a node comes from central differences of the *sampled* heights (one-sided at
/// the edges), `normalize(-dh/dx, 1, -dh/dz)`, so it always points up (`normal.y > 0`) and the
/// interpolated normal can never be zero.
#[derive(Debug, Clone, PartialEq)]
pub struct HeightField {
    x: Axis,
    z: Axis,
    texels: Vec<f32>,
}

impl HeightField {
    /// The scene's landscape: the height [`HeightField::analytic`] sampled at the nodes of
    /// `extent` with `resolution` nodes per axis.
    /// With an image or `.npy` file (`c.heights`, read by `scene::parse`), the nodes are the
    /// file's values, `base + amplitude * value`, row j at z_j (row 0 at min z).
    pub fn new(c: &HeightFieldCollider) -> Result<Self> {
        if let Some(d) = &c.heights {
            let heights: Vec<f32> = d
                .data
                .iter()
                .map(|v| (c.base as f64 + c.amplitude as f64 * *v as f64) as f32)
                .collect();
            return Self::from_heights(c.extent, [d.size[0], d.size[1]], &heights);
        }
        let x = Axis::new("height field x", c.extent[0], c.extent[2], c.resolution)?;
        let z = Axis::new("height field z", c.extent[1], c.extent[3], c.resolution)?;
        let (nx, nz) = (x.n as usize, z.n as usize);
        let mut heights = Vec::with_capacity(nx * nz);
        for j in 0..nz {
            for i in 0..nx {
                heights.push(Self::analytic(c, x.node(i), z.node(j)));
            }
        }
        Ok(Self::build(x, z, &heights))
    }

    /// A height field from explicit node heights: `heights[j * nx + i]` is the height at node
    /// `(x_i, z_j)`; `extent` is `[min x, min z, max x, max z]`, `res` is `[nx, nz]`.
    pub fn from_heights(extent: [f32; 4], res: [u32; 2], heights: &[f32]) -> Result<Self> {
        let x = Axis::new("height field x", extent[0], extent[2], res[0])?;
        let z = Axis::new("height field z", extent[1], extent[3], res[1])?;
        let want = res[0] as usize * res[1] as usize;
        if heights.len() != want {
            return Err(Error::InvalidInput(format!(
                "height field: {} heights given, a {}x{} grid needs {want}",
                heights.len(),
                res[0],
                res[1]
            )));
        }
        if let Some(h) = heights.iter().find(|h| !h.is_finite()) {
            return Err(Error::InvalidInput(format!(
                "height field: height {h} is not finite"
            )));
        }
        Ok(Self::build(x, z, heights))
    }

    fn build(x: Axis, z: Axis, heights: &[f32]) -> Self {
        let (nx, nz) = (x.n as usize, z.n as usize);
        let h = |i: usize, j: usize| heights[j * nx + i] as f64;
        // Central differences inside, one-sided at the edges.
        let diff = |i: usize, n: usize, d: f64, at: &dyn Fn(usize) -> f64| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            (at(b) - at(a)) / ((b - a) as f64 * d)
        };
        let (dx, dz) = (x.spacing_f64(), z.spacing_f64());
        let mut texels = Vec::with_capacity(nx * nz * 4);
        for j in 0..nz {
            for i in 0..nx {
                let hx = diff(i, nx, dx, &|ii| h(ii, j));
                let hz = diff(j, nz, dz, &|jj| h(i, jj));
                let len = (hx * hx + 1.0 + hz * hz).sqrt();
                texels.extend_from_slice(&[
                    heights[j * nx + i],
                    (-hx / len) as f32,
                    (1.0 / len) as f32,
                    (-hz / len) as f32,
                ]);
            }
        }
        HeightField { x, z, texels }
    }

    /// The scene's landscape, a sum of two products of sines with incommensurate frequencies
    /// (hills that do not repeat on a visible grid):
    ///
    /// `h(x, z) = base + amplitude * (sin(f x) cos(0.8 f z)
    ///            + 0.5 sin(1.7 f z + 0.3) sin(0.6 f x + 1.1)) / 1.5`, `f = frequency`,
    ///
    /// so `|h - base| <= amplitude`. Evaluated in double precision.
    pub fn analytic(c: &HeightFieldCollider, x: f32, z: f32) -> f32 {
        let (f, x, z) = (c.frequency as f64, x as f64, z as f64);
        let s = (f * x).sin() * (0.8 * f * z).cos()
            + 0.5 * (1.7 * f * z + 0.3).sin() * (0.6 * f * x + 1.1).sin();
        (c.base as f64 + c.amplitude as f64 * s / 1.5) as f32
    }

    /// `[min x, min z, max x, max z]`: the `extent` argument of `heightfield_sample`.
    pub fn extent(&self) -> [f32; 4] {
        [self.x.min, self.z.min, self.x.max, self.z.max]
    }

    /// `[nx, nz]`: the texture size and the `res` argument of `heightfield_sample`.
    pub fn resolution(&self) -> [u32; 2] {
        [self.x.n, self.z.n]
    }

    /// Position `(x_i, z_j)` of node `(i, j)`.
    pub fn node(&self, i: usize, j: usize) -> (f32, f32) {
        (self.x.node(i), self.z.node(j))
    }

    /// Texel `(i, j)`: `(height, normal)`.
    pub fn texel(&self, i: usize, j: usize) -> Vec4 {
        let at = (j * self.x.n as usize + i) * 4;
        Vec4::from_slice(&self.texels[at..at + 4])
    }

    /// The texture data, RGBA32F, x-fastest.
    pub fn texels(&self) -> &[f32] {
        &self.texels
    }

    /// Height and unit normal at `(x, z)`: bilinear interpolation of the texels, the normal
    /// normalised after interpolation. The twin of `heightfield_sample` in GLSL.
    pub fn sample(&self, x: f32, z: f32) -> (f32, Vec3) {
        let v = self.sample_raw(x, z);
        (v.x, Vec3::new(v.y, v.z, v.w).normalize())
    }

    /// The interpolated texel before the normal is normalised.
    fn sample_raw(&self, x: f32, z: f32) -> Vec4 {
        let (i0, i1, tx) = self.x.cell(x);
        let (j0, j1, tz) = self.z.cell(z);
        let c0 = lerp(self.texel(i0, j0), self.texel(i1, j0), tx);
        let c1 = lerp(self.texel(i0, j1), self.texel(i1, j1), tx);
        lerp(c0, c1, tz)
    }

    /// Uploads the texels to an RGBA32F 2D texture labelled `heightfield`.
    pub fn upload(&self, ctx: &Context) -> Result<Texture> {
        let [width, height] = self.resolution();
        let tex = Texture::new(
            ctx,
            TextureDesc {
                width,
                height,
                format: TextureFormat::Rgba32F,
                label: "heightfield",
            },
        )?;
        tex.upload_f32(&self.texels)?;
        Ok(tex)
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::Rng;
    use super::*;

    fn hills(extent: [f32; 4], resolution: u32) -> HeightFieldCollider {
        HeightFieldCollider {
            extent,
            resolution,
            base: 0.25,
            amplitude: 1.5,
            frequency: 0.7,
            friction: 0.0,
            resilience: 1.0,
            image: None,
            npy: None,
            heights: None,
        }
    }

    #[test]
    fn height_nodes_are_the_analytic_landscape() {
        let c = hills([-5.0, -3.0, 7.0, 4.0], 33);
        let hf = HeightField::new(&c).unwrap();
        assert_eq!(hf.resolution(), [33, 33]);
        assert_eq!(hf.node(32, 32), (7.0, 4.0));
        let mut lo = f32::INFINITY;
        let mut hi = f32::NEG_INFINITY;
        for j in 0..33 {
            for i in 0..33 {
                let (x, z) = hf.node(i, j);
                let h = hf.texel(i, j).x;
                assert_eq!(h, HeightField::analytic(&c, x, z));
                assert!((h - c.base).abs() <= c.amplitude);
                lo = lo.min(h);
                hi = hi.max(h);
            }
        }
        // A landscape, not a plane: the hills span most of the amplitude.
        assert!(hi - lo > c.amplitude, "{lo}..{hi}");
    }

    #[test]
    fn height_normals_are_unit_and_match_the_analytic_slope() {
        let c = hills([-5.0, -3.0, 7.0, 4.0], 65);
        let hf = HeightField::new(&c).unwrap();
        let [dx, dz] = [hf.x.spacing_f64(), hf.z.spacing_f64()];
        // Central differences are off by h^2/6 |h'''|; the normal (-g, 1)/|(-g, 1)| is
        // 1-Lipschitz in the slope g. Third derivatives of the landscape:
        let (a, f) = (c.amplitude as f64 / 1.5, c.frequency as f64);
        let hxxx = a * f.powi(3) * (1.0 + 0.5 * 0.6f64.powi(3));
        let hzzz = a * f.powi(3) * (0.8f64.powi(3) + 0.5 * 1.7f64.powi(3));
        let bound = ((dx * dx / 6.0 * hxxx).powi(2) + (dz * dz / 6.0 * hzzz).powi(2)).sqrt() + 1e-6;
        let analytic_slope = |x: f64, z: f64| {
            let hx = a
                * (f * (f * x).cos() * (0.8 * f * z).cos()
                    + 0.5 * (1.7 * f * z + 0.3).sin() * 0.6 * f * (0.6 * f * x + 1.1).cos());
            let hz = a
                * (-(f * x).sin() * 0.8 * f * (0.8 * f * z).sin()
                    + 0.5 * 1.7 * f * (1.7 * f * z + 0.3).cos() * (0.6 * f * x + 1.1).sin());
            let len = (hx * hx + 1.0 + hz * hz).sqrt();
            [-hx / len, 1.0 / len, -hz / len]
        };
        for j in 1..64 {
            for i in 1..64 {
                let n = hf.texel(i, j);
                let len = Vec3::new(n.y, n.z, n.w).length();
                assert!((len - 1.0).abs() < 1e-6);
                let (x, z) = hf.node(i, j);
                let want = analytic_slope(x as f64, z as f64);
                let err = ((n.y as f64 - want[0]).powi(2)
                    + (n.z as f64 - want[1]).powi(2)
                    + (n.w as f64 - want[2]).powi(2))
                .sqrt();
                assert!(err <= bound, "node ({i}, {j}): error {err} > {bound}");
            }
        }
    }

    #[test]
    fn height_sampler_reproduces_nodes_and_is_linear_along_edges() {
        // A dyadic grid (spacing 0.5): node positions map to integer grid coordinates exactly.
        let c = hills([-4.0, -2.0, 4.0, 6.0], 17);
        let hf = HeightField::new(&c).unwrap();
        for j in 0..17 {
            for i in 0..17 {
                let (x, z) = hf.node(i, j);
                let (h, n) = hf.sample(x, z);
                let t = hf.texel(i, j);
                assert_eq!(h, t.x, "node ({i}, {j})");
                assert!((n - Vec3::new(t.y, t.z, t.w)).length() < 1e-6);
            }
        }
        // Along an edge between nodes (i, j) and (i + 1, j) the height is linear.
        let mut rng = Rng(3);
        for _ in 0..200 {
            let (i, j) = ((rng.next() * 16.0) as usize, (rng.next() * 17.0) as usize);
            let s = rng.next();
            let (x0, z) = hf.node(i, j);
            let (x1, _) = hf.node(i + 1, j);
            let (h, _) = hf.sample(x0 + s * (x1 - x0), z);
            let want = (1.0 - s) * hf.texel(i, j).x + s * hf.texel(i + 1, j).x;
            assert!((h - want).abs() < 1e-5, "{h} vs {want}");
            // ... and along z too.
            let (x, z0) = hf.node(j, i);
            let (_, z1) = hf.node(j, i + 1);
            let (h, _) = hf.sample(x, z0 + s * (z1 - z0));
            let want = (1.0 - s) * hf.texel(j, i).x + s * hf.texel(j, i + 1).x;
            assert!((h - want).abs() < 1e-5, "{h} vs {want}");
        }
        // A non-dyadic grid reproduces its nodes up to rounding of the grid coordinate.
        let hf = HeightField::new(&hills([-5.1, -3.3, 7.7, 4.2], 23)).unwrap();
        for j in 0..23 {
            for i in 0..23 {
                let (x, z) = hf.node(i, j);
                assert!((hf.sample(x, z).0 - hf.texel(i, j).x).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn height_outside_the_extent_continues_from_the_edge() {
        let hf = HeightField::new(&hills([-4.0, -2.0, 4.0, 6.0], 17)).unwrap();
        let mut rng = Rng(5);
        for _ in 0..100 {
            let x = rng.range(-4.0, 4.0);
            let z = rng.range(-2.0, 6.0);
            assert_eq!(hf.sample(x, -9.0), hf.sample(x, -2.0));
            assert_eq!(hf.sample(x, 60.0), hf.sample(x, 6.0));
            assert_eq!(hf.sample(-4.5, z), hf.sample(-4.0, z));
            assert_eq!(hf.sample(1e6, z), hf.sample(4.0, z));
        }
        assert_eq!(hf.sample(-100.0, 100.0).0, hf.texel(0, 16).x);
    }

    #[test]
    fn explicit_heights_give_exact_normals_of_a_plane() {
        // h = 0.5 x - 0.25 z on a 5x4 grid: every difference quotient is exact.
        let (nx, nz) = (5usize, 4usize);
        let extent = [0.0, 0.0, 4.0, 3.0];
        let heights: Vec<f32> = (0..nx * nz)
            .map(|k| 0.5 * (k % nx) as f32 - 0.25 * (k / nx) as f32)
            .collect();
        let hf = HeightField::from_heights(extent, [5, 4], &heights).unwrap();
        let want = Vec3::new(-0.5, 1.0, 0.25).normalize();
        for j in 0..nz {
            for i in 0..nx {
                let t = hf.texel(i, j);
                assert!((Vec3::new(t.y, t.z, t.w) - want).length() < 1e-6);
            }
        }
        let (h, n) = hf.sample(1.3, 2.1);
        assert!((h - (0.65 - 0.525)).abs() < 1e-6);
        assert!((n - want).length() < 1e-6);
        assert!(HeightField::from_heights(extent, [5, 4], &heights[1..]).is_err());
        assert!(HeightField::from_heights(extent, [1, 4], &heights[..4]).is_err());
    }
}
