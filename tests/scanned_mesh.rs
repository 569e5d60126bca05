//! The scanned distance field (UberFlow §4.6) on the GPU: a triangle mesh scan-converted one
//! fragment pass per slice against an independent CPU reference, a mesh scene keeping particles
//! out of the mesh, and bad mesh files refused at their key.

mod common;

use common::{context, no_gl_error};
use glam::Vec3;
use texflow::scene::SdfCollider;
use texflow::sim::DistanceField;

// ---------------------------------------------------------------------------------------------
// The scanned distance field (UberFlow §4.6): a triangle mesh scan-converted on the GPU, one
// fragment pass per slice, against an independent CPU reference written here: the distance to
// a triangle as the distance to its plane where the foot lies inside it, else to the nearest of
// its three edges; the sign by the parity of a ray's crossings (Möller-Trumbore), not the
// winding number the shader uses.

/// Closest distance from `p` to segment `ab`, double precision.
fn segment_distance(p: glam::DVec3, a: glam::DVec3, b: glam::DVec3) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
    (p - (a + t * ab)).length()
}

/// Distance from `p` to triangle `t`: to its plane if the foot is inside, else to its edges.
fn triangle_distance(p: glam::DVec3, t: &[glam::DVec3; 3]) -> f64 {
    let [a, b, c] = *t;
    let n = (b - a).cross(c - a).normalize();
    let foot = p - n * (p - a).dot(n);
    let inside = [(a, b), (b, c), (c, a)]
        .iter()
        .all(|&(u, v)| (v - u).cross(foot - u).dot(n) >= 0.0);
    if inside {
        (p - a).dot(n).abs()
    } else {
        segment_distance(p, a, b)
            .min(segment_distance(p, b, c))
            .min(segment_distance(p, c, a))
    }
}

/// Whether the ray from `p` along `dir` crosses triangle `t` (Möller-Trumbore).
fn ray_crosses(p: glam::DVec3, dir: glam::DVec3, t: &[glam::DVec3; 3]) -> bool {
    let [a, b, c] = *t;
    let (e1, e2) = (b - a, c - a);
    let q = dir.cross(e2);
    let det = e1.dot(q);
    if det.abs() < 1e-14 {
        return false;
    }
    let s = p - a;
    let u = s.dot(q) / det;
    let r = s.cross(e1);
    let v = dir.dot(r) / det;
    let along = e2.dot(r) / det;
    u >= 0.0 && v >= 0.0 && u + v <= 1.0 && along > 0.0
}

/// The reference signed distance: brute force over the triangles, negative where a ray in a
/// direction no face or edge of the test meshes is parallel to crosses the mesh an odd number
/// of times.
fn reference_distance(mesh: &[[[f32; 3]; 3]], p: Vec3) -> f64 {
    let p = p.as_dvec3();
    let tris: Vec<[glam::DVec3; 3]> = mesh
        .iter()
        .map(|t| t.map(|v| Vec3::from_array(v).as_dvec3()))
        .collect();
    let d = tris
        .iter()
        .map(|t| triangle_distance(p, t))
        .fold(f64::INFINITY, f64::min);
    let dir = glam::DVec3::new(0.5773, 0.6113, 0.5411).normalize();
    let crossings = tris.iter().filter(|t| ray_crosses(p, dir, t)).count();
    if crossings % 2 == 1 {
        -d
    } else {
        d
    }
}

/// A wedge (a ramp): the triangular prism under the slope y = x from x = 0 to 1, z in [0, 0.8],
/// closed, 8 triangles with outward faces.
fn wedge() -> Vec<[[f32; 3]; 3]> {
    let v = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 0.0, 0.8],
        [1.0, 0.0, 0.8],
        [1.0, 1.0, 0.8],
    ];
    let f = [
        [0, 2, 1],
        [3, 4, 5],
        [0, 1, 4],
        [0, 4, 3],
        [1, 2, 5],
        [1, 5, 4],
        [0, 3, 5],
        [0, 5, 2],
    ];
    f.iter().map(|t| t.map(|i| v[i])).collect()
}

fn blob() -> Vec<[[f32; 3]; 3]> {
    let (_, bytes) = texflow::scene::BUILTIN_MESHES[0];
    texflow::scene::read_obj(bytes).unwrap()
}

fn mesh_collider(mesh: Vec<[[f32; 3]; 3]>, bounds: [[f32; 3]; 2], resolution: u32) -> SdfCollider {
    SdfCollider {
        bounds,
        resolution,
        spheres: vec![],
        boxes: vec![],
        mesh: Some("test".into()),
        triangles: mesh,
        field: None,
        distances: None,
        friction: 0.0,
        resilience: 1.0,
    }
}

/// The GPU's scanned field at every node against the reference. The shader computes the same
/// exact distance in single precision: its error is rounding of coordinates of size about 1
/// (a few 1e-7), far below the tolerance asked of it, half a voxel (the least node spacing / 2:
/// a distance that good keeps the surface, where it changes sign, within half a cell of the
/// mesh, no worse than the trilinear sampling of the field itself). Both are asserted: half a
/// voxel everywhere, and 1e-5 (float rounding) wherever the node is more than 1e-5 from the
/// surface (on it, the sign is moot: the nodes of the wedge's faces at x = 1, z = 0, ... lie
/// exactly on the mesh, distance 0 on both sides).
#[test]
fn scanned_mesh_matches_the_brute_force_reference() {
    let ctx = context();
    for (what, mesh, bounds, res) in [
        ("wedge", wedge(), [[-0.3, -0.25, -0.2], [1.3, 1.2, 1.1]], 17),
        ("blob", blob(), [[-1.6, -0.2, -1.4], [1.6, 1.8, 1.4]], 12),
    ] {
        let f = DistanceField::new(&mesh_collider(mesh.clone(), bounds, res)).unwrap();
        let tex = f.upload(&ctx).unwrap();
        assert_eq!(tex.size(), [res; 3]);
        let gpu = tex.read_f32().unwrap();
        let half_voxel = 0.5 * f.cell_size().min_element();
        let n = res as usize;
        let (mut worst, mut inside, mut outside) = (0.0f64, 0, 0);
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let g = gpu[(k * n + j) * n + i] as f64;
                    let p = f.node(i, j, k);
                    let want = reference_distance(&mesh, p);
                    let err = (g - want).abs();
                    assert!(
                        err <= half_voxel as f64,
                        "{what} node ({i}, {j}, {k}) at {p}: GPU {g}, reference {want}, \
                         more than half a voxel ({half_voxel}) apart"
                    );
                    if want.abs() > 1e-5 {
                        assert!(
                            err <= 1e-5,
                            "{what} node ({i}, {j}, {k}) at {p}: GPU {g}, reference {want}"
                        );
                        worst = worst.max(err);
                    }
                    inside += usize::from(want < -1e-5);
                    outside += usize::from(want > 1e-5);
                }
            }
        }
        // Not vacuous: both signs occur, and the CPU twin (the shader's formula in double
        // precision) agrees too.
        assert!(
            inside > 20 && outside > 20,
            "{what}: {inside} in, {outside} out"
        );
        let twin = f.texels();
        let twin_worst = gpu
            .iter()
            .zip(twin)
            .map(|(g, c)| (g - c).abs())
            .fold(0.0f32, f32::max);
        assert!(twin_worst <= 1e-5, "{what}: GPU vs CPU twin {twin_worst}");
        eprintln!(
            "{what}: {res}^3 nodes, {} triangles: GPU vs reference at most {worst:.2e} \
             (half a voxel {half_voxel:.3}), vs the CPU twin {twin_worst:.2e}; {inside} in",
            mesh.len()
        );
    }
    no_gl_error(&ctx);
}

/// The built-in scene `mesh` on a 16x16 state: particles poured onto the scanned blob never end
/// inside it. The collider keeps the sampled field at or above 0 (Latta eq. 6-7 push-out), and
/// the sampled field is within one cell diagonal of the exact distance (the exact distance is
/// 1-Lipschitz and trilinear interpolation is a convex combination of the cell's corners), so
/// no particle may be deeper than one diagonal below the surface.
#[test]
fn mesh_scene_keeps_particles_out_of_the_mesh() {
    let ctx = context();
    let mut scene = texflow::scene::load("mesh").unwrap();
    scene.particles.size = [16, 16];
    let mesh = scene.colliders.sdf[0].triangles.clone();
    assert_eq!(mesh.len(), 320);
    let field = DistanceField::new(&scene.colliders.sdf[0]).unwrap();
    let tol = field.cell_size().length();
    let mut sim = texflow::sim::ParticleSim::new(&ctx, &scene, 7).unwrap();
    let (mut deepest, mut touched, mut checked) = (f32::INFINITY, 0usize, 0usize);
    for round in 0..8 {
        for _ in 0..20 {
            sim.step().unwrap();
        }
        let pos = sim.read_positions().unwrap();
        for p in pos.chunks_exact(4).filter(|p| p[3] > 0.0) {
            let x = Vec3::new(p[0], p[1], p[2]);
            let d = field.analytic_distance(x);
            assert!(
                d >= -tol,
                "step {}: a particle at {x} is {d} inside the mesh (tolerance {tol})",
                (round + 1) * 20
            );
            deepest = deepest.min(d);
            touched += usize::from(d < tol);
            checked += 1;
        }
    }
    // Not vacuous: particles did reach the mesh.
    assert!(touched > 50, "{touched} of {checked} samples near the mesh");
    eprintln!(
        "mesh scene: {checked} particle samples, {touched} within a diagonal ({tol:.3}) of the \
         mesh, deepest {deepest:.4}"
    );
    no_gl_error(&ctx);
}

/// A scene whose mesh is missing or malformed fails from the CLI with exit code 2, at the
/// `mesh` key's line and column.
#[test]
fn bad_mesh_files_exit_2_at_the_key() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.obj"), "v 0 0 zero\n").unwrap();
    for (mesh, needle) in [
        ("nope.obj", "cannot read mesh file"),
        ("bad.obj", "not a valid OBJ"),
    ] {
        let src = format!(
            "name = \"m\"\n[particles]\nsize = [4, 4]\n[[colliders.sdf]]\nmesh = \"{mesh}\"\n\
             bounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\nresolution = 8\n\
             [[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
             speed = [0.0, 0.0]\n"
        );
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, src).unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_texflow"))
            .args(["scene", "check"])
            .arg(&path)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert!(
            err.contains("scene.toml:5:8:") && err.contains(needle),
            "{err}"
        );
    }
}
