//! The signed distance to a triangle mesh on the CPU, in double precision: the twin of
//! `glsl/sim/sdf_slice.frag` (the same closest-point regions and the same winding-number sign),
//! which fills the CPU copy of a scanned field and checks points against it.

use glam::{DVec3, Vec3};

use crate::scene::Triangle;

/// The point of triangle `(a, b, c)` closest to `p` (Ericson, *Real-Time Collision Detection*
/// §5.1.5: the Voronoi regions of the vertices, the edges and the face in turn).
pub(super) fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + (d1 / (d1 - d3)) * ab;
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + (d2 / (d2 - d6)) * ac;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Solid angle of triangle `(a, b, c)` (relative to the point), signed by its orientation (van
/// Oosterom and Strackee): `tan(Ω/2) = a·(b×c) / (|a||b||c| + (a·b)|c| + (a·c)|b| + (b·c)|a|)`.
pub(super) fn solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    if num == 0.0 && den == 0.0 {
        return 0.0;
    }
    2.0 * num.atan2(den)
}

/// The generalised winding number of the mesh at `p`: 1 inside a closed mesh with outward
/// (counter-clockwise) faces, -1 with inward ones, 0 outside.
pub(super) fn winding_number(triangles: &[Triangle], p: Vec3) -> f64 {
    let p = p.as_dvec3();
    let omega: f64 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| Vec3::from_array(v).as_dvec3() - p);
            solid_angle(a, b, c)
        })
        .sum();
    omega / (4.0 * std::f64::consts::PI)
}

/// Signed distance from `p` to the mesh (negative inside, where `|winding number| > 1/2`),
/// rounded once to `f32`.
pub(super) fn mesh_distance(triangles: &[Triangle], p: Vec3) -> f32 {
    let q = p.as_dvec3();
    let d2 = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|v| Vec3::from_array(v).as_dvec3());
            (q - closest_on_triangle(q, a, b, c)).length_squared()
        })
        .fold(f64::INFINITY, f64::min);
    let d = d2.sqrt();
    (if winding_number(triangles, p).abs() > 0.5 {
        -d
    } else {
        d
    }) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit cube [0, 1]³ of 12 outward triangles.
    fn cube() -> Vec<Triangle> {
        let v = |i: usize| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32];
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        quads
            .iter()
            .flat_map(|q| [[v(q[0]), v(q[1]), v(q[2])], [v(q[0]), v(q[2]), v(q[3])]])
            .collect()
    }

    #[test]
    fn cube_distances_and_signs_are_exact() {
        let c = cube();
        let d = |x, y, z| mesh_distance(&c, Vec3::new(x, y, z));
        assert!((winding_number(&c, Vec3::splat(0.5)) - 1.0).abs() < 1e-12);
        assert!(winding_number(&c, Vec3::splat(2.0)).abs() < 1e-12);
        assert_eq!(d(0.5, 0.5, 0.5), -0.5);
        assert_eq!(d(0.5, 0.2, 0.5), -0.2);
        assert_eq!(d(1.5, 0.5, 0.5), 0.5);
        assert!((d(2.0, 2.0, 0.5) - 2f32.sqrt()).abs() < 1e-6);
        assert!((d(2.0, 2.0, 2.0) - 3f32.sqrt()).abs() < 1e-6);
        assert_eq!(d(1.0, 0.5, 0.5), 0.0);
        // Reversed faces give a winding number of -1: still inside.
        let r: Vec<Triangle> = c.iter().map(|t| [t[0], t[2], t[1]]).collect();
        assert_eq!(mesh_distance(&r, Vec3::new(0.5, 0.2, 0.5)), -0.2);
    }
}
