//! The reader and writer's unit tests: round trips, what numpy writes, and one test per class
//! of malformed file (each message names what was found and what is accepted).

use super::*;
use std::fs;

#[test]
fn round_trips_and_aligns() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("a.npy");
    let v = vec![1.5f32, -0.0, f32::INFINITY, 3.0];
    write_f32(&p, &v).unwrap();
    let bytes = fs::read(&p).unwrap();
    assert_eq!(
        (bytes.len() - 16) % 64,
        0,
        "data starts on a 64-byte boundary"
    );
    let back = read_f32(&p).unwrap();
    assert_eq!(
        back.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        v.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
    let q = dir.path().join("i.npy");
    write_i32(&q, &[0, 5, 7]).unwrap();
    assert_eq!(read_u32(&q).unwrap(), vec![0, 5, 7]);
    let r = dir.path().join("r.npy");
    write_f32_shaped(&r, &[2, 4], &[0.0; 8]).unwrap();
    let (h, off) = parse_header(&r, &fs::read(&r).unwrap()).unwrap();
    assert_eq!(
        (h.shape, h.descr.as_str(), off % 64),
        (vec![2, 4], "<f4", 0)
    );
}

#[test]
fn reads_what_numpy_writes() {
    // numpy.save(np.array([1, 2], dtype=np.float32)) with numpy 1.x: version 1.0 header.
    let mut b =
        b"\x93NUMPY\x01\x00v\x00{'descr': '<f4', 'fortran_order': False, 'shape': (2,), }".to_vec();
    b.resize(10 + 0x76 - 1, b' ');
    b.push(b'\n');
    b.extend_from_slice(&1f32.to_le_bytes());
    b.extend_from_slice(&2f32.to_le_bytes());
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("n.npy");
    fs::write(&p, &b).unwrap();
    assert_eq!(read_f32(&p).unwrap(), vec![1.0, 2.0]);
}

#[test]
fn bad_files_get_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let check = |name: &str, bytes: &[u8], needle: &str| {
        let p = dir.path().join(name);
        fs::write(&p, bytes).unwrap();
        let msg = read_f32(&p).unwrap_err().to_string();
        assert!(msg.contains(needle), "{name}: {msg}");
    };
    check("text.npy", b"1,2,3\n", "not a .npy file");
    let f64s = encode("<f8", &[1], &1f64.to_le_bytes());
    check("f64.npy", &f64s, "dtype <f8 is not float32");
    check("empty.npy", &encode("<f4", &[0], &[]), "empty");
    let mut two_d = encode("<f4", &[2], &[0; 8]);
    let at = two_d.windows(4).position(|w| w == b"(2,)").unwrap();
    two_d.splice(at..at + 4, b"(1,2)".iter().copied());
    check("2d.npy", &two_d, "not 1-D");
    let missing = read_f32(&dir.path().join("nope.npy")).unwrap_err();
    assert!(matches!(missing, Error::Io { .. }));
}

/// A file of format `version` (1, 2 or 3, or anything for the version tests) with the header
/// text `dict` and the data `data`.
pub(super) fn file(version: u8, dict: &str, data: &[u8]) -> Vec<u8> {
    let mut out = MAGIC.to_vec();
    out.extend_from_slice(&[version, 0]);
    let mut h = dict.to_owned();
    h.push('\n');
    if version == 1 {
        out.extend_from_slice(&(h.len() as u16).to_le_bytes());
    } else {
        out.extend_from_slice(&(h.len() as u32).to_le_bytes());
    }
    out.extend_from_slice(h.as_bytes());
    out.extend_from_slice(data);
    out
}

/// The usual header text.
pub(super) fn dict(descr: &str, fortran: &str, shape: &str) -> String {
    format!("{{'descr': {descr}, 'fortran_order': {fortran}, 'shape': {shape}, }}")
}

pub(super) fn p() -> &'static Path {
    Path::new("k.npy")
}

/// Asserts that all three readers refuse `bytes` with a message holding each of `needles`.
#[track_caller]
fn refused_by_all(bytes: &[u8], needles: &[&str]) {
    let msgs = [
        decode_f32(p(), bytes).map(|_| ()),
        decode_u32(p(), bytes).map(|_| ()),
        decode_f32_shaped(p(), bytes).map(|_| ()),
    ];
    for (reader, r) in ["f32", "u32", "f32_shaped"].iter().zip(msgs) {
        let e = r.expect_err(reader);
        assert!(matches!(e, Error::InvalidInput(_)), "{reader}: {e:?}");
        assert!(e.is_bad_input());
        let msg = e.to_string();
        assert!(msg.starts_with("k.npy: "), "{reader}: {msg}");
        for n in needles {
            assert!(msg.contains(n), "{reader}: `{n}` not in: {msg}");
        }
    }
}

/// Asserts that each reader refuses the file `make` builds with a dtype it accepts, with a
/// message holding each of `needles`.
#[track_caller]
fn refused_with_its_dtype(make: impl Fn(&str) -> Vec<u8>, needles: &[&str]) {
    let msgs = [
        ("f32", decode_f32(p(), &make("'<f4'")).map(|_| ())),
        ("u32", decode_u32(p(), &make("'<u4'")).map(|_| ())),
        ("i32", decode_u32(p(), &make("'<i4'")).map(|_| ())),
        (
            "f32_shaped",
            decode_f32_shaped(p(), &make("'<f4'")).map(|_| ()),
        ),
    ];
    for (reader, r) in msgs {
        let msg = r.expect_err(reader).to_string();
        for n in needles {
            assert!(msg.contains(n), "{reader}: `{n}` not in: {msg}");
        }
    }
}

#[test]
fn shapes_that_overflow_or_disagree_with_the_data_are_refused() {
    let refused = |shape: &str, data: &[u8], needles: &[&str]| {
        refused_with_its_dtype(|d| file(1, &dict(d, "False", shape), data), needles);
    };
    // 2^62 elements of 4 bytes: 2^64 bytes, which used to wrap to 0 and "read" 0 keys.
    let huge = "(4611686018427387904,)";
    refused(
        huge,
        &[0; 12],
        &[huge, "more bytes than a 64-bit size", "corrupt"],
    );
    // 2^61 elements fit in the byte count but not in the file.
    refused(
        "(2305843009213693952,)",
        &[0; 12],
        &["holds 12 bytes", "needs exactly 9223372036854775808"],
    );
    // A shape whose element count overflows.
    let product = "(4294967296, 4294967296, 2)";
    refused(
        product,
        &[],
        &["more elements than a 64-bit count", "corrupt"],
    );
    let wide = "(18446744073709551616,)";
    refused(
        wide,
        &[],
        &["18446744073709551616", "does not fit in 64 bits"],
    );
    // Shorter and longer data than the shape declares.
    refused(
        "(3,)",
        &[0; 8],
        &["holds 8 bytes of data", "(3,) of <", "needs exactly 12"],
    );
    refused(
        "(1,)",
        &[0; 8],
        &["holds 8 bytes of data", "needs exactly 4"],
    );
    let long2d = file(1, &dict("'<f4'", "False", "(1, 2)"), &[0; 12]);
    let msg = decode_f32_shaped(p(), &long2d).unwrap_err().to_string();
    assert!(msg.contains("[1, 2] of <f4 needs exactly 8"), "{msg}");
    // And the declared length is what is read.
    let three = file(1, &dict("'<f4'", "False", "(3,)"), &[0; 12]);
    assert_eq!(decode_f32(p(), &three).unwrap().len(), 3);
}

#[test]
fn dtypes_other_than_the_accepted_name_what_they_are() {
    let one = |descr: &str| file(1, &dict(descr, "False", "(1,)"), &[0; 4]);
    let structured = one("[('a', '<f4')]");
    for (r, accepted) in [
        (decode_f32(p(), &structured).map(|_| ()), "float32 (<f4)"),
        (decode_u32(p(), &structured).map(|_| ()), "int32 or uint32"),
        (decode_f32_shaped(p(), &structured).map(|_| ()), "float32"),
    ] {
        let msg = r.unwrap_err().to_string();
        assert!(msg.contains("dtype [('a', '<f4')] is not"), "{msg}");
        assert!(msg.contains(accepted), "{msg}");
        assert!(msg.contains("structured dtype"), "{msg}");
        assert!(!msg.contains("no descr"), "{msg}");
    }
    let nested = one("[('a', '<f4', (2,)), ('b', [('c', '<i4')])]");
    refused_by_all(&nested, &["structured dtype", "('c', '<i4')"]);
    refused_by_all(
        &one("'>f4'"),
        &["dtype >f4 is not", "big-endian", "astype('<"],
    );
    let msg = decode_f32(p(), &one("'>i4'")).unwrap_err().to_string();
    assert!(msg.contains("big-endian"), "{msg}");
    for other in ["'<f8'", "'|u1'", "'<f2'", "'<U1'", "'<i8'"] {
        let name = other.trim_matches('\'');
        refused_by_all(&one(other), &[&format!("dtype {name} is not")]);
    }
    let msg = decode_f32(p(), &one("'<i4'")).unwrap_err().to_string();
    assert!(msg.contains("dtype <i4 is not float32 (<f4)"), "{msg}");
    let msg = decode_u32(p(), &one("'<f4'")).unwrap_err().to_string();
    assert!(
        msg.contains("dtype <f4 is not int32 or uint32 (<i4, <u4)"),
        "{msg}"
    );
    refused_by_all(&one("4"), &["'descr' is 4", "a dtype string such as '<f4'"]);
    refused_by_all(&one("None"), &["'descr' is None"]);
}

#[test]
fn fortran_order_is_refused_where_it_changes_the_layout() {
    let f2d = file(1, &dict("'<f4'", "True", "(2, 2)"), &[0; 16]);
    let msg = decode_f32_shaped(p(), &f2d).unwrap_err().to_string();
    assert!(msg.contains("Fortran order, C order is accepted"), "{msg}");
    assert!(msg.contains("ascontiguousarray"), "{msg}");
    // A 1-D array has the same bytes in either order.
    let f1d = file(1, &dict("'<f4'", "True", "(2,)"), &[0; 8]);
    assert_eq!(decode_f32(p(), &f1d).unwrap(), vec![0.0, 0.0]);
    let msg = decode_u32(p(), &f1d).unwrap_err().to_string();
    assert!(msg.contains("dtype <f4 is not int32"), "{msg}");
    refused_by_all(
        &file(1, &dict("'<f4'", "1", "(2,)"), &[0; 8]),
        &["'fortran_order' is 1", "True or False is accepted"],
    );
    refused_by_all(
        &file(1, &dict("'<f4'", "'False'", "(2,)"), &[0; 8]),
        &["'fortran_order' is 'False'"],
    );
}

#[test]
fn missing_unexpected_and_repeated_keys_are_named() {
    let all = [
        ("descr", "'<f4'"),
        ("fortran_order", "False"),
        ("shape", "(1,)"),
    ];
    for skip in 0..3 {
        let text: Vec<String> = all
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != skip)
            .map(|(_, (k, v))| format!("'{k}': {v}"))
            .collect();
        let bytes = file(1, &format!("{{{}}}", text.join(", ")), &[0; 4]);
        let key = all[skip].0;
        refused_by_all(
            &bytes,
            &[
                &format!("has no '{key}' key"),
                "exactly 'descr', 'fortran_order' and 'shape'",
            ],
        );
    }
    let extra = "{'descr': '<f4', 'fortran_order': False, 'shape': (1,), 'extra': 1}";
    refused_by_all(&file(1, extra, &[0; 4]), &["unexpected key 'extra'"]);
    let twice = "{'descr': '<f4', 'fortran_order': False, 'shape': (1,), 'shape': (1,)}";
    refused_by_all(&file(1, twice, &[0; 4]), &["'shape' is given twice"]);
    refused_by_all(&file(1, "{1: 2}", &[]), &["unexpected key 1"]);
    refused_by_all(&file(1, "('descr', '<f4')", &[]), &["is not a Python dict"]);
}

#[test]
fn malformed_header_text_is_located() {
    let bad = |text: &str, needles: &[&str]| refused_by_all(&file(1, text, &[0; 4]), needles);
    bad(
        "{'descr': '<f4', 'fortran_order': False 'shape': (1,)}",
        &[
            "bad .npy header",
            "expected `,` or `}` at byte 40",
            "`'shape'",
        ],
    );
    bad("{'descr': '<f4}", &["no closing '"]);
    bad(
        "{'descr': '<f4', 'shape': (1,",
        &["expected a Python literal", "the end of the header"],
    );
    bad("{'descr' '<f4'}", &["expected `:` after a key"]);
    bad(
        &(dict("'<f4'", "False", "(1,)") + " junk"),
        &["text after the dict: junk"],
    );
    bad(
        &dict("'<f4'", "false", "(1,)"),
        &["`false` in the header is not a Python literal"],
    );
    bad(
        &dict("'<f4'", "False", "[1]"),
        &["'shape' is [1]", "a tuple of sizes"],
    );
    bad(
        &dict("'<f4'", "False", "1"),
        &["'shape' is 1", "a tuple of sizes"],
    );
    bad(&dict("'<f4'", "False", "(-1,)"), &["negative size -1"]);
    bad(&dict("'<f4'", "False", "(2.5,)"), &["expected `,` or `)`"]);
    bad(
        &dict("'<f4'", "False", "('1',)"),
        &["the entry '1' is not a size"],
    );
    bad(&dict("'<f4'", "False", "(-,)"), &["expected a number"]);
    let deep = format!("{}{}", "[".repeat(100), "]".repeat(100));
    bad(
        &dict(&deep, "False", "(1,)"),
        &["nests deeper than 32 levels"],
    );
    // Python 2's long integers, as old numpy versions wrote them, and spacing are fine.
    let py2 = file(
        1,
        "{'descr':'<f4','fortran_order':False,'shape':(1L,)}",
        &[0; 4],
    );
    assert_eq!(decode_f32(p(), &py2).unwrap(), vec![0.0]);
    let dq = file(
        1,
        "{\"descr\": \"<f4\", \"fortran_order\": False, \"shape\": ( 1 , )}",
        &[0; 4],
    );
    assert_eq!(decode_f32(p(), &dq).unwrap(), vec![0.0]);
}

#[test]
fn truncated_files_and_bad_magic_say_where_they_end() {
    let good = file(1, &dict("'<f4'", "False", "(1,)"), &[0; 4]);
    refused_by_all(&[], &["truncated", "0 bytes", "\\x93NUMPY"]);
    refused_by_all(&good[..4], &["truncated", "4 bytes"]);
    refused_by_all(&good[..7], &["truncated", "before its format version"]);
    refused_by_all(
        &good[..9],
        &["truncated", "inside the 2-byte header length"],
    );
    refused_by_all(
        &good[..30],
        &["header is truncated", "says 58 bytes", "the file has 20"],
    );
    refused_by_all(
        b"PK\x03\x04zip",
        &["not a .npy file: it starts with `PK\\x03\\x04zi`"],
    );
    refused_by_all(b"\x93NUMPX\x01\x00", &["not a .npy file"]);
}

#[test]
fn versions_two_and_three_are_read_and_others_named() {
    let d = dict("'<f4'", "False", "(2,)");
    let data: Vec<u8> = [1.5f32, -2.0]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    for v in [1, 2, 3] {
        assert_eq!(
            decode_f32(p(), &file(v, &d, &data)).unwrap(),
            vec![1.5, -2.0]
        );
    }
    // Version 3 is UTF-8, versions 1 and 2 latin-1 (where a stray byte is a parse error).
    let utf8 = file(
        3,
        "{'descr': '<f4', 'fortran_order': False, 'shape': (2,), 'é': 1}",
        &data,
    );
    refused_by_all(&utf8, &["unexpected key 'é'"]);
    let mut latin1 = file(2, &d, &data);
    let at = latin1.windows(5).position(|w| w == b"shape").unwrap();
    latin1[at - 1] = 0xE9;
    refused_by_all(&latin1, &["bad .npy header"]);
    let mut not_utf8 = file(3, &d, &data);
    not_utf8[at - 1] = 0xE9;
    refused_by_all(&not_utf8, &["not UTF-8, as version 3.0 requires"]);
    let v2 = file(2, &d, &data);
    refused_by_all(
        &v2[..10],
        &["inside the 4-byte header length of version 2.0"],
    );
    for (major, minor) in [(0, 0), (4, 0), (1, 1), (2, 9), (255, 255)] {
        let mut b = file(1, &d, &data);
        b[6] = major;
        b[7] = minor;
        refused_by_all(
            &b,
            &[
                &format!("unsupported .npy format version {major}.{minor}"),
                "versions 1.0, 2.0 and 3.0 are accepted",
            ],
        );
    }
}
