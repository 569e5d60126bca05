//! The scene's colliders drawn in the particles' camera (`render.geometry = true`): planes as
//! bounded checker grids, spheres, boxes, the height-field terrain shaded by its normals, the
//! shapes and the scanned mesh of distance fields. UberFlow's Fig. 4 (left) shows the landscape
//! the snow settles on; this draws it.
//!
//! The triangles are built on the CPU into one vertex buffer, once for the colliders that do
//! not move; those that move (orbiting spheres) are rebuilt at each frame's time by
//! [`GeometryRenderer::replace`], from the same function that places them for the collision
//! passes. They are drawn opaque with a depth write before the particles, which are then depth-tested against
//! it without writing depth (see [`super::ParticleRenderer::draw_frame`] for the order with
//! each blending).

use glam::Vec3;

use super::isosurface::Surface;
use crate::error::{Error, Result};
use crate::scene::{Collider, SceneFile};

mod draw;
pub(super) use draw::first_pass_state;
pub use draw::GeometryRenderer;

/// Floats per vertex: position, normal, colour, checker cell size (0: plain).
const FLOATS: usize = 10;
/// Segments around a sphere's axis; rings are half as many.
const SPHERE_SEGMENTS: usize = 32;

const PLANE_COLOR: [f32; 3] = [0.50, 0.50, 0.52];
const SOLID_COLOR: [f32; 3] = [0.46, 0.50, 0.58];
const MESH_COLOR: [f32; 3] = [0.62, 0.56, 0.50];
const TERRAIN_COLOR: [f32; 3] = [0.30, 0.30, 0.29];

/// Most cells a side of the drawn terrain: a finer height field (up to 4096 nodes a side) is
/// drawn through every k-th node, so that its mesh stays near 60 MB (4096² nodes drawn whole
/// would be 4 GB of vertices, and as much again in the GL buffer).
pub const MAX_TERRAIN_CELLS: usize = 511;

/// A height field's sampled nodes, as the simulation holds them: `texels[4·(j·nx + i)..]` is
/// (height, normal) at node `(x_i, z_j)` of `extent` = `[min x, min z, max x, max z]`.
#[derive(Debug, Clone, Copy)]
pub struct Terrain<'a> {
    /// Region over the xz plane.
    pub extent: [f32; 4],
    /// Nodes per axis `[nx, nz]`.
    pub size: [u32; 2],
    /// `nx·nz` texels of (height, normal.x, normal.y, normal.z).
    pub texels: &'a [f32],
}

/// Triangles with per-vertex normals and colours, in the vertex buffer's layout.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// `FLOATS` floats per vertex, three vertices per triangle.
    pub vertices: Vec<f32>,
}

impl Mesh {
    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.vertices.len() / FLOATS
    }

    /// Whether it has no triangles.
    pub fn is_empty(&self) -> bool {
        self.vertices.is_empty()
    }

    fn vertex(&mut self, p: Vec3, n: Vec3, color: [f32; 3], cell: f32) {
        self.vertices.extend_from_slice(&[
            p.x, p.y, p.z, n.x, n.y, n.z, color[0], color[1], color[2], cell,
        ]);
    }

    fn triangle(&mut self, p: [Vec3; 3], n: [Vec3; 3], color: [f32; 3], cell: f32) {
        for k in 0..3 {
            self.vertex(p[k], n[k], color, cell);
        }
    }

    /// A flat-shaded triangle (its face normal; the fragment stage lights both sides).
    fn flat(&mut self, p: [Vec3; 3], color: [f32; 3]) {
        let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        self.triangle(p, [n; 3], color, 0.0);
    }

    /// The square of half side `half` on the plane through `point` with `normal`, centred at
    /// `centre` projected onto it, checkered in cells of `cell` metres.
    pub fn plane(&mut self, point: Vec3, normal: Vec3, centre: Vec3, half: f32, cell: f32) {
        let n = normal.normalize_or_zero();
        if n == Vec3::ZERO {
            return;
        }
        let c = centre - n * (centre - point).dot(n);
        let (u, v) = n.any_orthonormal_pair();
        let corner = |a: f32, b: f32| c + (u * a + v * b) * half;
        let q = [
            corner(-1.0, -1.0),
            corner(1.0, -1.0),
            corner(1.0, 1.0),
            corner(-1.0, 1.0),
        ];
        self.triangle([q[0], q[1], q[2]], [n; 3], PLANE_COLOR, cell);
        self.triangle([q[0], q[2], q[3]], [n; 3], PLANE_COLOR, cell);
    }

    /// A sphere of latitude-longitude quads with smooth normals.
    pub fn sphere(&mut self, centre: Vec3, radius: f32, color: [f32; 3]) {
        let (seg, rings) = (SPHERE_SEGMENTS, SPHERE_SEGMENTS / 2);
        let at = |i: usize, j: usize| {
            let theta = std::f32::consts::PI * j as f32 / rings as f32;
            let phi = std::f32::consts::TAU * i as f32 / seg as f32;
            Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            )
        };
        for j in 0..rings {
            for i in 0..seg {
                let n = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                let p = n.map(|d| centre + d * radius);
                self.triangle([p[0], p[1], p[2]], [n[0], n[1], n[2]], color, 0.0);
                self.triangle([p[0], p[2], p[3]], [n[0], n[2], n[3]], color, 0.0);
            }
        }
    }

    /// An axis-aligned box, six flat faces.
    pub fn cuboid(&mut self, min: Vec3, max: Vec3, color: [f32; 3]) {
        let p = |x: bool, y: bool, z: bool| {
            Vec3::new(
                if x { max.x } else { min.x },
                if y { max.y } else { min.y },
                if z { max.z } else { min.z },
            )
        };
        // Each face: four corners in order around it (either way round).
        let faces = [
            [
                p(false, false, false),
                p(false, true, false),
                p(false, true, true),
                p(false, false, true),
            ],
            [
                p(true, false, false),
                p(true, false, true),
                p(true, true, true),
                p(true, true, false),
            ],
            [
                p(false, false, false),
                p(false, false, true),
                p(true, false, true),
                p(true, false, false),
            ],
            [
                p(false, true, false),
                p(true, true, false),
                p(true, true, true),
                p(false, true, true),
            ],
            [
                p(false, false, false),
                p(true, false, false),
                p(true, true, false),
                p(false, true, false),
            ],
            [
                p(false, false, true),
                p(false, true, true),
                p(true, true, true),
                p(true, false, true),
            ],
        ];
        let centre = (min + max) * 0.5;
        for mut q in faces {
            // Wound counter-clockwise seen from outside, so that the face normal points out.
            let n = (q[1] - q[0]).cross(q[2] - q[0]);
            if n.dot(q[0] - centre) < 0.0 {
                q.reverse();
            }
            self.flat([q[0], q[1], q[2]], color);
            self.flat([q[0], q[2], q[3]], color);
        }
    }

    /// The zero surface of a distance field's nodes `s`, in `color`, lit by its gradient.
    pub fn isosurface(&mut self, s: &Surface<'_>, color: [f32; 3]) -> Result<()> {
        for (p, n) in super::isosurface::triangles(s)? {
            self.triangle(p, n, color, 0.0);
        }
        Ok(())
    }

    /// The height field's grid, two triangles per cell, each node at its sampled height with its
    /// sampled normal (what the collision pass interpolates between).
    pub fn terrain(&mut self, t: &Terrain<'_>) -> Result<()> {
        let [nx, nz] = t.size.map(|n| n as usize);
        if nx < 2 || nz < 2 || t.texels.len() != 4 * nx * nz {
            return Err(Error::InvalidInput(format!(
                "terrain of {nx}x{nz} nodes with {} floats: needs at least 2x2 nodes of 4 floats",
                t.texels.len()
            )));
        }
        let [x0, z0, x1, z1] = t.extent;
        // The drawn nodes: every k-th along each axis, and always the last.
        let drawn = |n: usize| -> Vec<usize> {
            let k = (n - 1).div_ceil(MAX_TERRAIN_CELLS);
            let mut v: Vec<usize> = (0..n - 1).step_by(k).collect();
            v.push(n - 1);
            v
        };
        let (xs, zs) = (drawn(nx), drawn(nz));
        self.vertices
            .reserve(FLOATS * 6 * (xs.len() - 1) * (zs.len() - 1));
        let node = |i: usize, j: usize| {
            let k = 4 * (j * nx + i);
            let x = x0 + (x1 - x0) * i as f32 / (nx - 1) as f32;
            let z = z0 + (z1 - z0) * j as f32 / (nz - 1) as f32;
            let s = &t.texels[k..k + 4];
            (Vec3::new(x, s[0], z), Vec3::new(s[1], s[2], s[3]))
        };
        for z in zs.windows(2) {
            for x in xs.windows(2) {
                let q = [
                    node(x[0], z[0]),
                    node(x[1], z[0]),
                    node(x[1], z[1]),
                    node(x[0], z[1]),
                ];
                for tri in [[0, 2, 1], [0, 3, 2]] {
                    let p = tri.map(|k| q[k].0);
                    let n = tri.map(|k| q[k].1);
                    self.triangle(p, n, TERRAIN_COLOR, 0.0);
                }
            }
        }
        Ok(())
    }

    /// Every collider of `scene` where the simulation has it at time `t`: [`fixed`](Self::fixed)
    /// and [`moving`](Self::moving) together.
    pub fn of_scene(
        scene: &SceneFile,
        terrain: Option<&Terrain<'_>>,
        surface: Option<&Surface<'_>>,
        t: f64,
    ) -> Result<Mesh> {
        let mut m = Mesh::fixed(scene, terrain, surface)?;
        m.vertices.extend(Mesh::moving(scene, t).vertices);
        Ok(m)
    }

    /// The colliders that do not move: planes as squares around the camera's target,
    /// `camera.distance` to each side (an infinite plane cannot be drawn; this covers what the
    /// camera sees of it), still spheres, boxes, the first height field from `terrain` (the
    /// simulation's nodes), and each distance field's spheres, boxes or mesh triangles, or for
    /// a field from a file the zero surface of `surface` (the simulation's nodes).
    pub fn fixed(
        scene: &SceneFile,
        terrain: Option<&Terrain<'_>>,
        surface: Option<&Surface<'_>>,
    ) -> Result<Mesh> {
        let c = &scene.colliders;
        let cam = &scene.render.camera;
        let mut m = Mesh::default();
        let half = cam.distance.max(1e-3);
        let mut terrain = terrain;
        for collider in c.iter() {
            match collider {
                Collider::Plane(p) => {
                    let (point, normal) = (Vec3::from(p.point), Vec3::from(p.normal));
                    m.plane(
                        point,
                        normal,
                        Vec3::from(cam.target),
                        half,
                        checker_cell(half),
                    );
                }
                // Orbiting spheres are drawn by `moving`.
                Collider::Sphere(s) if s.orbit.is_some() => {}
                Collider::Sphere(s) => {
                    m.sphere(Vec3::from(s.center_at(0.0)), s.radius, SOLID_COLOR)
                }
                Collider::Box(b) => m.cuboid(Vec3::from(b.min), Vec3::from(b.max), SOLID_COLOR),
                // The simulation's nodes of the first height field (the one the pass reads).
                Collider::HeightField(_) => {
                    if let Some(t) = terrain.take() {
                        m.terrain(t)?;
                    }
                }
                Collider::Sdf(sdf) => {
                    for t in &sdf.triangles {
                        m.flat(t.map(Vec3::from), MESH_COLOR);
                    }
                    for s in &sdf.spheres {
                        m.sphere(Vec3::new(s[0], s[1], s[2]), s[3], SOLID_COLOR);
                    }
                    for b in &sdf.boxes {
                        let (lo, hi) = (Vec3::new(b[0], b[1], b[2]), Vec3::new(b[3], b[4], b[5]));
                        m.cuboid(lo, hi, SOLID_COLOR);
                    }
                }
            }
        }
        if let Some(s) = surface {
            m.isosurface(s, MESH_COLOR)?;
        }
        Ok(m)
    }

    /// The colliders that move (spheres on an orbit), at time `t`, where
    /// [`SphereCollider::center_at`](crate::scene::SphereCollider::center_at) puts them for the
    /// collision passes. Their triangles are as many at every `t`.
    pub fn moving(scene: &SceneFile, t: f64) -> Mesh {
        let mut m = Mesh::default();
        for s in scene.colliders.sphere.iter().filter(|s| s.orbit.is_some()) {
            m.sphere(Vec3::from(s.center_at(t)), s.radius, SOLID_COLOR);
        }
        m
    }
}

/// A checker cell of 1, 2 or 5 times a power of ten, near an eighth of the plane's half side.
fn checker_cell(half: f32) -> f32 {
    let raw = half / 8.0;
    let decade = 10f32.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|k| k * decade)
        .min_by(|a, b| (a - raw).abs().total_cmp(&(b - raw).abs()))
        .unwrap_or(decade);
    step.max(1e-3)
}

/// What `render.geometry` draws of `scene`'s colliders, for the pass list.
pub fn describe(scene: &SceneFile) -> String {
    let c = &scene.colliders;
    let count = |n: usize, one: &str, many: &str| match n {
        0 => None,
        1 => Some(format!("1 {one}")),
        n => Some(format!("{n} {many}")),
    };
    // What `fixed` and `moving` draw, kind by kind: a distance field's spheres and boxes are
    // drawn as spheres and boxes.
    let (mut planes, mut spheres, mut boxes, mut heights) = (0, 0, 0, 0);
    let (mut meshes, mut triangles, mut files) = (0, 0, 0);
    for collider in c.iter() {
        match collider {
            Collider::Plane(_) => planes += 1,
            Collider::Sphere(_) => spheres += 1,
            Collider::Box(_) => boxes += 1,
            Collider::HeightField(_) => heights = 1,
            Collider::Sdf(s) => {
                spheres += s.spheres.len();
                boxes += s.boxes.len();
                meshes += !s.triangles.is_empty() as usize;
                triangles += s.triangles.len();
                files += s.distances.is_some() as usize;
            }
        }
    }
    let parts: Vec<String> = [
        count(planes, "plane (checker)", "planes (checker)"),
        count(spheres, "sphere", "spheres"),
        count(boxes, "box", "boxes"),
        count(heights, "height field", "height fields"),
        (meshes > 0).then(|| format!("{triangles} mesh triangles")),
        count(
            files,
            "distance field's zero surface",
            "distance fields' zero surfaces",
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    if parts.is_empty() {
        "nothing".to_owned()
    } else {
        parts.join(", ")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checker_cells_are_round_numbers() {
        assert!((checker_cell(4.0) - 0.5).abs() < 1e-6);
        assert_eq!(checker_cell(8.0), 1.0);
        assert!((checker_cell(2.2) - 0.2).abs() < 1e-6);
    }

    #[test]
    fn meshes_have_the_expected_triangles() {
        let mut m = Mesh::default();
        m.cuboid(Vec3::ZERO, Vec3::ONE, SOLID_COLOR);
        assert_eq!(m.len(), 36);
        // Every face normal points out of the box: away from its centre.
        for v in m.vertices.chunks_exact(FLOATS) {
            let (p, n) = (Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
            assert!((p - Vec3::splat(0.5)).dot(n) > 0.0, "{p} {n}");
        }
        let mut s = Mesh::default();
        s.sphere(Vec3::new(1.0, 2.0, 3.0), 0.5, SOLID_COLOR);
        for v in s.vertices.chunks_exact(FLOATS) {
            let p = Vec3::new(v[0], v[1], v[2]);
            assert!(((p - Vec3::new(1.0, 2.0, 3.0)).length() - 0.5).abs() < 1e-5);
        }
        let texels: Vec<f32> = (0..9).flat_map(|k| [k as f32, 0.0, 1.0, 0.0]).collect();
        let mut t = Mesh::default();
        let terrain = Terrain {
            extent: [0.0, 0.0, 2.0, 2.0],
            size: [3, 3],
            texels: &texels,
        };
        t.terrain(&terrain).unwrap();
        assert_eq!(t.len(), 4 * 6);
        // Node (2, 1) is at x = 2, z = 1 with height 5.
        assert!(t
            .vertices
            .chunks_exact(FLOATS)
            .any(|v| v[0] == 2.0 && v[2] == 1.0 && v[1] == 5.0));
    }
}
