//! The checks of the fuzz targets, shared with the stable smoke test (`tests/fuzz_smoke.rs`
//! includes this file). Each panics when an input breaks the promise of issue 13: a fuzzer
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
