//! Bad input in custom GLSL and options, through the built binary: `scene check` refuses what
//! `render` refuses, the user's file is found by its own path and named with its line, and the
//! messages name the option typed (docs/reliability.md).

mod common;

use common::bad_input::{custom, run, run_in, scene_file, scene_text, LIFT};
use common::cli::{s, stderr};

use std::fs;
use std::process::Command;

// ---------------------------------------------------------------------------------------------
// Custom GLSL: one validation, the user's file and line, found by its own path
// ---------------------------------------------------------------------------------------------

/// Every custom force that `render` refuses, `scene check` refuses first (exit 2), naming the
/// user's file; none is blamed on texflow's own files.
#[test]
fn scene_check_refuses_the_custom_glsl_render_refuses() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::create_dir(d.join("folder.glsl")).unwrap();
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("syntax.glsl", b"vec3 force(vec3 x, vec3 v, float age, int type) {\n  return x +;\n}\n".to_vec(), "syntax.glsl:2"),
        ("version.glsl", [b"#version 450\n".as_slice(), LIFT.as_bytes()].concat(), "version.glsl:1"),
        ("error.glsl", [LIFT.as_bytes(), b"#error stop here\n".as_slice()].concat(), "error.glsl:4"),
        ("include.glsl", [b"#include \"x.glsl\"\n".as_slice(), LIFT.as_bytes()].concat(), "include.glsl:1"),
        ("line.glsl", [b"#line 9999\n".as_slice(), LIFT.as_bytes(), b"oops\n"].concat(), "line.glsl:1"),
        ("compute.glsl", [b"#extension GL_ARB_shader_storage_buffer_object : require\n".as_slice(), LIFT.as_bytes()].concat(), "compute.glsl:1"),
        ("utf8.glsl", [LIFT.as_bytes(), b"// \xff\n".as_slice()].concat(), "utf8.glsl:4:4"),
        ("nul.glsl", [LIFT.as_bytes(), b"\0\n".as_slice()].concat(), "nul.glsl:4:1"),
        ("endless.glsl", b"vec3 force(vec3 x, vec3 v, float age, int type) {\n  while (true) {}\n  return x;\n}\n".to_vec(), "endless.glsl:2"),
        ("missing.glsl", Vec::new(), "missing.glsl"),
        ("folder.glsl", Vec::new(), "folder.glsl"),
    ];
    for (name, text, want) in &cases {
        if !text.is_empty() {
            fs::write(d.join(name), text).unwrap();
        }
        let sc = d.join(format!("{name}.toml"));
        fs::write(&sc, scene_text(&custom(name))).unwrap();
        let check = run(&["scene", "check", s(&sc)]);
        let render = run(&["render", s(&sc), "--frames", "1", "--out", s(&d.join("o"))]);
        for (what, o) in [("check", &check), ("render", &render)] {
            assert_eq!(o.status.code(), Some(2), "{what} {name}: {}", stderr(o));
            assert!(
                stderr(o).contains(want),
                "{what} {name}: want {want}: {}",
                stderr(o)
            );
            assert!(
                !stderr(o).contains("glsl/sim"),
                "{what} {name}: {}",
                stderr(o)
            );
        }
    }
    assert!(!d.join("o").exists());
}

/// A user file whose path is a built-in include's (`common/rng.glsl`), and one file named by two
/// `[[forces.custom]]`: both valid, and the file named twice acts twice (twice the velocity of
/// the file named once, from rest under no other force).
#[test]
fn user_glsl_is_found_by_its_own_path_and_may_be_used_twice() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::create_dir(d.join("common")).unwrap();
    fs::write(d.join("common/rng.glsl"), LIFT).unwrap();
    let once = d.join("once.toml");
    fs::write(&once, scene_text(&custom("common/rng.glsl"))).unwrap();
    let twice = d.join("twice.toml");
    fs::write(
        &twice,
        scene_text(&(custom("common/rng.glsl") + &custom("common/rng.glsl"))),
    )
    .unwrap();
    let mut v = Vec::new();
    for sc in ["once.toml", "twice.toml"] {
        // Run from the scene's folder, so that the path is exactly `common/rng.glsl`.
        let o = run_in(Some(d), None, &["scene", "check", sc]);
        assert_eq!(o.status.code(), Some(0), "{sc}: {}", stderr(&o));
        let dumps = format!("dumps_{sc}");
        let o = run_in(
            Some(d),
            None,
            &[
                "render",
                sc,
                "--frames",
                "2",
                "--dump-state",
                &dumps,
                "--video",
                "a.gif",
            ],
        );
        assert_eq!(o.status.code(), Some(0), "{sc}: {}", stderr(&o));
        let vel = texflow::npy::read_f32_shaped(&d.join(&dumps).join("velocities_00001.npy"));
        v.push(vel.unwrap().1);
    }
    assert!(!v[0].is_empty());
    for (a, b) in v[0].chunks(4).zip(v[1].chunks(4)) {
        assert!(a[1] > 0.0, "the force acts: {a:?}");
        assert!(
            (b[1] - 2.0 * a[1]).abs() <= 1e-5 * a[1],
            "twice {b:?}, once {a:?}"
        );
    }
}

/// The user's GLSL errors are bad input (exit 2) at the user's file and line, and a byte-order
/// mark is no error.
#[test]
fn user_glsl_errors_name_the_users_file_and_a_bom_is_accepted() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    fs::write(
        d.join("bom.glsl"),
        [b"\xEF\xBB\xBF".as_slice(), LIFT.as_bytes()].concat(),
    )
    .unwrap();
    let sc = d.join("bom.toml");
    fs::write(&sc, scene_text(&custom("bom.glsl"))).unwrap();
    let o = run(&["scene", "check", s(&sc)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    fs::write(
        d.join("undefined.glsl"),
        "\n\nvec3 force(vec3 x, vec3 v, float age, int type) {\n  return nothing_here;\n}\n",
    )
    .unwrap();
    let sc = d.join("undefined.toml");
    fs::write(&sc, scene_text(&custom("undefined.glsl"))).unwrap();
    let o = run(&["render", s(&sc), "--frames", "1", "--out", s(&d.join("o"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("undefined.glsl:4"), "{}", stderr(&o));
    assert!(
        !stderr(&o).contains("custom-force-"),
        "no internal names: {}",
        stderr(&o)
    );
    // An include of a file that is not texflow's, and a `#line` that would move the error into
    // texflow's files: bad input at the user's file and line, not "the machine failed".
    for (name, text, want) in [
        (
            "inc.glsl",
            format!("#include \"x.glsl\"\n{LIFT}"),
            "inc.glsl:1",
        ),
        (
            "line.glsl",
            format!("{LIFT}#line 9999\nnot glsl\n"),
            "line.glsl:4",
        ),
    ] {
        fs::write(d.join(name), text).unwrap();
        let sc = d.join(format!("{name}.toml"));
        fs::write(&sc, scene_text(&custom(name))).unwrap();
        let o = run(&["render", s(&sc), "--frames", "1", "--out", s(&d.join("o"))]);
        assert_eq!(o.status.code(), Some(2), "{name}: {}", stderr(&o));
        assert!(stderr(&o).contains(want), "{name}: {}", stderr(&o));
        assert!(!stderr(&o).contains("glsl/"), "{name}: {}", stderr(&o));
    }
}

// ---------------------------------------------------------------------------------------------
// Messages name the option typed; point sizes in scene check
// ---------------------------------------------------------------------------------------------

#[test]
fn messages_name_the_option_typed() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let sc = scene_file(d, "");
    let file = d.join("file");
    fs::write(&file, b"").unwrap();
    let sub = file.join("sub");
    for (args, flag) in [
        (
            vec!["render", s(&sc), "--particles", "99999"],
            "--particles",
        ),
        (
            vec!["render", s(&sc), "--resolution", "99999"],
            "--resolution",
        ),
        (vec!["collide-stats", "--iterations", "17"], "--iterations"),
        (vec!["collide-stats", "--k", "99"], "--k"),
        (vec!["render", s(&sc), "--out", s(&sub)], "--out"),
    ] {
        let o = run(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(flag), "{args:?}: {}", stderr(&o));
        assert!(!stderr(&o).contains("particles.size"), "{}", stderr(&o));
        assert!(!stderr(&o).contains("render.resolution"), "{}", stderr(&o));
        assert!(!stderr(&o).contains("collisions."), "{}", stderr(&o));
    }
    // Without a display, `view` refuses a size over the limit for the size.
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args(["view", s(&sc), "--resolution", "99999"])
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--resolution"), "{}", stderr(&o));
    assert!(!stderr(&o).contains("display"), "{}", stderr(&o));
}

/// Sprites wider than the device's largest point: `scene check` refuses them at the key.
#[test]
fn scene_check_refuses_points_wider_than_the_device_draws() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let wide = |render: &str, emitter: &str| {
        format!(
            "name = \"wide\"\nintegrator = \"euler\"\n[particles]\nsize = [16, 16]\n[time]\n\
             dt = 0.02\n[[emitters.initial]]\nshape = \"point\"\ndirection = [0.0, 1.0, 0.0]\n\
             speed = [0.0, 0.0]\n{emitter}\n[render]\nresolution = [16, 16]\nmode = \"sprites\"\n\
             {render}\n"
        )
    };
    for (text, at) in [
        (wide("point_size = 100000.0", ""), ":15:14:"),
        (
            wide("point_size = 200.0", "sprite_scale = 1000.0"),
            ":11:16:",
        ),
    ] {
        let sc = d.join("wide.toml");
        fs::write(&sc, &text).unwrap();
        let o = run(&["scene", "check", s(&sc)]);
        assert_eq!(o.status.code(), Some(2), "{text}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("wide.toml{at}")) && stderr(&o).contains("largest point"),
            "{text}: {}",
            stderr(&o)
        );
        let o = run(&["render", s(&sc), "--frames", "1", "--out", s(&d.join("o"))]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("wide.toml{at}")),
            "{}",
            stderr(&o)
        );
    }
}
