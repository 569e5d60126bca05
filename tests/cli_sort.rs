//! `texflow sort` through the built binary: .npy in, sorted .npy and permutation out, for every
//! variant; bad files refused with exit code 2 and nothing written.

mod common;

use common::cli::{s, texflow};

use std::path::{Path, PathBuf};

use texflow::sort::network::key_order_bits;

#[test]
fn sort_writes_sorted_keys_and_the_permutation() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("keys.npy");
    // 1000 keys (not a power of two) with duplicates, infinities, NaN and signed zeros.
    let mut state = 99u64;
    let keys: Vec<f32> = (0..1000)
        .map(|i| {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            match i % 97 {
                0 => f32::NAN,
                1 => f32::INFINITY,
                2 => f32::NEG_INFINITY,
                3 => -0.0,
                4 => 0.0,
                _ => ((state >> 40) % 500) as f32 - 250.0,
            }
        })
        .collect();
    texflow::npy::write_f32(&input, &keys).unwrap();
    let mut want: Vec<(u32, u32)> = keys
        .iter()
        .enumerate()
        .map(|(i, k)| (key_order_bits(*k), i as u32))
        .collect();
    want.sort();
    for variant in ["fp", "gpfp", "packed", "oddeven", "multistep"] {
        let (out, ids) = (
            dir.path().join(format!("{variant}.npy")),
            dir.path().join(format!("{variant}_ids.npy")),
        );
        let o = texflow(&[
            "sort",
            "--variant",
            variant,
            "--input",
            s(&input),
            "--output",
            s(&out),
            "--ids",
            s(&ids),
            "--quiet",
        ]);
        assert!(
            o.status.success(),
            "{variant}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        let sorted = texflow::npy::read_f32(&out).unwrap();
        let perm = texflow::npy::read_u32(&ids).unwrap();
        assert_eq!(sorted.len(), keys.len());
        let got: Vec<(u32, u32)> = sorted
            .iter()
            .zip(&perm)
            .map(|(k, &i)| (key_order_bits(*k), i))
            .collect();
        assert_eq!(got, want, "{variant}");
        for (k, &i) in sorted.iter().zip(&perm) {
            assert_eq!(
                k.to_bits(),
                keys[i as usize].to_bits(),
                "{variant}: key of id {i}"
            );
        }
    }
}

/// A .npy file of header dictionary `h` (padded to 64 bytes) and `data`.
fn npy_dict(mut h: String, data: &[u8]) -> Vec<u8> {
    while !(10 + h.len() + 1).is_multiple_of(64) {
        h.push(' ');
    }
    h.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend_from_slice(&(h.len() as u16).to_le_bytes());
    b.extend_from_slice(h.as_bytes());
    b.extend_from_slice(data);
    b
}

/// A .npy file of dtype `descr` and `shape` holding `data`.
fn npy(descr: &str, shape: &str, data: &[u8]) -> Vec<u8> {
    let h = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    npy_dict(h, data)
}

/// Writes `bytes` to `name` in `dir`.
fn write(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn bad_sort_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.npy");
    let write = |name: &str, bytes: &[u8]| write(dir.path(), name, bytes);
    let cases = [
        (dir.path().join("missing.npy"), "missing.npy"),
        (write("text.npy", b"1 2 3"), "not a .npy file"),
        (
            write("f64.npy", &npy("<f8", "(1,)", &[0; 8])),
            "dtype <f8 is not float32",
        ),
        (write("empty.npy", &npy("<f4", "(0,)", &[])), "empty"),
        (write("2d.npy", &npy("<f4", "(1, 2)", &[0; 8])), "not 1-D"),
        // A shape whose byte count overflows, and data of another length than the
        // shape's, used to sort 0 or 3 keys and exit 0.
        (
            write("huge.npy", &npy("<f4", "(4611686018427387904,)", &[0; 12])),
            "more bytes than a 64-bit size",
        ),
        (
            write("short.npy", &npy("<f4", "(3,)", &[0; 8])),
            "needs exactly 12",
        ),
        (
            write("long.npy", &npy("<f4", "(1,)", &[0; 12])),
            "needs exactly 4",
        ),
        (write("be.npy", &npy(">f4", "(1,)", &[0; 4])), "big-endian"),
        (
            write(
                "structured.npy",
                &npy_dict(
                    "{'descr': [('a', '<f4')], 'fortran_order': False, 'shape': (1,), }".into(),
                    &[0; 4],
                ),
            ),
            "structured dtype",
        ),
        (
            write("v4.npy", b"\x93NUMPY\x04\x00\x00\x00\x00\x00"),
            "versions 1.0, 2.0 and 3.0 are accepted",
        ),
    ];
    for (input, message) in cases {
        let o = texflow(&["sort", "--input", s(&input), "--output", s(&out), "--quiet"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{message}: {err}");
        assert!(err.contains(message), "expected `{message}` in: {err}");
        assert!(!out.exists());
    }
}

#[test]
fn bad_sort_options_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.npy");
    let good = write(dir.path(), "good.npy", &npy("<f4", "(2,)", &[0; 8]));
    let o = texflow(&[
        "sort",
        "--variant",
        "quick",
        "--input",
        s(&good),
        "--output",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("unknown sort variant `quick`"));
    let o = texflow(&[
        "sort",
        "--input",
        s(&good),
        "--output",
        s(&dir.path().join("no/such/dir.npy")),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("does not exist"));
    assert!(!out.exists());
}

#[test]
fn bench_sort_prints_json_records() {
    let o = texflow(&[
        "bench",
        "sort",
        "--sizes",
        "8,16",
        "--variants",
        "fp,packed",
        "--repeats",
        "2",
        "--json",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let records = v["records"].as_array().unwrap();
    // Per size: two variants and two CPU baselines.
    assert_eq!(records.len(), 8);
    for r in records {
        for f in ["variant", "size", "ms", "passes", "floor_ms", "ratio"] {
            assert!(r.get(f).is_some(), "missing {f}");
        }
        if r["variant"] == "fp" && r["size"] == 16 {
            // 256 entries: 8·9/2 = 36 network passes, plus the key pass and the rearrangement.
            assert_eq!(r["passes"].as_u64(), Some(38));
        }
    }
}
