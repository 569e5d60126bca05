//! The checks of the fuzz targets, shared with the stable smoke test (`tests/fuzz_smoke.rs`
//! includes this file). Each panics when an input breaks the bad-input promise: a fuzzer
//! reports the panic and keeps the input.

use std::path::Path;

use texflow::Error;

/// Feeds `data` to every `.npy` reader. Each must refuse it with a bad-input error (exit code 2
/// in the CLI), or return exactly the number of elements its header declares, with the data
/// exactly as long as they need.
pub fn npy(data: &[u8]) {
    let path = Path::new("fuzz.npy");
    let check = |read: Result<usize, Error>, one_d: bool| match read {
        Ok(n) => {
            let (h, at) = texflow::npy::parse_header(path, data).expect("a file read has a header");
            assert_eq!(n, h.elements(), "{h:?}");
            assert_eq!(data.len() - at, 4 * n, "{h:?}");
            if one_d {
                assert_eq!(h.shape, vec![n]);
            }
        }
        Err(e) => assert!(e.is_bad_input(), "not a bad-input error: {e:?}"),
    };
    check(texflow::npy::decode_f32(path, data).map(|v| v.len()), true);
    check(texflow::npy::decode_u32(path, data).map(|v| v.len()), true);
    check(
        texflow::npy::decode_f32_shaped(path, data).map(|(shape, v)| {
            assert_eq!(shape.iter().product::<usize>(), v.len());
            v.len()
        }),
        false,
    );
}

/// Parses `data` as a scene file, where it is UTF-8 (a file that is not is refused before the
/// parser). It must be refused with a line and a column, or parse into a scene that validates.
pub fn scene(data: &[u8]) {
    let Ok(src) = std::str::from_utf8(data) else {
        return;
    };
    match texflow::scene::parse("fuzz.toml", src) {
        Ok(scene) => {
            if let Err(e) = scene.validate() {
                panic!("parsed, but validate refuses it: {e:?}");
            }
        }
        Err(Error::Scene { line, column, .. }) => {
            assert!(line >= 1 && column >= 1, "no location: {line}:{column}");
        }
        Err(e) => panic!("refused without a line and column: {e}"),
    }
}

/// Reads `data` as an OBJ mesh. It must be refused with a message, or give between 1 and
/// `MAX_TRIANGLES` triangles, every vertex finite.
pub fn obj(data: &[u8]) {
    match texflow::scene::read_obj(data) {
        Ok(t) => {
            assert!(
                !t.is_empty() && t.len() <= texflow::scene::MAX_TRIANGLES,
                "{} triangles",
                t.len()
            );
            assert!(
                t.iter().flatten().flatten().all(|c| c.is_finite()),
                "a vertex that is not finite"
            );
        }
        Err(m) => assert!(!m.is_empty(), "refused without a message"),
    }
}

/// The custom-force front end on `data` as the user's file: the text checks refuse it with the
/// file and a line, or accept it; what they accept is spliced by the include resolver as one
/// source, every one of its lines in order, none taken for an include, and a driver's location
/// in it maps back to the user's file and that line.
pub fn glsl(data: &[u8]) {
    let checked = texflow::scene::check_glsl("user.glsl", data);
    user_source("user.glsl", "force custom_force_0", "force", checked);
}

/// What every user-GLSL front end promises of `checked`, the text checks' verdict on the file
/// `name`: a refusal names the file; an accepted text is spliced whole, in order, between the
/// root's lines, and a driver's location maps back to it. `define` renames the user's function
/// as texflow's root does.
fn user_source(name: &str, define: &str, undef: &str, checked: Result<String, String>) {
    use texflow::gl::source::{embedded, map_log, resolve, LINE_STRIDE};
    let text = match checked {
        Ok(t) => t,
        Err(m) => {
            assert!(m.starts_with(&format!("{name}:")), "no location: {m}");
            return;
        }
    };
    let root = format!(
        "#include \"common/rng.glsl\"\n#define {define}\n#include \"{name}\"\n#undef {undef}\n\
         void main() {{}}\n"
    );
    let user: &str = &text;
    let lookup = |p: &str| match p {
        "root" => Some(root.as_str()),
        p if p == name => Some(user),
        p => embedded(p),
    };
    let r = resolve("root", &[], &lookup).expect("an accepted file resolves");
    assert_eq!(r.files, ["root", "common/rng.glsl", name]);
    // The user's lines, in order, between its `#line` (file 2: line 2 × LINE_STRIDE + 1) and
    // the root's next `#line`.
    let first_line = format!("#line {} 2\n", 2 * LINE_STRIDE + 1);
    let start = r.text.find(&first_line).expect("the user's source") + first_line.len();
    let end = start
        + r.text[start..]
            .find("#line 4 0\n")
            .expect("back to the root");
    let spliced: Vec<&str> = r.text[start..end].lines().collect();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(spliced, lines, "the user's text is spliced as it is");
    let n = lines.len().max(1) as u32;
    let (_, first) = map_log(&format!("2:{n}(1): error: x\n"), &r.files);
    assert_eq!(first, Some((name.to_owned(), n)));
    // As Mesa reports an error inside an included function: source 0, the line carrying the file.
    let (_, first) = map_log(
        &format!("0:{}(1): error: x\n", 2 * LINE_STRIDE + n),
        &r.files,
    );
    assert_eq!(first, Some((name.to_owned(), n)));
}

/// Whether a field read from a file holds what its size says: at least 2 nodes on its first two
/// axes, `channels` finite values per node.
fn field_is_whole(f: &texflow::scene::FieldData, channels: usize) {
    let [x, y, z] = f.size.map(|n| n as usize);
    assert!(x >= 2 && y >= 2 && z >= 1, "size {:?}", f.size);
    assert_eq!(f.channels, channels);
    assert_eq!(f.data.len(), x * y * z * channels, "size {:?}", f.size);
    assert!(
        f.data.iter().all(|v| v.is_finite()),
        "a value that is not finite"
    );
}

/// Feeds `data` to the field-file readers: as a height map image (a grey PNG), and as a height
/// map, wind and distance field `.npy`. Each must refuse it with a message, or give a field
/// whose size matches its values, all finite (the image's in [0, 1]).
pub fn field(data: &[u8]) {
    use texflow::scene::{grey_image, npy_field};
    match grey_image(data) {
        Ok(f) => {
            field_is_whole(&f, 1);
            assert!(
                f.data.iter().all(|v| (0.0..=1.0).contains(v)),
                "a level outside [0, 1]"
            );
        }
        Err(m) => assert!(!m.is_empty(), "refused without a message"),
    }
    for (dims, channels) in [(&[2][..], 1), (&[3, 2][..], 3), (&[3][..], 1)] {
        match npy_field("fuzz.npy", data, dims, channels) {
            Ok(f) => field_is_whole(&f, channels),
            Err(m) => assert!(!m.is_empty(), "refused without a message"),
        }
    }
}

/// The pair-force front end on `data` as the user's file: the text checks refuse it with the
/// file and a line, or accept it; what they accept is spliced by the include resolver as one
/// source, its lines in order, and a driver's location in it maps back to the user's file.
pub fn pair(data: &[u8]) {
    let checked = texflow::scene::check_pair_glsl("pair.glsl", data);
    user_source(
        "pair.glsl",
        "pair_force pair_force_0",
        "pair_force",
        checked,
    );
}

/// `--set KEY=VALUE` values: each line of `data` (UTF-8) is one setting, applied to the built-in
/// `e1` scene's source. They must be refused as bad input, naming the setting (`--set ...`) or
/// the file's line and column, or give a scene that validates.
pub fn set(data: &[u8]) {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let settings: Vec<String> = text.lines().map(str::to_owned).collect();
    let src = texflow::scene::builtin_source("e1").expect("the e1 scene");
    match texflow::scene::parse_with("fuzz.toml", src, &settings) {
        Ok(scene) => {
            if let Err(e) = scene.validate() {
                panic!("set, but validate refuses it: {e:?}");
            }
        }
        Err(Error::Scene { line, column, .. }) => {
            assert!(line >= 1 && column >= 1, "no location: {line}:{column}");
        }
        Err(e) => {
            assert!(e.is_bad_input(), "not a bad-input error: {e:?}");
            assert!(
                e.to_string().contains("--set"),
                "the setting is not named: {e}"
            );
        }
    }
}
