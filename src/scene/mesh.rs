//! Triangle meshes for the scanned distance field (UberFlow §4.6: "we first scan-convert the
//! original scene into a signed distance representation"): the OBJ file that
//! `[[colliders.sdf]] mesh` names, read when the scene is parsed, so that a missing or bad file
//! is a scene error at the key's line and column. Data only: the scan conversion itself is
//! `sim::fields` (one fragment pass per slice of the 3D texture).
//!
//! The file is read relative to the scene file's folder; a built-in scene reads the meshes
//! compiled into the binary ([`super::sources`]). Faces are triangulated (fans), triangles of
//! zero area (and the segments `l` and two-vertex faces, which the OBJ reader turns into such
//! triangles) are dropped: they bound no volume.

use std::path::Path;

use toml::de::DeTable;
use toml::Spanned;

use super::locate::{locate, scene_error, Key};
use super::schema::SceneFile;
use super::sources::builtin_mesh;
use crate::error::Result;

use Key::{Index as I, Name as N};

/// The most triangles a mesh may have. The scan conversion keeps them in a float texture of
/// 3 × count texels (one a vertex) and tests every voxel against every triangle (brute force, as
/// the few hundred triangles of a 2004 scene allow): 1024 is the smallest `GL_MAX_TEXTURE_SIZE`
/// that OpenGL 3.3 guarantees, and a 64³ field of 1024 triangles is already 2.7·10⁸ tests.
pub const MAX_TRIANGLES: usize = 1024;

/// A triangle: three vertices.
pub type Triangle = [[f32; 3]; 3];

/// Reads the triangles of an OBJ file's text: every object, every face triangulated, triangles
/// of zero area dropped. Errors say what is wrong with the file (not where the key is).
pub fn read_obj(bytes: &[u8]) -> std::result::Result<Vec<Triangle>, String> {
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    // Only positions are used: each face element keeps its vertex index alone (`1/2/3` -> `1`).
    // tobj 4.0.5 multiplies a texture or normal index without checking it (`f 1/-9` overflows:
    // a panic in a debug build; found by the `obj` fuzz check).
    let bytes = vertex_indices_only(bytes);
    // Materials are not needed: a `mtllib` line gets "no materials" and is otherwise ignored.
    let (models, _) = tobj::load_obj_buf(&mut &bytes[..], &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| format!("it is not a valid OBJ file ({e})"))?;
    let mut triangles = Vec::new();
    for m in &models {
        let (pos, idx) = (&m.mesh.positions, &m.mesh.indices);
        if let Some(v) = pos.chunks(3).position(|v| v.iter().any(|c| !c.is_finite())) {
            return Err(format!(
                "vertex {} of object `{}` is not finite: every coordinate must be a number",
                v + 1,
                m.name
            ));
        }
        for f in idx.chunks_exact(3) {
            let v = |k: usize| {
                let at = f[k] as usize * 3;
                [pos[at], pos[at + 1], pos[at + 2]]
            };
            let t = [v(0), v(1), v(2)];
            if area2(&t) > 0.0 {
                triangles.push(t);
            }
        }
    }
    if triangles.is_empty() {
        return Err(
            "it has no triangles (no faces of non-zero area): a distance field needs \
                    a closed surface"
                .into(),
        );
    }
    if triangles.len() > MAX_TRIANGLES {
        return Err(format!(
            "it has {} triangles, more than the {MAX_TRIANGLES} the scan conversion takes: \
             simplify the mesh",
            triangles.len()
        ));
    }
    Ok(triangles)
}

/// `bytes` with everything from a `/` to the next whitespace removed: face elements `v/vt/vn`
/// become `v` (a `/` appears nowhere else that matters here: names are not used).
fn vertex_indices_only(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(bytes.len());
    let mut skipping = false;
    for &b in bytes {
        if b.is_ascii_whitespace() {
            skipping = false;
        } else if b == b'/' {
            skipping = true;
        }
        if !skipping {
            out.push(b);
        }
    }
    out
}

/// Twice the area of a triangle, in double precision.
fn area2(t: &Triangle) -> f64 {
    let p = t.map(|v| v.map(|c| c as f64));
    let e1 = [0, 1, 2].map(|k| p[1][k] - p[0][k]);
    let e2 = [0, 1, 2].map(|k| p[2][k] - p[0][k]);
    let c = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
}

/// Reads the mesh of every distance field that names one into its `triangles`; a failure is a
/// scene error at the `mesh` key.
pub(super) fn load_meshes(
    path: &str,
    src: &str,
    doc: &Spanned<DeTable<'_>>,
    scene: &mut SceneFile,
) -> Result<()> {
    for (i, sdf) in scene.colliders.sdf.iter_mut().enumerate() {
        let Some(name) = sdf.mesh.clone() else {
            continue;
        };
        let fail = |message: String| {
            let at = locate(doc, &[N("colliders"), N("sdf"), I(i), N("mesh")]);
            scene_error(path, src, at, message)
        };
        let bytes = read(path, &name).map_err(fail)?;
        sdf.triangles = read_obj(&bytes).map_err(|m| fail(format!("mesh `{name}`: {m}")))?;
    }
    Ok(())
}

/// The bytes of mesh `name` of the scene labelled `scene` (a file path, or a built-in's label).
fn read(scene: &str, name: &str) -> std::result::Result<Vec<u8>, String> {
    if let Some(found) = builtin_mesh(scene, name) {
        return found
            .map(|b| b.to_vec())
            .ok_or_else(|| format!("the built-in scenes have no mesh `{name}`"));
    }
    let folder = Path::new(scene).parent().unwrap_or(Path::new(""));
    let file = folder.join(name);
    crate::input::read_bounded(&file, crate::input::MAX_MESH_BYTES).map_err(|e| {
        format!(
            "cannot read mesh file {}: {e} (the path is relative to the scene file's folder)",
            file.display()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_faces_are_triangulated_and_degenerate_ones_dropped() {
        let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nl 1 2\nf 1 2 2\n";
        let t = read_obj(quad.as_bytes()).unwrap();
        assert_eq!(t.len(), 2);
        assert_eq!(t[0], [[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]);
    }

    #[test]
    fn texture_and_normal_indices_are_ignored_even_out_of_range() {
        let t =
            read_obj(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1/1 2/-9 3//4\nf 1/-9\n").unwrap();
        assert_eq!(t, [[[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]]);
    }

    #[test]
    fn bad_obj_files_say_what_is_wrong() {
        let e = |s: &str| read_obj(s.as_bytes()).unwrap_err();
        assert!(
            e("v 1 x 2\n").contains("not a valid OBJ"),
            "{}",
            e("v 1 x 2\n")
        );
        assert!(e("v 0 0 0\nf 1 2 5\n").contains("not a valid OBJ"));
        assert!(e("# nothing\n").contains("no triangles"));
        assert!(e("v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").contains("vertex 1"));
        let mut many = String::new();
        for i in 0..=MAX_TRIANGLES {
            many += &format!("v {i} 0 0\nv {i} 1 0\nv {i} 0 1\n");
            let b = 3 * i + 1;
            many += &format!("f {} {} {}\n", b, b + 1, b + 2);
        }
        assert!(e(&many).contains("1025 triangles"), "{}", e(&many));
    }

    /// A scene of one mesh distance field, in `dir`, naming `mesh` on line 5.
    fn scene_with(dir: &Path, mesh: &str) -> (String, String) {
        let src = format!(
            "name = \"m\"\n[particles]\nsize = [4, 4]\n[[colliders.sdf]]\nmesh = \"{mesh}\"\n\
             bounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\nresolution = 8\n\
             [[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
             speed = [0.0, 0.0]\n"
        );
        let path = dir.join("scene.toml");
        std::fs::write(&path, &src).unwrap();
        (path.display().to_string(), src)
    }

    #[test]
    fn mesh_files_load_relative_to_the_scene_and_fail_at_the_key() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("m")).unwrap();
        let tetra = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
        std::fs::write(dir.path().join("m/tetra.obj"), tetra).unwrap();
        let (path, src) = scene_with(dir.path(), "m/tetra.obj");
        let s = super::super::parse(&path, &src).unwrap();
        assert_eq!(s.colliders.sdf[0].triangles.len(), 4);

        let mut many = String::new();
        for i in 0..=MAX_TRIANGLES {
            many += &format!("v {i} 0 0\nv {i} 1 0\nv {i} 0 1\nf -3 -2 -1\n");
        }
        for (file, text, needle) in [
            ("missing.obj", None, "cannot read mesh file"),
            (
                "bad.obj",
                Some("v 0 0 zero\n".to_owned()),
                "not a valid OBJ",
            ),
            (
                "empty.obj",
                Some("# no faces\nv 0 0 0\n".to_owned()),
                "no triangles",
            ),
            ("many.obj", Some(many), "1025 triangles"),
        ] {
            if let Some(text) = text {
                std::fs::write(dir.path().join(file), text).unwrap();
            }
            let (path, src) = scene_with(dir.path(), file);
            match super::super::parse(&path, &src) {
                Err(crate::error::Error::Scene {
                    line,
                    column,
                    message,
                    ..
                }) => {
                    assert_eq!((line, column), (5, 8), "{file}: {message}");
                    assert!(message.contains(needle), "{file}: {message}");
                }
                other => panic!("{file}: {other:?}"),
            }
        }
    }

    #[test]
    fn a_mesh_excludes_shapes_and_builtins_use_their_own_meshes() {
        let dir = tempfile::tempdir().unwrap();
        let (path, src) = scene_with(dir.path(), "x.obj");
        let src = src.replace(
            "resolution = 8",
            "resolution = 8\nspheres = [[0.0, 0.0, 0.0, 0.5]]",
        );
        let msg = super::super::parse(&path, &src).unwrap_err().to_string();
        assert!(
            msg.contains(":5:8:") && msg.contains("either a mesh"),
            "{msg}"
        );
        let s = super::super::load("mesh").unwrap();
        assert_eq!(s.colliders.sdf[0].triangles.len(), 320);
        assert_eq!(builtin_mesh("mesh (built-in)", "nope.obj"), Some(None));
        assert_eq!(builtin_mesh("scenes/mesh.toml", "meshes/blob.obj"), None);
    }
}
