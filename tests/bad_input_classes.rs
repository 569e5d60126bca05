//! Bad input, one test per class of defect that probing found (docs/reliability.md): inputs
//! that are not regular files, sizes inside their documented range, sort variants, forces on
//! child emitters, user GLSL with a wrong signature, 1-bit height maps, `trace --set`, a state
//! that turned NaN under `bench scene`, a `--video` that names a folder, the fire's point size.

mod common;

use common::cli::{command, file_names, s, stderr};

use std::fs;
use std::path::Path;
use std::process::{Command, Output, Stdio};

fn run_in(dir: &Path, args: &[&str]) -> Output {
    command()
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .output()
        .unwrap()
}

fn grey_png(w: u32, h: u32) -> Vec<u8> {
    let img = image::GrayImage::from_fn(w, h, |i, j| image::Luma([((i + j) * 16) as u8]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// `diff` refuses an input that is not a regular file before reading either (a fifo blocked it
/// for ever; `/dev/zero` never ends), in either place.
#[test]
fn diff_refuses_fifos_devices_and_folders() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fs::write(dir.join("a.png"), grey_png(4, 4)).unwrap();
    let fifo = dir.join("f");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    for (a, b) in [
        ("a.png", "f"),
        ("f", "a.png"),
        ("a.png", "/dev/zero"),
        ("a.png", "."),
    ] {
        // A hang would block this test: the check comes before any read, so it ends at once.
        let o = run_in(dir, &["diff", a, b]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "diff {a} {b}: {err}");
        assert!(err.contains("not a regular file"), "diff {a} {b}: {err}");
    }
    let o = run_in(dir, &["diff", "a.png", "a.png"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// A height field of 4096 nodes a side (the top of its documented range) with
/// `render.geometry = true` runs: the drawn terrain goes through at most 512 nodes a side
/// (it grew to ~12 GB and died by SIGSEGV).
#[test]
fn the_largest_height_field_renders_with_geometry() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run_in(
        tmp.path(),
        &[
            "render",
            "snow",
            "--set",
            "colliders.heightfield.0.resolution=4096",
            "--frames",
            "1",
            "--particles",
            "16",
            "--resolution",
            "64",
            "--out",
            "f",
            "-q",
        ],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(file_names(&tmp.path().join("f")), ["frame_00000.png"]);
}

/// The drawn terrain of a fine height field: at most `MAX_TERRAIN_CELLS` cells a side, its
/// corners the field's corners, every drawn node one of the field's nodes.
#[test]
fn a_fine_terrain_is_drawn_through_a_bounded_grid() {
    use texflow::render::{Mesh, Terrain, MAX_TERRAIN_CELLS};
    let n = 1537usize;
    let height = |i: usize, j: usize| (i * 3 + j * 7) as f32;
    let mut texels = Vec::with_capacity(4 * n * n);
    for j in 0..n {
        for i in 0..n {
            texels.extend_from_slice(&[height(i, j), 0.0, 1.0, 0.0]);
        }
    }
    let t = Terrain {
        extent: [0.0, 0.0, (n - 1) as f32, (n - 1) as f32],
        size: [n as u32, n as u32],
        texels: &texels,
    };
    let mut m = Mesh::default();
    m.terrain(&t).unwrap();
    assert!(
        m.len() <= 6 * MAX_TERRAIN_CELLS * MAX_TERRAIN_CELLS,
        "{}",
        m.len()
    );
    let mut corner = false;
    for v in m.vertices.chunks_exact(10) {
        let (i, j) = (v[0] as usize, v[2] as usize);
        assert_eq!(v[1], height(i, j), "node ({i}, {j})");
        corner |= i == n - 1 && j == n - 1;
    }
    assert!(corner, "the far corner is drawn");
}

/// Every variant `sort` accepts works in `trace sort` (the blocked sort failed at every size,
/// leaving an empty folder), ending sorted, and in `bench sort`; the help of `sort` and `trace`
/// lists each of them.
#[test]
fn every_sort_variant_traces() {
    use texflow::sort::Variant;
    let tmp = tempfile::tempdir().unwrap();
    for v in Variant::ALL {
        let out = tmp.path().join(v.name());
        let o = command()
            .args(["trace", "sort", "--variant", v.name(), "--size", "8", "-q"])
            .args(["--out", s(&out)])
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(0), "{}: {}", v.name(), stderr(&o));
        let names = file_names(&out);
        assert!(names.contains(&"index.md".to_owned()), "{names:?}");
        let last = names
            .iter()
            .filter(|n| n.starts_with("pass_"))
            .max()
            .unwrap();
        let img = image::open(out.join(last)).unwrap().to_rgb8();
        let keys: Vec<f32> = texflow::trace::keys_from_picture(&img, 8)
            .into_iter()
            .map(|k| k.unwrap())
            .collect();
        assert!(
            keys.windows(2).all(|w| w[0] <= w[1]),
            "{}: {keys:?}",
            v.name()
        );
    }
    // `bench sort` runs every variant by default.
    let o = command()
        .args([
            "bench",
            "sort",
            "--sizes",
            "8",
            "--repeats",
            "1",
            "--no-cpu",
            "-q",
        ])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = String::from_utf8(o.stdout).unwrap();
    for v in Variant::ALL {
        assert!(
            table.contains(&format!("| {} |", v.name())),
            "bench sort: {table}"
        );
    }
    for cmd in [["sort", "--help"], ["trace", "--help"]] {
        let help = String::from_utf8(command().args(cmd).output().unwrap().stdout).unwrap();
        for v in Variant::ALL {
            assert!(help.contains(v.name()), "{cmd:?} lists {}", v.name());
        }
    }
}

/// A fireworks scene with `add` put into its first child emitter (or its rocket).
fn fireworks_with(dir: &Path, add: &str, child: bool) -> std::path::PathBuf {
    let src = texflow::scene::builtin_source("fireworks").unwrap();
    let header = if child { "# Type 2" } else { "# Type 1" };
    let at = src.find(header).expect("the fireworks scene's comments");
    let text = format!("{}{add}\n{}", &src[..at], &src[at..]);
    let p = dir.join("fw.toml");
    fs::write(&p, text).unwrap();
    p
}

/// The forces of a child emitter are checked by the rules every other emitter's are (they
/// skipped every check), and a pair force is refused on any emitter, each at its line.
#[test]
fn child_emitters_forces_are_validated() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (
            "[[emitters.child.forces.wind]]\ndrag = 1.0\nbounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]",
            true,
            "wind",
        ),
        (
            "[[emitters.child.forces.custom]]\nglsl = \"missing.glsl\"",
            true,
            "custom force",
        ),
        (
            "[[emitters.child.forces.pair]]\nglsl = \"m.glsl\"\nradius = 0.1",
            true,
            "pair force",
        ),
        (
            "[[emitters.timestamp.forces.pair]]\nglsl = \"m.glsl\"\nradius = 0.1",
            false,
            "pair",
        ),
        (
            "[[emitters.child.forces.gravity]]\nacceleration = [0.0, -1e7, 0.0]",
            true,
            "1e6",
        ),
        ("[[emitters.child.forces.damping]]\nrate = 1e30", true, "dt"),
        ("[[emitters.child.forces.damping]]\nrate = -1e5", true, "dt"),
        (
            "[[emitters.child.forces.spring]]\nanchor = [0.0, 0.0, 0.0]\nstiffness = 1e30",
            true,
            "1e6",
        ),
        (
            "[[emitters.child.forces.attractor]]\nposition = [0.0, 0.0, 0.0]\nstrength = 1e30",
            true,
            "1e6",
        ),
    ];
    for (add, child, says) in cases {
        let scene = fireworks_with(tmp.path(), add, child);
        let text = fs::read_to_string(&scene).unwrap();
        let first = add.lines().next().unwrap();
        let line = text.lines().position(|l| l == first).unwrap() + 1;
        for cmd in ["scene check", "render"] {
            let mut args: Vec<&str> = cmd.split(' ').collect();
            args.push(s(&scene));
            if cmd == "render" {
                args.extend(["--frames", "1", "--out", "never"]);
            }
            let o = run_in(tmp.path(), &args);
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{cmd} with {add}: {err}");
            assert!(err.contains(says), "{cmd} with {add}: {err}");
            // At the table's line, or at a key on the next one.
            let at = (line..=line + 2).any(|l| err.contains(&format!("fw.toml:{l}:")));
            assert!(at, "{cmd} with {add}: at line {line}: {err}");
        }
        assert!(!tmp.path().join("never").exists());
    }
}

/// A pair force or a custom force whose function has the wrong arguments is reported at the
/// user's file, the line and column of its definition, in the user's names (it was reported at
/// line 54 of texflow's internal source, under the renamed `pair_force_0`).
#[test]
fn a_wrong_signature_names_the_users_file_and_function() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fs::write(
        dir.join("p.glsl"),
        "vec3 pair_force(vec3 x, vec3 v) { return v; }\n",
    )
    .unwrap();
    fs::write(
        dir.join("c.glsl"),
        "// a force\n\n  vec3 force(vec3 x) { return x; }\n",
    )
    .unwrap();
    let base = "name = \"sig\"\nintegrator = \"euler\"\n[particles]\nsize = [8, 8]\n\
                [[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
                speed = [0.0, 0.0]\n";
    let pair = "[[forces.pair]]\nglsl = \"p.glsl\"\nradius = 0.05\n[collisions]\nradius = 0.02\n\
                cell = 0.05\ndetection = \"exact\"\n\
                bounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\n";
    let custom = "[[forces.custom]]\nglsl = \"c.glsl\"\n";
    // An error inside the user's file: at its line and the driver's column.
    fs::write(
        dir.join("q.glsl"),
        "vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, vec3 vj, int type_j,\n\
         float mass_j, float distance) {\n  return x +;\n}\n",
    )
    .unwrap();
    let syntax = pair.replace("p.glsl", "q.glsl");
    for (extra, at, name, renamed) in [
        (pair, "p.glsl:1:6", "pair_force(", "pair_force_0"),
        (custom, "c.glsl:3:8", "force(", "custom_force_0"),
        (&syntax, "q.glsl:3:", "pair_force(", "pair_force_0"),
    ] {
        fs::write(dir.join("s.toml"), format!("{base}{extra}")).unwrap();
        let o = run_in(dir, &["scene", "check", "s.toml"]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(at), "at {at}: {err}");
        assert!(err.contains(name), "{err}");
        for internal in [renamed, "pair-forces:", "custom-integrate:", "-force-0-"] {
            assert!(!err.contains(internal), "{internal} in: {err}");
        }
    }
}

/// A 1-, 2- or 4-bit grey PNG is a height map as intended: its levels are spread over [0, 1]
/// as an 8-bit image's are (docs/scenes.md), so black is `base` and white `base + amplitude`.
#[test]
fn low_bit_grey_height_maps_span_zero_to_one() {
    for depth in [png::BitDepth::One, png::BitDepth::Two, png::BitDepth::Four] {
        let mut bytes = Vec::new();
        let mut enc = png::Encoder::new(&mut bytes, 8, 2);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(depth);
        let mut w = enc.write_header().unwrap();
        // Row 0 black, row 1 white (every bit set), whatever the depth.
        let row = (8 * depth as usize).div_ceil(8);
        let data: Vec<u8> = [vec![0u8; row], vec![0xffu8; row]].concat();
        w.write_image_data(&data).unwrap();
        w.finish().unwrap();
        let f = texflow::scene::grey_image(&bytes).unwrap();
        assert_eq!(f.size, [8, 2, 1], "{depth:?}");
        assert!(
            f.data[..8].iter().all(|&v| v == 0.0),
            "{depth:?}: {:?}",
            f.data
        );
        assert!(
            f.data[8..].iter().all(|&v| v == 1.0),
            "{depth:?}: {:?}",
            f.data
        );
    }
}

/// `trace` takes `--set` for a scene (applied and validated like `render`'s) and refuses it for
/// a sort.
#[test]
fn trace_takes_set() {
    let tmp = tempfile::tempdir().unwrap();
    let o = run_in(
        tmp.path(),
        &["trace", "e1", "--set", "render.point_size=-1", "--out", "t"],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("point_size") && err.contains("--set"), "{err}");
    let o = run_in(
        tmp.path(),
        &[
            "trace",
            "sort",
            "--set",
            "render.point_size=2",
            "--out",
            "t",
        ],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--set"), "{}", stderr(&o));
    assert!(!tmp.path().join("t").exists());
}

/// `bench scene` on a state that blew up names the NaN and infinite values (it said "no live
/// particle", as if the scene had emptied).
#[test]
fn bench_scene_names_a_state_that_blew_up() {
    let tmp = tempfile::tempdir().unwrap();
    // Un-damping at |rate × dt| = 4 multiplies the speed by 5 a step: past f32's range in ~55.
    let scene = "name = \"blowup\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n\
                 [time]\ndt = 0.02\n[[emitters.initial]]\nshape = \"point\"\n\
                 direction = [0.0, 1.0, 0.0]\nspeed = [1.0, 1.0]\nmass = 1.0\n\
                 [[forces.damping]]\nrate = -200.0\n[render]\nresolution = [16, 16]\n";
    fs::write(tmp.path().join("b.toml"), scene).unwrap();
    let o = run_in(
        tmp.path(),
        &[
            "bench",
            "scene",
            "./b.toml",
            "--sizes",
            "16",
            "--repeats",
            "1",
            "--warmup",
            "100",
        ],
    );
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("256 particle(s) hold NaN or infinite values"),
        "{err}"
    );
}

/// A `--video` that ends in `/` names a folder: refused before anything is created (the run
/// used to make the --out folder, write the frames and fail at the end with a raw OS error).
#[test]
fn a_video_path_ending_in_a_slash_is_refused_first() {
    let tmp = tempfile::tempdir().unwrap();
    for video in ["v.gif/", "v.png/"] {
        let o = run_in(
            tmp.path(),
            &[
                "render", "e1", "--frames", "2", "--video", video, "--out", "f",
            ],
        );
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(
            err.contains("--video") && !err.contains("os error"),
            "{err}"
        );
        assert!(
            file_names(tmp.path()).is_empty(),
            "{:?}",
            file_names(tmp.path())
        );
    }
}

/// `scene check` and `render` agree on the point size for every built-in scene, the fire's
/// included (its check said ok and `render` refused without a location): both refuse a point
/// wider than the device draws, at the key's line and column, with the same message, and the
/// refused render creates nothing.
#[test]
fn scene_check_and_render_agree_on_the_point_size_for_every_scene() {
    let tmp = tempfile::tempdir().unwrap();
    let set = ["--set", "render.point_size=1e30"];
    for name in texflow::scene::BUILTIN {
        let check = run_in(tmp.path(), &[&["scene", "check", name][..], &set].concat());
        let render = run_in(
            tmp.path(),
            &[&["render", name, "--frames", "1", "--out", "f"][..], &set].concat(),
        );
        let (c, r) = (stderr(&check), stderr(&render));
        assert_eq!(check.status.code(), Some(2), "{name}: {c}");
        assert_eq!(render.status.code(), Some(2), "{name}: {r}");
        let at = format!("{name} (built-in):");
        assert!(c.contains(&at) && c.contains("point_size"), "{name}: {c}");
        assert_eq!(c, r, "{name}");
        assert!(!tmp.path().join("f").exists(), "{name}");
    }
}
