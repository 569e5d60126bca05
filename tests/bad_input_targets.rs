//! Every file a command reads against every file it writes, through the built binary: each
//! input kind (the scene, a custom force's and a pair force's GLSL, an OBJ mesh, a height map as
//! PNG and as `.npy`, a wind and a distance field, the `--compare` reference and its other half)
//! is put where each output kind lands (`--video`, a frame of `--out`, a dump of
//! `--dump-state`, a picture and the index of `trace --out`, `view --screenshot`), as the file itself, as a hard link
//! and as a symbolic link. Every run must be refused (exit 2) naming what it reads, leave the
//! input's bytes as they were and create nothing (docs/reliability.md).

mod common;

use common::cli::{command, file_names, s, stderr};

use std::fs;
use std::path::{Path, PathBuf};

/// A tiny particle scene (16×16 state and frame), then `extra`.
fn scene_text(extra: &str) -> String {
    format!(
        "name = \"tiny\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
         dt = 0.02\n[[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
         speed = [0.0, 0.0]\nmass = 1.0\n{extra}[render]\nresolution = [16, 16]\n"
    )
}

const BOUNDS: &str = "bounds = [[-1.0, -1.0, -1.0], [1.0, 1.0, 1.0]]\n";

fn grey_png() -> Vec<u8> {
    let img = image::GrayImage::from_fn(4, 4, |i, j| image::Luma([(i * 40 + j * 20) as u8]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// What a kind of input is: the scene's lines that name file `F` (None: the input is the scene
/// file itself, or not named by the scene) and the file's bytes.
struct Kind {
    name: &'static str,
    scene: Option<&'static str>,
    bytes: Vec<u8>,
}

fn kinds() -> Vec<Kind> {
    let npy = |shape: &[usize], v: f32| {
        let n = shape.iter().product();
        texflow::npy::encode_f32(shape, &vec![v; n])
    };
    let k = |name, scene, bytes| Kind { name, scene, bytes };
    vec![
        k("scene", None, Vec::new()),
        k(
            "custom force",
            Some("[[forces.custom]]\nglsl = \"F\"\n"),
            b"vec3 force(vec3 x, vec3 v, float age, int type) { return vec3(0.0); }\n".to_vec(),
        ),
        k(
            "pair force",
            Some(
                "[[forces.pair]]\nglsl = \"F\"\nradius = 0.05\n[collisions]\nradius = 0.02\n\
                 cell = 0.05\ndetection = \"exact\"\nBOUNDS",
            ),
            b"vec3 pair_force(vec3 x, vec3 v, int type, float mass, vec3 xj, vec3 vj, \
              int type_j, float mass_j, float distance) { return vec3(0.0); }\n"
                .to_vec(),
        ),
        k(
            "mesh",
            Some("[[colliders.sdf]]\nmesh = \"F\"\nresolution = 8\nBOUNDS"),
            b"v 0 0 0\nv 0.5 0 0\nv 0 0.5 0\nv 0 0 0.5\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n"
                .to_vec(),
        ),
        k(
            "height map (PNG)",
            Some("[[colliders.heightfield]]\nimage = \"F\"\nextent = [-1.0, -1.0, 1.0, 1.0]\namplitude = 0.5\n"),
            grey_png(),
        ),
        k(
            "height map (npy)",
            Some("[[colliders.heightfield]]\nnpy = \"F\"\nextent = [-1.0, -1.0, 1.0, 1.0]\namplitude = 0.5\n"),
            npy(&[3, 3], 0.5),
        ),
        k(
            "wind field",
            Some("[[forces.wind]]\nfield = \"F\"\ndrag = 1.0\nBOUNDS"),
            npy(&[2, 2, 2, 3], 0.1),
        ),
        k(
            "distance field",
            Some("[[colliders.sdf]]\nfield = \"F\"\nBOUNDS"),
            npy(&[2, 2, 2], 1.0),
        ),
        k("--compare reference", None, npy(&[256, 4], 0.0)),
        k("--compare's velocities", None, npy(&[256, 4], 0.0)),
    ]
}

/// Where an output lands: the name it writes in the run's folder and the command's arguments
/// (`{dir}`: the folder, `{scene}`: the scene file).
struct Output {
    name: &'static str,
    args: &'static [&'static str],
    /// Whether the command reads a `--compare` reference (render does, trace does not).
    compares: bool,
}

const OUTPUTS: [Output; 6] = [
    Output {
        name: "v.png",
        args: &[
            "render",
            "{scene}",
            "--frames",
            "2",
            "--video",
            "{dir}/v.png",
        ],
        compares: true,
    },
    Output {
        name: "frame_00001.png",
        args: &["render", "{scene}", "--frames", "2", "--out", "{dir}"],
        compares: true,
    },
    Output {
        name: "positions_00001.npy",
        args: &[
            "render",
            "{scene}",
            "--frames",
            "2",
            "--out",
            "{dir}/f",
            "--dump-state",
            "{dir}",
        ],
        compares: true,
    },
    Output {
        name: "01_position.png",
        args: &["trace", "{scene}", "--frame", "1", "--out", "{dir}"],
        compares: false,
    },
    Output {
        name: "index.md",
        args: &["trace", "{scene}", "--out", "{dir}"],
        compares: false,
    },
    Output {
        name: "shot.png",
        args: &[
            "view",
            "{scene}",
            "--frames",
            "1",
            "--screenshot",
            "{dir}/shot.png",
        ],
        compares: false,
    },
];

/// How the input is put at the output's place.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Placed {
    /// The input is the file there.
    Itself,
    /// The input is elsewhere, a hard link to it is there.
    HardLink,
    /// The input is elsewhere, a symbolic link to it is there.
    SymLink,
}

/// Where input kind `k` is written: at the output's place `target`, or in `elsewhere` with a
/// link at that place.
fn input_path(k: &Kind, o: &Output, how: Placed, target: &Path, elsewhere: &Path) -> PathBuf {
    match (how, k.name) {
        (Placed::Itself, _) => target.to_path_buf(),
        // The velocities sit beside the positions, under the name --compare expects.
        (_, "--compare's velocities") => elsewhere.join("velocities_00001.npy"),
        (_, "--compare reference") => elsewhere.join("positions_00001.npy"),
        _ => elsewhere.join(format!("input_{}", o.name)),
    }
}

/// Writes the scene file and the input of kind `k` at `input`; returns the scene's path and the
/// input's bytes.
fn write_scene_and_input(k: &Kind, input: &Path) -> (PathBuf, Vec<u8>) {
    // The scene file: the input itself for the kind "scene", else beside the input (relative
    // names are read from the scene's folder).
    let scene_path = match k.scene {
        None if k.name == "scene" => input.to_path_buf(),
        _ => input.parent().unwrap().join("scene.toml"),
    };
    let file_name = input.file_name().unwrap().to_str().unwrap();
    let extra = k.scene.map_or(String::new(), |t| {
        t.replace("F", file_name).replace("BOUNDS", BOUNDS)
    });
    let text = scene_text(&extra);
    fs::write(&scene_path, &text).unwrap();
    let bytes = if k.name == "scene" {
        text.into_bytes()
    } else {
        fs::write(input, &k.bytes).unwrap();
        k.bytes.clone()
    };
    (scene_path, bytes)
}

/// `--compare` and its positions file for the kinds read by `--compare` (written beside
/// `input` when missing), else nothing.
fn compare_args(k: &Kind, how: Placed, input: &Path) -> Vec<String> {
    let mut compare = Vec::new();
    if k.name.starts_with("--compare") {
        let positions = input.with_file_name("positions_00001.npy");
        if !positions.exists() {
            fs::write(&positions, &k.bytes).unwrap();
        }
        let velocities = positions.with_file_name("velocities_00001.npy");
        if k.name == "--compare's velocities" && !velocities.exists() {
            fs::write(&velocities, &k.bytes).unwrap();
        }
        compare = vec!["--compare".to_owned(), s(&positions).to_owned()];
        // The reference itself is named as the output only when placed there.
        if how == Placed::Itself && k.name == "--compare reference" {
            compare[1] = s(input).to_owned();
        }
    }
    compare
}

/// Sets up input kind `k` so that output `o` would land on it (`how`), runs the command, and
/// checks it is refused with nothing written or created.
fn refused(k: &Kind, o: &Output, how: Placed) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run");
    let elsewhere = tmp.path().join("in");
    fs::create_dir_all(&dir).unwrap();
    fs::create_dir_all(&elsewhere).unwrap();
    let target = dir.join(o.name);
    let input = input_path(k, o, how, &target, &elsewhere);
    let (scene_path, bytes) = write_scene_and_input(k, &input);
    let compare = compare_args(k, how, &input);
    match how {
        Placed::Itself => {}
        Placed::HardLink => fs::hard_link(&input, &target).unwrap(),
        Placed::SymLink => std::os::unix::fs::symlink(&input, &target).unwrap(),
    }
    let before = (file_names(&dir), file_names(&elsewhere));
    let mut args: Vec<String> = o
        .args
        .iter()
        .map(|a| {
            a.replace("{dir}", s(&dir))
                .replace("{scene}", s(&scene_path))
        })
        .collect();
    args.extend(compare);
    let out = command()
        .args(&args)
        .current_dir(tmp.path())
        // `view` must not open a window: it is refused before it looks for a display.
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    let case = format!(
        "{} at {} ({how:?}): texflow {}",
        k.name,
        o.name,
        args.join(" ")
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{case}: {err}");
    assert!(
        err.contains("which the run reads") || err.contains("which it reads"),
        "{case}: the message names what the run reads: {err}"
    );
    assert_eq!(
        fs::read(&input).unwrap(),
        bytes,
        "{case}: the input changed"
    );
    assert_eq!(
        (file_names(&dir), file_names(&elsewhere)),
        before,
        "{case}: a refused run created or removed something"
    );
    assert_eq!(file_names(tmp.path()), ["in", "run"], "{case}");
}

/// Every input kind × every output kind × itself, a hard link and a symbolic link.
#[test]
fn no_output_replaces_an_input() {
    let mut cases = 0;
    for k in kinds() {
        for o in &OUTPUTS {
            if k.name.starts_with("--compare") && !o.compares {
                continue;
            }
            for how in [Placed::Itself, Placed::HardLink, Placed::SymLink] {
                // --compare's velocities are found beside the reference, by name: they can
                // only be reached at an output's place through a link.
                if k.name == "--compare's velocities" && how == Placed::Itself {
                    continue;
                }
                refused(&k, o, how);
                cases += 1;
            }
        }
    }
    assert_eq!(cases, 8 * 6 * 3 + 3 * 3 + 3 * 2);
}

/// The folder a command writes into may itself not be an input's path, and a file an input
/// names through `..` from the scene's folder is the same file.
#[test]
fn inputs_are_compared_by_identity_not_spelling() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    fs::create_dir_all(dir.join("scenes")).unwrap();
    fs::write(dir.join("h.png"), grey_png()).unwrap();
    let extra = "[[colliders.heightfield]]\nimage = \"../h.png\"\n\
                 extent = [-1.0, -1.0, 1.0, 1.0]\namplitude = 0.5\n";
    let scene = dir.join("scenes/s.toml");
    fs::write(&scene, scene_text(extra)).unwrap();
    let video = dir.join("scenes/../././h.png");
    let out = command()
        .args(["render", s(&scene), "--frames", "2", "--video", s(&video)])
        .output()
        .unwrap();
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("height field's image"), "{err}");
    assert_eq!(fs::read(dir.join("h.png")).unwrap(), grey_png());
}
