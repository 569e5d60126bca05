//! The signed distance field (UberFlow §4.6): the union of a scene's spheres and boxes, or a
//! triangle mesh scan-converted on the GPU.

use std::sync::OnceLock;

use glam::{Vec3, Vec4};

use super::grid::{self, Axis, Grid3};
use super::mesh::mesh_distance;
use super::scan::scan_convert;
use crate::error::{Error, Result};
use crate::gl::{Context, Texture3D};
use crate::scene::{SdfCollider, Triangle, MAX_TRIANGLES};

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

/// The shapes a field is built from.
#[derive(Debug, Clone, PartialEq)]
enum Shapes {
    /// The union of spheres and boxes: the texels are computed on the CPU and uploaded.
    Union {
        spheres: Vec<[f32; 4]>,
        boxes: Vec<[f32; 6]>,
    },
    /// A closed triangle mesh: scan-converted on the GPU (`scan`), the CPU's texels computed
    /// only when the CPU samples the field.
    Mesh(Vec<Triangle>),
    /// Distances read from a file (`field`): its texels, interpolated trilinearly.
    File(Box<Grid3>),
}

impl Shapes {
    fn distance(&self, p: Vec3) -> f32 {
        match self {
            Shapes::Union { spheres, boxes } => union_distance(spheres, boxes, p),
            Shapes::Mesh(triangles) => mesh_distance(triangles, p),
            Shapes::File(grid) => grid.trilinear(p).x,
        }
    }
}

/// A signed distance field in a 3D R32F texture (UberFlow §4.6): negative inside the union of
/// the scene's spheres and boxes, or inside its triangle mesh.
///
/// The union's distance is the minimum of the shapes' exact distances: exact outside the union
/// and inside a single shape, a lower bound of the depth where shapes overlap. It is
/// 1-Lipschitz, which is what the error bounds of the tests rest on. A mesh's distance is the
/// distance to its nearest triangle, negative where the mesh's winding number exceeds 1/2 in
/// magnitude (inside a closed mesh); also 1-Lipschitz away from the surface's sign change.
///
/// A mesh's field is made on the GPU by [`DistanceField::upload`] (one fragment pass per slice,
/// `scan`); the CPU's copy of its texels (for [`DistanceField::sample`] and the CPU twins) is
/// computed from the same formula in double precision the first time it is needed.
#[derive(Debug, Clone, PartialEq)]
pub struct DistanceField {
    axes: [Axis; 3],
    shapes: Shapes,
    grid: OnceLock<Grid3>,
}

impl DistanceField {
    /// Samples the exact distance of `c`'s shapes at the nodes of `c.bounds`, `c.resolution` per
    /// axis; for a mesh (`c.triangles`, read by `scene::parse` from `c.mesh`) that is left to
    /// the GPU's scan conversion in [`DistanceField::upload`].
    pub fn new(c: &SdfCollider) -> Result<Self> {
        if let Some(d) = &c.distances {
            let axes = grid::axes("distance field", c.bounds, d.size)?;
            let grid = Grid3::from_data("distance field", axes, 1, d.data.clone())?;
            return Ok(DistanceField {
                axes,
                shapes: Shapes::File(Box::new(grid.clone())),
                grid: OnceLock::from(grid),
            });
        }
        let r = c.resolution;
        let axes = grid::axes("distance field", c.bounds, [r, r, r])?;
        if c.mesh.is_some() || !c.triangles.is_empty() {
            return Self::mesh(c, axes);
        }
        if c.spheres.is_empty() && c.boxes.is_empty() {
            return Err(Error::InvalidInput(
                "distance field: needs at least one sphere or box, or a mesh".into(),
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
        let shapes = Shapes::Union {
            spheres: c.spheres.clone(),
            boxes: c.boxes.clone(),
        };
        let grid = Grid3::from_axes(axes, 1, |p| Vec4::splat(shapes.distance(p)));
        Ok(DistanceField {
            axes,
            shapes,
            grid: OnceLock::from(grid),
        })
    }

    fn mesh(c: &SdfCollider, axes: [Axis; 3]) -> Result<Self> {
        let name = c.mesh.as_deref().unwrap_or("the mesh");
        if c.triangles.is_empty() {
            return Err(Error::InvalidInput(format!(
                "distance field: {name} has no triangles (scene::parse reads them from the file)"
            )));
        }
        if !(c.spheres.is_empty() && c.boxes.is_empty()) {
            return Err(Error::InvalidInput(
                "distance field: either a mesh or spheres and boxes, not both".into(),
            ));
        }
        if c.triangles.len() > MAX_TRIANGLES {
            return Err(Error::InvalidInput(format!(
                "distance field: {name} has {} triangles, more than {MAX_TRIANGLES}",
                c.triangles.len()
            )));
        }
        if c.triangles
            .iter()
            .flatten()
            .flatten()
            .any(|v| !v.is_finite())
        {
            return Err(Error::InvalidInput(format!(
                "distance field: {name} has a vertex that is not finite"
            )));
        }
        Ok(DistanceField {
            axes,
            shapes: Shapes::Mesh(c.triangles.clone()),
            grid: OnceLock::new(),
        })
    }

    /// The texels (computed now for a mesh, on the first call).
    fn grid(&self) -> &Grid3 {
        self.grid.get_or_init(|| {
            Grid3::from_axes(self.axes, 1, |p| Vec4::splat(self.shapes.distance(p)))
        })
    }

    /// The mesh's triangles (empty for spheres and boxes).
    pub fn triangles(&self) -> &[Triangle] {
        match &self.shapes {
            Shapes::Mesh(t) => t,
            Shapes::Union { .. } | Shapes::File(_) => &[],
        }
    }

    /// The exact distance of the union or the mesh at `p` (double precision, rounded once); for
    /// a field from a file, its trilinear interpolation.
    pub fn analytic_distance(&self, p: Vec3) -> f32 {
        self.shapes.distance(p)
    }

    /// `[min corner, max corner]`: the `bmin`, `bmax` arguments of `sdf_sample`.
    pub fn bounds(&self) -> [Vec3; 2] {
        let [x, y, z] = self.axes;
        [
            Vec3::new(x.min, y.min, z.min),
            Vec3::new(x.max, y.max, z.max),
        ]
    }

    /// Nodes per axis: the texture size and the `res` argument of `sdf_sample`.
    pub fn resolution(&self) -> [u32; 3] {
        self.axes.map(|a| a.n)
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
        let [x, y, z] = self.axes;
        Vec3::new(x.node(i), y.node(j), z.node(k))
    }

    /// Texel `(i, j, k)`: the distance at that node.
    pub fn texel(&self, i: usize, j: usize, k: usize) -> f32 {
        self.grid().texel(i, j, k).x
    }

    /// The texture data, R32F, x-fastest.
    pub fn texels(&self) -> &[f32] {
        &self.grid().data
    }

    /// Trilinear interpolation of the distance. The twin of `sdf_sample` in GLSL.
    pub fn sample(&self, p: Vec3) -> f32 {
        self.grid().trilinear(p).x
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

    /// The field in an R32F 3D texture labelled `sdf`: the CPU's texels uploaded for spheres
    /// and boxes; a mesh scan-converted on the GPU, one fragment pass per slice (UberFlow §4.6).
    pub fn upload(&self, ctx: &Context) -> Result<Texture3D> {
        match &self.shapes {
            Shapes::Union { .. } | Shapes::File(_) => self.grid().upload(ctx, "sdf"),
            Shapes::Mesh(t) => scan_convert(ctx, t, self.bounds(), self.resolution()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_util::Rng;
    use super::*;

    fn sdf(bounds: [[f32; 3]; 2], resolution: u32) -> SdfCollider {
        SdfCollider {
            bounds,
            resolution,
            spheres: vec![[-0.3, 0.1, 0.2, 0.45]],
            boxes: vec![[0.2, -0.6, -0.4, 0.8, 0.0, 0.3]],
            mesh: None,
            triangles: vec![],
            field: None,
            distances: None,
            friction: 0.0,
            resilience: 1.0,
        }
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
            mesh: None,
            triangles: vec![],
            field: None,
            distances: None,
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
            mesh: None,
            triangles: vec![],
            field: None,
            distances: None,
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
}
