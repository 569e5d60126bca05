//! Fields from files (UberFlow §4.2, §4.6; Latta §3.4.2): height fields from grey PNGs and
//! `.npy` files, winds and distance fields from `.npy` files, against the files' values read
//! independently; the errors a bad file gives, at the key's line and column; and particles on
//! the GPU kept above a terrain read from a file.

mod common;

use common::scene::scene_error;

use std::path::Path;

use texflow::scene::{self, SizeLimits};
use texflow::sim::{DistanceField, FlowField, HeightField, ParticleSim};

fn write(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).unwrap();
}

/// A scene file in `dir` with `body`, parsed.
fn parse_in(dir: &Path, body: &str) -> texflow::Result<scene::SceneFile> {
    let src = format!(
        "name = \"files\"\n[particles]\nsize = [8, 8]\n[[emitters.initial]]\n\
         direction = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n{body}"
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, &src).unwrap();
    scene::load(path.to_str().unwrap())
}

/// A greyscale PNG of `w`×`h` pixels of `bits` (8 or 16) with the value `f(i, j)` at column i,
/// row j.
fn grey_png(w: u32, h: u32, bits: u8, f: impl Fn(u32, u32) -> u16) -> Vec<u8> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Grayscale);
    enc.set_depth(if bits == 8 {
        png::BitDepth::Eight
    } else {
        png::BitDepth::Sixteen
    });
    let mut data = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let v = f(i, j);
            if bits == 8 {
                data.push(v as u8);
            } else {
                data.extend_from_slice(&v.to_be_bytes());
            }
        }
    }
    let mut wr = enc.write_header().unwrap();
    wr.write_image_data(&data).unwrap();
    wr.finish().unwrap();
    out
}

const HF: &str = "[[colliders.heightfield]]\nextent = [-2.0, -1.0, 2.0, 3.0]\nbase = 0.5\n\
                  amplitude = 2.0\n";

/// 8- and 16-bit grey images and a 2D `.npy` (non-square) give the nodes base + amplitude ·
/// value, row j at z_j, column i at x_i.
#[test]
fn height_fields_from_images_and_npy() {
    let dir = tempfile::tempdir().unwrap();
    let f16 = |i: u32, j: u32| ((i * 997 + j * 7919) % 65536) as u16;
    let f8 = |i: u32, j: u32| ((i * 37 + j * 11) % 256) as u16;
    write(dir.path(), "a.png", &grey_png(9, 5, 16, f16));
    write(dir.path(), "b.png", &grey_png(6, 7, 8, f8));
    for (file, w, h, max, f) in [
        ("a.png", 9, 5, 65535.0, &f16 as &dyn Fn(u32, u32) -> u16),
        ("b.png", 6, 7, 255.0, &f8),
    ] {
        let s = parse_in(dir.path(), &format!("{HF}image = \"{file}\"\n")).unwrap();
        let hf = HeightField::new(&s.colliders.heightfield[0]).unwrap();
        assert_eq!(hf.resolution(), [w, h]);
        for j in 0..h {
            for i in 0..w {
                let want = (0.5 + 2.0 * (f(i, j) as f32 / max) as f64) as f32;
                assert!(
                    (hf.texel(i as usize, j as usize).x - want).abs() < 1e-6,
                    "{file} ({i}, {j})"
                );
            }
        }
        assert_eq!(hf.node(w as usize - 1, h as usize - 1), (2.0, 3.0));
    }
    let v: Vec<f32> = (0..4 * 11).map(|k| (k as f32 * 0.37).sin()).collect();
    texflow::npy::write_f32_shaped(&dir.path().join("h.npy"), &[4, 11], &v).unwrap();
    let s = parse_in(dir.path(), &format!("{HF}npy = \"h.npy\"\n")).unwrap();
    let hf = HeightField::new(&s.colliders.heightfield[0]).unwrap();
    assert_eq!(hf.resolution(), [11, 4]);
    assert_eq!(hf.texel(3, 2).x, (0.5 + 2.0 * v[2 * 11 + 3] as f64) as f32);
}

/// A 3D wind file is the texture, plus the mean; a 2D one is one layer at every height; a
/// distance field file is the texture.
#[test]
fn winds_and_distance_fields_from_npy() {
    let dir = tempfile::tempdir().unwrap();
    let (nx, ny, nz) = (5usize, 3usize, 4usize);
    let v: Vec<f32> = (0..nx * ny * nz * 3)
        .map(|k| (k as f32 * 0.11).cos())
        .collect();
    texflow::npy::write_f32_shaped(&dir.path().join("w.npy"), &[nz, ny, nx, 3], &v).unwrap();
    let w2: Vec<f32> = (0..nx * nz * 3).map(|k| k as f32 * 0.01).collect();
    texflow::npy::write_f32_shaped(&dir.path().join("w2.npy"), &[nz, nx, 3], &w2).unwrap();
    let d: Vec<f32> = (0..nx * ny * nz).map(|k| k as f32 * 0.1 - 2.0).collect();
    texflow::npy::write_f32_shaped(&dir.path().join("d.npy"), &[nz, ny, nx], &d).unwrap();
    let wind = |file: &str| {
        format!(
            "[[forces.wind]]\nfield = \"{file}\"\nvelocity = [1.0, 0.0, 0.5]\n\
             bounds = [[-1.0, 0.0, -1.0], [1.0, 2.0, 1.0]]\ndrag = 1.0\n"
        )
    };
    let s = parse_in(dir.path(), &wind("w.npy")).unwrap();
    let f = FlowField::new(&s.forces.wind[0]).unwrap();
    assert_eq!(f.resolution(), [5, 3, 4]);
    let at = |i: usize, j: usize, k: usize| ((k * ny + j) * nx + i) * 3;
    let t = f.texel(4, 2, 1);
    let a = at(4, 2, 1);
    assert_eq!(t.to_array(), [v[a] + 1.0, v[a + 1], v[a + 2] + 0.5]);
    let s = parse_in(dir.path(), &wind("w2.npy")).unwrap();
    let f = FlowField::new(&s.forces.wind[0]).unwrap();
    assert_eq!(f.resolution(), [5, 2, 4]);
    assert_eq!(f.texel(2, 0, 3), f.texel(2, 1, 3));
    assert_eq!(f.texel(2, 1, 3).y, w2[(3 * nx + 2) * 3 + 1]);
    let s = parse_in(
        dir.path(),
        "[[colliders.sdf]]\nfield = \"d.npy\"\nbounds = [[-1.0, 0.0, -1.0], [1.0, 2.0, 1.0]]\n",
    )
    .unwrap();
    let f = DistanceField::new(&s.colliders.sdf[0]).unwrap();
    assert_eq!(f.resolution(), [5, 3, 4]);
    assert_eq!(f.texel(1, 2, 3), d[(3 * ny + 2) * nx + 1]);
}

/// A bad file is a scene error at the key that names it (line 8 of the scene, column 9: its value),
/// saying what is wrong: shape, dtype, a non-finite value, colour instead of grey, a missing
/// file; and a field larger than the device's 3D textures is refused by `check_limits` there.
#[test]
fn bad_field_files_name_the_key_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    texflow::npy::write_f32_shaped(&p.join("shape.npy"), &[4, 4, 4, 2], &[0.0; 128]).unwrap();
    texflow::npy::write_i32(&p.join("int.npy"), &[1, 2, 3]).unwrap();
    let mut nan = vec![0.0f32; 4 * 4 * 4 * 3];
    nan[17] = f32::NAN;
    texflow::npy::write_f32_shaped(&p.join("nan.npy"), &[4, 4, 4, 3], &nan).unwrap();
    texflow::npy::write_f32_shaped(&p.join("big.npy"), &[20, 4, 4, 3], &[0.0; 960]).unwrap();
    let mut rgb = Vec::new();
    {
        let mut enc = png::Encoder::new(&mut rgb, 2, 2);
        enc.set_color(png::ColorType::Rgb);
        let mut w = enc.write_header().unwrap();
        w.write_image_data(&[0; 12]).unwrap();
    }
    write(p, "rgb.png", &rgb);
    let wind = |file: &str| {
        format!(
            "[[forces.wind]]\nfield = \"{file}\"\n\
             bounds = [[-1.0, 0.0, -1.0], [1.0, 2.0, 1.0]]\ndrag = 1.0\n"
        )
    };
    for (file, says) in [
        ("shape.npy", "does not end in 3 components"),
        ("int.npy", "float32"),
        ("nan.npy", "flat index 17 is not finite"),
        ("missing.npy", "cannot read field file"),
    ] {
        let (line, column, m) = scene_error(parse_in(p, &wind(file)));
        assert_eq!((line, column), (8, 9), "{m}");
        assert!(m.contains(says) && m.contains(file), "{m}");
    }
    let (line, column, m) = scene_error(parse_in(p, &format!("{HF}image = \"rgb.png\"\n")));
    assert_eq!((line, column), (11, 9), "{m}");
    assert!(m.contains("not 8- or 16-bit greyscale"), "{m}");
    // The device's 3D texture limit, at the key.
    let s = parse_in(p, &wind("big.npy")).unwrap();
    let src = std::fs::read_to_string(p.join("scene.toml")).unwrap();
    let limits = SizeLimits {
        max_texture: 4096,
        max_3d_texture: 16,
    };
    let e = scene::check_limits("scene.toml", &src, &s, limits, &[]).unwrap_err();
    let m = e.to_string();
    assert!(m.contains(":8:9") && m.contains("20 is over"), "{m}");
}

/// Particles snowing onto the shipped example terrain (a 16-bit grey PNG) on the GPU stay above
/// it: every live particle is at least at the CPU twin's height there, less the skin.
#[test]
fn particles_rest_on_a_terrain_from_an_image() {
    let mut s = scene::load("examples/terrain/terrain.toml").unwrap();
    s.particles.size = [16, 16];
    let hf = HeightField::new(&s.colliders.heightfield[0]).unwrap();
    assert_eq!(hf.resolution(), [64, 64]);
    let ctx = common::context();
    let mut sim = ParticleSim::new(&ctx, &s, 2).unwrap();
    let mut landed = 0;
    for step in 0..240 {
        sim.step().unwrap();
        if step % 40 != 39 {
            continue;
        }
        for p in sim.read_positions().unwrap().chunks(4) {
            if !(p[3] > 0.0 && p[0].is_finite()) || p[0].abs() > 5.0 || p[2].abs() > 5.0 {
                continue;
            }
            let (h, _) = hf.sample(p[0], p[2]);
            assert!(p[1] >= h - 1e-3, "{p:?} below the terrain at {h}");
            if p[1] < h + 0.05 {
                landed += 1;
            }
        }
    }
    assert!(landed > 10, "{landed} particles on the ground");
    common::no_gl_error(&ctx);
}

/// A non-square terrain from an `.npy` (24 nodes along x, 40 along z, a slope along z and ripples
/// along x) on the GPU: the pass samples it with its own size per axis, so particles dropped on
/// it rest on the CPU twin's surface (a swapped axis would put them a slope's height off).
#[test]
fn particles_rest_on_a_non_square_npy_terrain() {
    let dir = tempfile::tempdir().unwrap();
    let (nx, nz) = (24usize, 40usize);
    let v: Vec<f32> = (0..nx * nz)
        .map(|k| {
            let (i, j) = (k % nx, k / nx);
            j as f32 / (nz - 1) as f32 + 0.1 * (i as f32 * 0.9).sin()
        })
        .collect();
    texflow::npy::write_f32_shaped(&dir.path().join("t.npy"), &[nz, nx], &v).unwrap();
    let src = "name = \"slope\"\n[particles]\nsize = [16, 16]\n[time]\ndt = 0.01\n\
               [[emitters.initial]]\nshape = \"box\"\ncenter = [0.0, 3.0, 0.0]\n\
               size = [3.0, 0.1, 5.0]\ndirection = [0.0, -1.0, 0.0]\nspeed = [0.0, 0.5]\n\
               [[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n\
               [[forces.damping]]\nrate = 2.0\n\
               [[colliders.heightfield]]\nnpy = \"t.npy\"\nextent = [-2.0, -3.0, 2.0, 3.0]\n\
               amplitude = 1.5\nfriction = 1.0\nresilience = 0.0\n";
    let path = dir.path().join("slope.toml");
    std::fs::write(&path, src).unwrap();
    let s = scene::load(path.to_str().unwrap()).unwrap();
    let hf = HeightField::new(&s.colliders.heightfield[0]).unwrap();
    assert_eq!(hf.resolution(), [24, 40]);
    let ctx = common::context();
    let mut sim = ParticleSim::new(&ctx, &s, 3).unwrap();
    for _ in 0..300 {
        sim.step().unwrap();
    }
    let mut resting = 0;
    for p in sim.read_positions().unwrap().chunks(4) {
        let (h, _) = hf.sample(p[0], p[2]);
        assert!(p[1] >= h - 1e-3, "{p:?} below the terrain at {h}");
        if p[1] < h + 0.02 {
            resting += 1;
        }
    }
    assert!(resting > 200, "{resting} of 256 resting on the terrain");
    common::no_gl_error(&ctx);
}

/// Writes a wind, a grey height image, a height `.npy` and a sphere's distance field (radius
/// 0.5, 32³ over ±1, negative inside) into `dir`.
fn write_fields(dir: &Path) {
    let n = 32usize;
    let h = 2.0 / (n - 1) as f32;
    let mut d = Vec::with_capacity(n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let p = glam::Vec3::new(i as f32, j as f32, k as f32) * h - glam::Vec3::ONE;
                d.push(p.length() - 0.5);
            }
        }
    }
    texflow::npy::write_f32_shaped(&dir.join("sdf.npy"), &[n, n, n], &d).unwrap();
    let w: Vec<f32> = (0..4 * 4 * 4)
        .flat_map(|k| [0.5 + 0.1 * (k % 4) as f32, 0.0, 0.3])
        .collect();
    texflow::npy::write_f32_shaped(&dir.join("w.npy"), &[4, 4, 4, 3], &w).unwrap();
    write(
        dir,
        "h.png",
        &grey_png(6, 5, 8, |i, j| (i * 20 + j * 9) as u16),
    );
    let v: Vec<f32> = (0..5 * 6).map(|k| (k as f32 * 0.3).sin() * 0.2).collect();
    texflow::npy::write_f32_shaped(&dir.join("h.npy"), &[5, 6], &v).unwrap();
}

/// A scene of 32² particles dropped from a square above the origin onto `colliders`.
fn drop_scene(colliders: &str) -> String {
    format!(
        "name = \"drop\"\nintegrator = \"euler\"\n[particles]\nsize = [32, 32]\n\
         [time]\ndt = 0.01\nsubsteps = 2\n[[emitters.initial]]\nshape = \"box\"\n\
         center = [0.0, 1.5, 0.0]\nsize = [0.6, 0.1, 0.6]\ndirection = [0.0, -1.0, 0.0]\n\
         speed = [0.0, 0.0]\n[[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n\
         [render]\nresolution = [32, 32]\n\
         camera = {{ target = [0.0, 0.0, 0.0], distance = 3.0, elevation = 20.0 }}\n\
         {colliders}"
    )
}

const SDF_FILE: &str = "[[colliders.sdf]]\nfield = \"data/sdf.npy\"\n\
                        bounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\nfriction = 1.0\n\
                        resilience = 0.0\n";

/// Every field from a file (wind, height image or `.npy`, distance field) is the same with an
/// unrelated `--set` as without: the files are read after the settings, relative to the scene
/// file (here in another folder than the working one). Parsed, the fields are equal; rendered,
/// the dumps are the same bytes; `scene check` and `trace` with the setting pass.
#[test]
fn fields_from_files_are_the_same_with_and_without_set() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("data")).unwrap();
    write_fields(&dir.path().join("data"));
    let wind = "[[forces.wind]]\nfield = \"data/w.npy\"\n\
                bounds = [[-2.0, -2.0, -2.0], [2.0, 2.0, 2.0]]\ndrag = 2.0\n";
    let height = |key: &str, file: &str| {
        format!(
            "[[colliders.heightfield]]\n{key} = \"data/{file}\"\n\
             extent = [-2.0, -2.0, 2.0, 2.0]\nbase = -0.5\namplitude = 0.5\nresilience = 0.0\n"
        )
    };
    let set = "render.point_size=3".to_owned();
    for (name, colliders) in [
        ("wind", wind.to_owned()),
        ("image", height("image", "h.png")),
        ("npy", height("npy", "h.npy")),
        ("sdf", SDF_FILE.to_owned()),
    ] {
        let path = dir.path().join(format!("{name}.toml"));
        let src = drop_scene(&colliders);
        std::fs::write(&path, &src).unwrap();
        let label = path.to_str().unwrap();
        let plain = scene::parse(label, &src).unwrap();
        let with = scene::parse_with(label, &src, std::slice::from_ref(&set)).unwrap();
        assert_eq!(with.render.point_size, 3.0, "{name}");
        let f = loaded_fields(&with);
        assert!(
            f.0.iter().chain(&f.1).chain(&f.2).all(Option::is_some),
            "{name}: a field was not read with --set"
        );
        assert_eq!(f, loaded_fields(&plain), "{name}");
        // The commands, run from another folder.
        let a = render_dump(dir.path(), label, &[], &format!("{name}-plain"));
        let b = render_dump(dir.path(), label, &["--set", &set], &format!("{name}-set"));
        assert!(a == b, "{name}: the state differs with --set {set}");
        let trace = dir.path().join(format!("{name}-trace"));
        for args in [
            vec!["scene", "check", label, "--set", &set],
            vec![
                "trace",
                label,
                "--set",
                &set,
                "--out",
                common::cli::s(&trace),
            ],
        ] {
            let o = common::cli::command()
                .args(&args)
                .current_dir("/")
                .output()
                .unwrap();
            let err = common::cli::stderr(&o);
            assert_eq!(o.status.code(), Some(0), "{name} {args:?}: {err}");
        }
    }
}

/// The field data a parsed scene holds: wind, height and distance fields, in order.
type LoadedFields = (
    Vec<Option<scene::FieldData>>,
    Vec<Option<scene::FieldData>>,
    Vec<Option<scene::FieldData>>,
);

fn loaded_fields(s: &scene::SceneFile) -> LoadedFields {
    let c = &s.colliders;
    (
        s.forces.wind.iter().map(|w| w.data.clone()).collect(),
        c.heightfield.iter().map(|h| h.heights.clone()).collect(),
        c.sdf.iter().map(|d| d.distances.clone()).collect(),
    )
}

/// `render SCENE --frames 3` run from another folder with `extra` options, its frames and
/// dumps under `dir/out`; the positions dumped at frame 2.
fn render_dump(dir: &std::path::Path, label: &str, extra: &[&str], out: &str) -> Vec<u8> {
    let (frames, dumps) = (dir.join(out), dir.join(format!("{out}-d")));
    let mut args = vec!["render", label, "--frames", "3", "--quiet", "--out"];
    args.extend([
        common::cli::s(&frames),
        "--dump-state",
        common::cli::s(&dumps),
    ]);
    args.extend(extra);
    let o = common::cli::command()
        .args(&args)
        .current_dir("/")
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(0),
        "{out}: {}",
        common::cli::stderr(&o)
    );
    std::fs::read(dumps.join("positions_00002.npy")).unwrap()
}

/// A sphere's distance field read from a file collides as the same sphere given analytically
/// (sampled at the same nodes): 32² particles dropped on it rest at the same places, within
/// one voxel, and as many are caught. With `render.geometry` its zero surface is drawn.
#[test]
fn a_distance_field_from_a_file_collides_as_the_analytic_shape() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("data")).unwrap();
    write_fields(&dir.path().join("data"));
    let analytic = "[[colliders.sdf]]\nspheres = [[0.0, 0.0, 0.0, 0.5]]\nresolution = 32\n\
                    bounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\nfriction = 1.0\n\
                    resilience = 0.0\n";
    let load = |name: &str, colliders: &str| {
        let path = dir.path().join(name);
        std::fs::write(&path, drop_scene(colliders)).unwrap();
        scene::load(path.to_str().unwrap()).unwrap()
    };
    let (file, exact) = (load("file.toml", SDF_FILE), load("exact.toml", analytic));
    let ctx = common::context();
    let rest = |s: &scene::SceneFile| {
        let mut sim = ParticleSim::new(&ctx, s, 3).unwrap();
        for _ in 0..120 {
            sim.step().unwrap();
        }
        sim.read_positions().unwrap()
    };
    let (a, b) = (rest(&file), rest(&exact));
    let voxel = 2.0 / 31.0;
    let caught = |p: &[f32]| p.chunks(4).filter(|p| p[1] > 0.0).count();
    for (i, (p, q)) in a.chunks(4).zip(b.chunks(4)).enumerate() {
        let d = glam::Vec3::from_slice(p).distance(glam::Vec3::from_slice(q));
        assert!(
            d <= voxel,
            "particle {i}: {p:?} (file) and {q:?} (analytic)"
        );
    }
    assert_eq!(caught(&a), caught(&b));
    assert!(caught(&a) > 300, "{} of 1024 caught", caught(&a));
    // Drawn: the centre of the frame is the sphere, not the background.
    let frame = |geometry: bool| {
        let mut s = file.clone();
        s.render.geometry = geometry;
        texflow::ParticleEngine::new(&ctx, &s, 3)
            .unwrap()
            .render()
            .unwrap()
    };
    let (bare, drawn) = (frame(false), frame(true));
    assert_ne!(bare.get_pixel(16, 16), drawn.get_pixel(16, 16));
    assert_eq!(bare.get_pixel(0, 0), drawn.get_pixel(0, 0));
    common::no_gl_error(&ctx);
}
