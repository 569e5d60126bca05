//! The lookup fields that colliders and forces sample (UberFlow §4.6, Latta eq. 1): a height
//! field (2D), a signed distance field (3D) and a wind flow field (3D). Each is built on the CPU
//! from its scene description, uploaded once to a float texture, and sampled in GLSL by
//! `glsl/sim/fields.glsl` with `texelFetch` only: the interpolation is done by hand (no hardware
//! filtering, whose 8-bit interpolation weights would make the GPU disagree with the CPU). Every
//! field has a CPU sampler that is the twin of its GLSL function, with the same arithmetic in the
//! same order, so the two agree up to float rounding (tests/fields.rs).
//!
//! # Conventions (identical for the three fields)
//!
//! - **Nodes.** An axis from `min` to `max` with `n >= 2` nodes has its nodes at
//!   `x_i = min + i (max - min) / (n - 1)`, `i = 0 .. n-1`: the first node lies on `min`, the last
//!   on `max` (node-centred, not cell-centred). Texel `i` of that axis holds the value at `x_i`.
//!   Texel `(i, j)` of the height field is `i` along x and `j` along z; texel `(i, j, k)` of a 3D
//!   field is `(x, y, z)`. Uploads are x-fastest: value `c` of texel `(i, j, k)` is at
//!   `((k ny + j) nx + i) channels + c`.
//! - **Sampling.** A position maps to the continuous grid coordinate
//!   `u = (x - min) / (max - min) * (n - 1)`, clamped to `[0, n - 1]`; it lies between the nodes
//!   `i0 = floor(u)` and `i1 = min(i0 + 1, n - 1)` with the weight `t = u - i0` in `[0, 1)`.
//!   Linear interpolation is `a + t (b - a)`: a sample at a node's grid coordinate (`t = 0`)
//!   returns the node's value bit for bit, and between equal texels it returns that value
//!   exactly (so a region where the field is constant has a gradient of exactly zero, with or
//!   without fused multiply-adds). Bilinear interpolates along x first, then z; trilinear along
//!   x, then y, then z.
//! - **Outside the bounds** the coordinate is clamped per axis: the field continues constant
//!   along each axis from its boundary values (a landscape that goes on flat from its edge
//!   heights; a distance field that stops growing; a wind that keeps its boundary velocity).
//! - Positions must be finite.

use glam::{Vec3, Vec4};

use crate::error::{Error, Result};
use crate::gl::{Context, Texture, Texture3D, TextureDesc, TextureFormat};
use crate::scene::{HeightFieldCollider, SdfCollider, Wind};

/// One axis of a field's grid: `n` nodes from `min` to `max`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Axis {
    min: f32,
    max: f32,
    n: u32,
}

impl Axis {
    fn new(what: &str, min: f32, max: f32, n: u32) -> Result<Self> {
        if n < 2 {
            return Err(Error::InvalidInput(format!(
                "{what}: resolution {n} is too small, a field needs at least 2 nodes per axis"
            )));
        }
        if !(min.is_finite() && max.is_finite() && min < max) {
            return Err(Error::InvalidInput(format!(
                "{what}: the range {min}..{max} must be finite with min < max"
            )));
        }
        Ok(Axis { min, max, n })
    }

    /// Position of node `i`, computed in double precision so that the last node is `max`.
    fn node(&self, i: usize) -> f32 {
        let (lo, hi) = (self.min as f64, self.max as f64);
        (lo + i as f64 * (hi - lo) / (self.n - 1) as f64) as f32
    }

    /// Node spacing in double precision.
    fn spacing_f64(&self) -> f64 {
        (self.max as f64 - self.min as f64) / (self.n - 1) as f64
    }

    /// The nodes `i0`, `i1` around `x` and the weight `t` (see the module doc); the twin of
    /// `field_cell` in GLSL.
    fn cell(&self, x: f32) -> (usize, usize, f32) {
        let top = (self.n - 1) as f32;
        let u = ((x - self.min) / (self.max - self.min) * top).clamp(0.0, top);
        let i0 = u.floor() as usize;
        (i0, (i0 + 1).min(self.n as usize - 1), u - i0 as f32)
    }
}

/// `a + t (b - a)` per component (exactly `a` at `t = 0` and where `a == b`), the twin of
/// `field_lerp` in GLSL. (Not glam's `Vec4::lerp`, which computes `a (1 - t) + b t`: not exact
/// between equal texels.)
fn lerp(a: Vec4, b: Vec4, t: f32) -> Vec4 {
    a + t * (b - a)
}

/// A 3D grid of `C`-channel texels with the module's conventions.
#[derive(Debug, Clone, PartialEq)]
struct Grid3 {
    axes: [Axis; 3],
    channels: usize,
    data: Vec<f32>,
}

impl Grid3 {
    fn build(
        what: &str,
        bounds: [[f32; 3]; 2],
        res: [u32; 3],
        channels: usize,
        f: impl Fn(Vec3) -> Vec4,
    ) -> Result<Self> {
        let axes = [
            Axis::new(&format!("{what} x"), bounds[0][0], bounds[1][0], res[0])?,
            Axis::new(&format!("{what} y"), bounds[0][1], bounds[1][1], res[1])?,
            Axis::new(&format!("{what} z"), bounds[0][2], bounds[1][2], res[2])?,
        ];
        let [nx, ny, nz] = res.map(|n| n as usize);
        let mut data = Vec::with_capacity(nx * ny * nz * channels);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let p = Vec3::new(axes[0].node(i), axes[1].node(j), axes[2].node(k));
                    data.extend_from_slice(&f(p).to_array()[..channels]);
                }
            }
        }
        Ok(Grid3 {
            axes,
            channels,
            data,
        })
    }

    fn res(&self) -> [u32; 3] {
        self.axes.map(|a| a.n)
    }

    fn bounds(&self) -> [Vec3; 2] {
        let [x, y, z] = self.axes;
        [
            Vec3::new(x.min, y.min, z.min),
            Vec3::new(x.max, y.max, z.max),
        ]
    }

    fn node(&self, [i, j, k]: [usize; 3]) -> Vec3 {
        Vec3::new(
            self.axes[0].node(i),
            self.axes[1].node(j),
            self.axes[2].node(k),
        )
    }

    /// Texel `(i, j, k)` with its channels in x, y, z, w (missing channels 0).
    fn texel(&self, i: usize, j: usize, k: usize) -> Vec4 {
        let [nx, ny, _] = self.res().map(|n| n as usize);
        let at = ((k * ny + j) * nx + i) * self.channels;
        let mut v = [0.0; 4];
        v[..self.channels].copy_from_slice(&self.data[at..at + self.channels]);
        Vec4::from_array(v)
    }

    /// Trilinear interpolation: the twin of `field_trilinear` in GLSL.
    fn trilinear(&self, p: Vec3) -> Vec4 {
        let (i0, i1, tx) = self.axes[0].cell(p.x);
        let (j0, j1, ty) = self.axes[1].cell(p.y);
        let (k0, k1, tz) = self.axes[2].cell(p.z);
        let t = |a, b, c| self.texel(a, b, c);
        let c00 = lerp(t(i0, j0, k0), t(i1, j0, k0), tx);
        let c10 = lerp(t(i0, j1, k0), t(i1, j1, k0), tx);
        let c01 = lerp(t(i0, j0, k1), t(i1, j0, k1), tx);
        let c11 = lerp(t(i0, j1, k1), t(i1, j1, k1), tx);
        let c0 = lerp(c00, c10, ty);
        let c1 = lerp(c01, c11, ty);
        lerp(c0, c1, tz)
    }

    fn upload(&self, ctx: &Context, label: &str) -> Result<Texture3D> {
        let format = match self.channels {
            1 => TextureFormat::R32F,
            _ => TextureFormat::Rgba32F,
        };
        Texture3D::new(ctx, label, format, self.res(), Some(&self.data))
    }
}

// ---------------------------------------------------------------------------------------------
// Height field
// ---------------------------------------------------------------------------------------------

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
    pub fn new(c: &HeightFieldCollider) -> Result<Self> {
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

// ---------------------------------------------------------------------------------------------
// Signed distance field
// ---------------------------------------------------------------------------------------------

/// Exact signed distance to a sphere `[x, y, z, r]`, in double precision.
fn sphere_distance(p: [f64; 3], s: [f32; 4]) -> f64 {
    let d = [0, 1, 2].map(|k| p[k] - s[k] as f64);
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - s[3] as f64
}

/// Exact signed distance to a box `[min x, min y, min z, max x, max y, max z]`: the Euclidean
/// distance outside, minus the distance to the nearest face inside.
fn box_distance(p: [f64; 3], b: [f32; 6]) -> f64 {
    let q = [0, 1, 2].map(|k| {
        let (lo, hi) = (b[k] as f64, b[k + 3] as f64);
        (p[k] - 0.5 * (lo + hi)).abs() - 0.5 * (hi - lo)
    });
    let outside = q.map(|v| v.max(0.0));
    let outside =
        (outside[0] * outside[0] + outside[1] * outside[1] + outside[2] * outside[2]).sqrt();
    let inside = q[0].max(q[1]).max(q[2]).min(0.0);
    outside + inside
}

/// The union's distance at `p`: the least of the shapes' distances, rounded once to `f32`.
fn union_distance(spheres: &[[f32; 4]], boxes: &[[f32; 6]], p: Vec3) -> f32 {
    let q = p.to_array().map(|v| v as f64);
    let s = spheres.iter().map(|s| sphere_distance(q, *s));
    let b = boxes.iter().map(|b| box_distance(q, *b));
    s.chain(b).fold(f64::INFINITY, f64::min) as f32
}

/// A signed distance field in a 3D R32F texture (UberFlow §4.6): negative inside the union of
/// the scene's spheres and boxes.
///
/// The union's distance is the minimum of the shapes' exact distances: exact outside the union
/// and inside a single shape, a lower bound of the depth where shapes overlap. It is
/// 1-Lipschitz, which is what the error bounds of the tests rest on.
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceField {
    grid: Grid3,
    spheres: Vec<[f32; 4]>,
    boxes: Vec<[f32; 6]>,
}

impl DistanceField {
    /// Samples the exact distance of `c`'s shapes at the nodes of `c.bounds`, `c.resolution` per
    /// axis.
    pub fn new(c: &SdfCollider) -> Result<Self> {
        if c.spheres.is_empty() && c.boxes.is_empty() {
            return Err(Error::InvalidInput(
                "distance field: needs at least one sphere or box".into(),
            ));
        }
        if let Some(s) = c
            .spheres
            .iter()
            .find(|s| s.iter().any(|v| !v.is_finite()) || s[3] <= 0.0)
        {
            return Err(Error::InvalidInput(format!(
                "distance field: sphere {s:?} needs a finite centre and a radius above 0"
            )));
        }
        if let Some(b) = c
            .boxes
            .iter()
            .find(|b| b.iter().any(|v| !v.is_finite()) || (0..3).any(|k| b[k] > b[k + 3]))
        {
            return Err(Error::InvalidInput(format!(
                "distance field: box {b:?} needs finite corners with min <= max on every axis"
            )));
        }
        let r = c.resolution;
        let grid = Grid3::build("distance field", c.bounds, [r, r, r], 1, |p| {
            Vec4::splat(union_distance(&c.spheres, &c.boxes, p))
        })?;
        Ok(DistanceField {
            grid,
            spheres: c.spheres.clone(),
            boxes: c.boxes.clone(),
        })
    }

    /// The exact distance of the union at `p` (double precision, rounded once).
    pub fn analytic_distance(&self, p: Vec3) -> f32 {
        union_distance(&self.spheres, &self.boxes, p)
    }

    /// `[min corner, max corner]`: the `bmin`, `bmax` arguments of `sdf_sample`.
    pub fn bounds(&self) -> [Vec3; 2] {
        self.grid.bounds()
    }

    /// Nodes per axis: the texture size and the `res` argument of `sdf_sample`.
    pub fn resolution(&self) -> [u32; 3] {
        self.grid.res()
    }

    /// Node spacing per axis, `(max - min) / (n - 1)` in single precision as the shader computes
    /// it: the step of [`DistanceField::gradient`].
    pub fn cell_size(&self) -> Vec3 {
        let [lo, hi] = self.bounds();
        let n = self.resolution().map(|n| (n - 1) as f32);
        (hi - lo) / Vec3::from_array(n)
    }

    /// Position of node `(i, j, k)`.
    pub fn node(&self, i: usize, j: usize, k: usize) -> Vec3 {
        self.grid.node([i, j, k])
    }

    /// Texel `(i, j, k)`: the distance at that node.
    pub fn texel(&self, i: usize, j: usize, k: usize) -> f32 {
        self.grid.texel(i, j, k).x
    }

    /// The texture data, R32F, x-fastest.
    pub fn texels(&self) -> &[f32] {
        &self.grid.data
    }

    /// Trilinear interpolation of the distance. The twin of `sdf_sample` in GLSL.
    pub fn sample(&self, p: Vec3) -> f32 {
        self.grid.trilinear(p).x
    }

    /// Central differences of the interpolated field with a step of one cell per axis (not
    /// normalised). The twin of the first half of `sdf_normal` in GLSL.
    pub fn gradient(&self, p: Vec3) -> Vec3 {
        let h = self.cell_size();
        let d = |e: Vec3| self.sample(p + e) - self.sample(p - e);
        Vec3::new(
            d(Vec3::new(h.x, 0.0, 0.0)) / (2.0 * h.x),
            d(Vec3::new(0.0, h.y, 0.0)) / (2.0 * h.y),
            d(Vec3::new(0.0, 0.0, h.z)) / (2.0 * h.z),
        )
    }

    /// The unit gradient, or `(0, 1, 0)` where the gradient is zero (the field is constant
    /// there, e.g. beyond a corner of the bounds). The twin of `sdf_normal` in GLSL.
    pub fn normal(&self, p: Vec3) -> Vec3 {
        let g = self.gradient(p);
        if g.dot(g) > 0.0 {
            g.normalize()
        } else {
            Vec3::Y
        }
    }

    /// Uploads the distances to an R32F 3D texture labelled `sdf`.
    pub fn upload(&self, ctx: &Context) -> Result<Texture3D> {
        self.grid.upload(ctx, "sdf")
    }
}

// ---------------------------------------------------------------------------------------------
// Flow field
// ---------------------------------------------------------------------------------------------

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
    use super::*;

    /// splitmix64: deterministic test points.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 40) as f32 / (1u64 << 24) as f32
        }
        fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.next()
        }
        fn point(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
            Vec3::new(
                self.range(lo.x, hi.x),
                self.range(lo.y, hi.y),
                self.range(lo.z, hi.z),
            )
        }
    }

    fn hills(extent: [f32; 4], resolution: u32) -> HeightFieldCollider {
        HeightFieldCollider {
            extent,
            resolution,
            base: 0.25,
            amplitude: 1.5,
            frequency: 0.7,
            friction: 0.0,
            resilience: 1.0,
        }
    }

    fn sdf(bounds: [[f32; 3]; 2], resolution: u32) -> SdfCollider {
        SdfCollider {
            bounds,
            resolution,
            spheres: vec![[-0.3, 0.1, 0.2, 0.45]],
            boxes: vec![[0.2, -0.6, -0.4, 0.8, 0.0, 0.3]],
            friction: 0.0,
            resilience: 1.0,
        }
    }

    fn wind() -> Wind {
        Wind {
            velocity: [1.0, 0.0, -0.5],
            turbulence: 0.8,
            resolution: 12,
            bounds: [[-2.0, 0.0, -1.0], [2.0, 3.0, 1.0]],
            drag: 1.0,
        }
    }

    #[test]
    fn axis_cells_clamp_and_reach_the_last_node() {
        let a = Axis::new("a", -1.0, 3.0, 5).unwrap();
        assert_eq!(a.cell(-1.0), (0, 1, 0.0));
        assert_eq!(a.cell(-7.0), (0, 1, 0.0));
        assert_eq!(a.cell(1.0), (2, 3, 0.0));
        assert_eq!(a.cell(1.5), (2, 3, 0.5));
        assert_eq!(a.cell(2.75), (3, 4, 0.75));
        assert_eq!(a.cell(3.0), (4, 4, 0.0));
        assert_eq!(a.cell(30.0), (4, 4, 0.0));
        assert_eq!(a.node(4), 3.0);
        assert!(Axis::new("a", 0.0, 1.0, 1).is_err());
        assert!(Axis::new("a", 1.0, 1.0, 4).is_err());
        assert!(Axis::new("a", 0.0, f32::NAN, 4).is_err());
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

    #[test]
    fn analytic_distance_has_the_right_sign_and_value() {
        let f = DistanceField::new(&sdf([[-1.0; 3], [1.0; 3]], 9)).unwrap();
        // Sphere centre: -r; box centre: - half the smallest side (0.3 along y).
        assert!((f.analytic_distance(Vec3::new(-0.3, 0.1, 0.2)) + 0.45).abs() < 1e-6);
        assert!((f.analytic_distance(Vec3::new(0.5, -0.3, -0.05)) + 0.3).abs() < 1e-6);
        // Outside, next to a face of the box and an edge.
        assert!((f.analytic_distance(Vec3::new(1.0, -0.3, -0.05)) - 0.2).abs() < 1e-6);
        let edge = f.analytic_distance(Vec3::new(1.1, 0.4, -0.05));
        assert!((edge - 0.5).abs() < 1e-6, "{edge}");
        // On the sphere's surface.
        assert!(f.analytic_distance(Vec3::new(-0.3, 0.55, 0.2)).abs() < 1e-6);
    }

    #[test]
    fn sampled_distance_has_the_sign_and_stays_within_the_bound() {
        let bounds = [[-1.0, -1.0, -1.0], [1.0, 0.8, 1.2]];
        let f = DistanceField::new(&sdf(bounds, 33)).unwrap();
        let h = f.cell_size();
        // The union's distance is 1-Lipschitz and trilinear interpolation is a convex
        // combination of the eight corners, each within the cell's diagonal of p: the sampled
        // distance is within one diagonal of the true one (plus rounding).
        let diag = h.length() + 1e-5;
        let [lo, hi] = f.bounds();
        let mut rng = Rng(11);
        for _ in 0..5000 {
            let p = rng.point(lo, hi);
            let (s, a) = (f.sample(p), f.analytic_distance(p));
            assert!((s - a).abs() <= diag, "{p}: sampled {s}, exact {a}");
            if a < -diag {
                assert!(s < 0.0, "{p} is inside");
            }
            if a > diag {
                assert!(s > 0.0, "{p} is outside");
            }
        }
        // Deep inside the sphere (-0.45) and the box (-0.3), and well outside both (0.94).
        assert!(f.sample(Vec3::new(-0.3, 0.1, 0.2)) < -0.45 + diag);
        assert!(f.sample(Vec3::new(0.5, -0.3, -0.05)) < -0.3 + diag);
        assert!(f.sample(Vec3::new(0.8, 0.7, 1.0)) > 0.5);
        // Nodes hold the exact distance.
        for (i, j, k) in [(0, 0, 0), (5, 17, 30), (32, 32, 32)] {
            assert_eq!(f.texel(i, j, k), f.analytic_distance(f.node(i, j, k)));
            assert_eq!(f.sample(f.node(i, j, k)), f.texel(i, j, k));
        }
    }

    #[test]
    fn smooth_regions_meet_the_interpolation_error_bound() {
        // One sphere: r(p) = |p - c| - R has second derivatives of at most 1/|p - c|, so the
        // trilinear error is at most sum(h_i^2) / (8 d) with d the least distance from the
        // centre over the cell (Sum of the 1-D bounds h^2/8 max|f''|).
        let c = SdfCollider {
            bounds: [[-1.0; 3], [1.0; 3]],
            resolution: 41,
            spheres: vec![[0.05, -0.1, 0.0, 0.5]],
            boxes: vec![],
            friction: 0.0,
            resilience: 1.0,
        };
        let f = DistanceField::new(&c).unwrap();
        let h = f.cell_size();
        let centre = Vec3::new(0.05, -0.1, 0.0);
        let mut rng = Rng(13);
        let mut worst = 0.0f32;
        for _ in 0..5000 {
            let p = rng.point(Vec3::splat(-1.0), Vec3::splat(1.0));
            let d = (p - centre).length() - h.length();
            if d < 0.2 {
                continue;
            }
            let bound = h.length_squared() / (8.0 * d) + 2e-6;
            let err = (f.sample(p) - f.analytic_distance(p)).abs();
            worst = worst.max(err / bound);
            assert!(err <= bound, "{p}: error {err} > {bound}");
        }
        assert!(worst > 0.05, "the bound should not be vacuous: {worst}");
    }

    #[test]
    fn sphere_normals_point_radially() {
        let c = SdfCollider {
            bounds: [[-1.0; 3], [1.0; 3]],
            resolution: 48,
            spheres: vec![[0.1, 0.0, -0.05, 0.4]],
            boxes: vec![],
            friction: 0.0,
            resilience: 1.0,
        };
        let f = DistanceField::new(&c).unwrap();
        let h = f.cell_size();
        let hmax = h.max_element();
        let centre = Vec3::new(0.1, 0.0, -0.05);
        let mut rng = Rng(17);
        for _ in 0..3000 {
            let p = rng.point(Vec3::splat(-1.0 + hmax), Vec3::splat(1.0 - hmax));
            // d: least distance from the centre of any cell the six samples touch.
            let d = (p - centre).length() - hmax - h.length();
            if d < 0.25 {
                continue;
            }
            // Per component: the interpolant is within e = |h|^2 / (8 d) of the exact distance,
            // so the difference quotient of the interpolant is within e / h_i of the exact
            // quotient, which is within h_i^2 / 6 * max|r'''| <= h_i^2 / (2 d^2) of the exact
            // derivative. The normal of a gradient g with |g_true| = 1 is off by at most
            // asin(|g - g_true|).
            let e = h.length_squared() / (8.0 * d);
            let comp = Vec3::splat(e) / h + h * h / (2.0 * d * d);
            let err = comp.length();
            let want = (p - centre).normalize();
            let n = f.normal(p);
            assert!((n.length() - 1.0).abs() < 1e-5);
            let cos = n.dot(want);
            assert!(
                cos >= (1.0 - err * err).sqrt() - 1e-5,
                "{p}: normal {n}, radial {want}, cos {cos}, allowed angle {err}"
            );
        }
        // Where the field is constant (beyond a corner) the normal falls back to +y.
        assert_eq!(f.normal(Vec3::splat(5.0)), Vec3::Y);
    }

    #[test]
    fn distance_field_rejects_bad_descriptions() {
        let mut c = sdf([[-1.0; 3], [1.0; 3]], 8);
        c.resolution = 1;
        assert!(DistanceField::new(&c).is_err());
        let mut c = sdf([[-1.0; 3], [1.0, -2.0, 1.0]], 8);
        assert!(DistanceField::new(&c).is_err());
        c.bounds = [[-1.0; 3], [1.0; 3]];
        c.spheres.clear();
        c.boxes.clear();
        assert!(DistanceField::new(&c).is_err());
        c.spheres.push([0.0, 0.0, 0.0, 0.0]);
        assert!(DistanceField::new(&c).is_err());
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
