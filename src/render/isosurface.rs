//! The zero level set of a sampled distance field (a `[[colliders.sdf]] field` from a file),
//! as triangles for [`super::Mesh::isosurface`]: marching tetrahedra over the field's own nodes,
//! so the surface drawn is where the trilinear field the collision pass samples crosses zero,
//! to within the linear interpolation along each tetrahedron's edges.

use glam::Vec3;

use crate::error::{Error, Result};

/// A triangle of the surface: its corners and their unit normals, counter-clockwise seen from
/// outside.
pub type Triangle = ([Vec3; 3], [Vec3; 3]);

/// A distance field's nodes as the simulation holds them: `texels[(k·ny + j)·nx + i]` is the
/// distance at node `(i, j, k)` of the box `bounds`, negative inside.
#[derive(Debug, Clone, Copy)]
pub struct Surface<'a> {
    /// `[min corner, max corner]`.
    pub bounds: [Vec3; 2],
    /// Nodes per axis `[nx, ny, nz]`.
    pub size: [u32; 3],
    /// `nx·ny·nz` distances, x fastest.
    pub texels: &'a [f32],
}

/// The six tetrahedra of a cube around its diagonal from corner 0 to corner 7 (corner c is
/// offset by `c & 1` in x, `c >> 1 & 1` in y, `c >> 2 & 1` in z): they share faces, so the
/// surface has no cracks between cells.
const TETRAHEDRA: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 3, 2, 7],
    [0, 2, 6, 7],
    [0, 6, 4, 7],
    [0, 4, 5, 7],
    [0, 5, 1, 7],
];

impl Surface<'_> {
    fn node(&self, i: usize, j: usize, k: usize) -> (Vec3, f32) {
        let [nx, ny, nz] = self.size.map(|n| n as usize);
        let [lo, hi] = self.bounds;
        let t = Vec3::new(
            i as f32 / (nx - 1) as f32,
            j as f32 / (ny - 1) as f32,
            k as f32 / (nz - 1) as f32,
        );
        (lo + (hi - lo) * t, self.texels[(k * ny + j) * nx + i])
    }

    /// The field's gradient at node `(i, j, k)` by differences (one-sided at the border):
    /// the outward normal there, before normalising.
    fn gradient(&self, i: usize, j: usize, k: usize) -> Vec3 {
        let n = self.size.map(|n| n as usize);
        let at = [i, j, k];
        let mut g = [0.0f32; 3];
        for (axis, g) in g.iter_mut().enumerate() {
            let (a, b) = (at[axis].saturating_sub(1), (at[axis] + 1).min(n[axis] - 1));
            let pick = |c: usize| {
                let mut p = at;
                p[axis] = c;
                self.node(p[0], p[1], p[2])
            };
            let ((pa, da), (pb, db)) = (pick(a), pick(b));
            *g = (db - da) / (pb[axis] - pa[axis]);
        }
        Vec3::from_array(g)
    }
}

/// The triangles where `s` is zero, with normals from the field's gradient.
pub fn triangles(s: &Surface<'_>) -> Result<Vec<Triangle>> {
    let [nx, ny, nz] = s.size.map(|n| n as usize);
    if nx < 2 || ny < 2 || nz < 2 || s.texels.len() != nx * ny * nz {
        return Err(Error::InvalidInput(format!(
            "distance field of {nx}x{ny}x{nz} nodes with {} values: needs at least 2 nodes \
             per axis and one value per node",
            s.texels.len()
        )));
    }
    let mut out = Vec::new();
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let corner = |c: usize| (i + (c & 1), j + (c >> 1 & 1), k + (c >> 2 & 1));
                let nodes: [(Vec3, f32, Vec3); 8] = std::array::from_fn(|c| {
                    let (a, b, d) = corner(c);
                    let (p, v) = s.node(a, b, d);
                    (p, v, s.gradient(a, b, d))
                });
                if nodes.iter().all(|n| n.1 < 0.0) || nodes.iter().all(|n| n.1 >= 0.0) {
                    continue;
                }
                for t in TETRAHEDRA {
                    tetrahedron(t.map(|c| nodes[c]), &mut out);
                }
            }
        }
    }
    Ok(out)
}

/// The zero crossing in one tetrahedron: nothing, a triangle or a quad (two triangles).
fn tetrahedron(v: [(Vec3, f32, Vec3); 4], out: &mut Vec<Triangle>) {
    let cross = |a: usize, b: usize| {
        let ((pa, da, ga), (pb, db, gb)) = (v[a], v[b]);
        let t = da / (da - db);
        (pa.lerp(pb, t), ga.lerp(gb, t).normalize_or_zero())
    };
    let inside: Vec<usize> = (0..4).filter(|&c| v[c].1 < 0.0).collect();
    let outside: Vec<usize> = (0..4).filter(|&c| v[c].1 >= 0.0).collect();
    let mut emit = |q: [(Vec3, Vec3); 3]| {
        let (p, n) = (q.map(|x| x.0), q.map(|x| x.1));
        // Wound counter-clockwise seen from outside (the gradient's side).
        let face = (p[1] - p[0]).cross(p[2] - p[0]);
        if face.dot(n[0] + n[1] + n[2]) < 0.0 {
            out.push(([p[0], p[2], p[1]], [n[0], n[2], n[1]]));
        } else {
            out.push((p, n));
        }
    };
    match (inside.as_slice(), outside.as_slice()) {
        ([a], [b, c, d]) | ([b, c, d], [a]) => {
            emit([cross(*a, *b), cross(*a, *c), cross(*a, *d)]);
        }
        ([a, b], [c, d]) => {
            let q = [cross(*a, *c), cross(*a, *d), cross(*b, *d), cross(*b, *c)];
            emit([q[0], q[1], q[2]]);
            emit([q[0], q[2], q[3]]);
        }
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sphere's field gives a closed surface whose every vertex is on the sphere to within
    /// the interpolation's error (a fraction of a cell), with outward normals.
    #[test]
    fn a_sphere_field_gives_the_sphere() {
        let n = 17usize;
        let h = 2.0 / (n - 1) as f32;
        let mut texels = Vec::new();
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let p = Vec3::new(i as f32, j as f32, k as f32) * h - Vec3::ONE;
                    texels.push(p.length() - 0.6);
                }
            }
        }
        let s = Surface {
            bounds: [Vec3::splat(-1.0), Vec3::ONE],
            size: [n as u32; 3],
            texels: &texels,
        };
        let tris = triangles(&s).unwrap();
        assert!(tris.len() > 100, "{} triangles", tris.len());
        let mut area = 0.0;
        for (p, n) in &tris {
            for k in 0..3 {
                assert!((p[k].length() - 0.6).abs() < 0.2 * h, "{:?}", p[k]);
                assert!(
                    n[k].dot(p[k].normalize()) > 0.95,
                    "{:?} at {:?}",
                    n[k],
                    p[k]
                );
            }
            let face = (p[1] - p[0]).cross(p[2] - p[0]);
            assert!(face.dot(p[0]) > 0.0, "wound inwards at {:?}", p[0]);
            area += 0.5 * face.length();
        }
        let sphere = 4.0 * std::f32::consts::PI * 0.36;
        assert!(
            (area / sphere - 1.0).abs() < 0.02,
            "area {area} of {sphere}"
        );
    }
}
