//! `render --compare`: a run checked against a dump saved earlier. It passes on its own dump,
//! fails (exit 4) on a perturbed one naming the particle, the component and how far, and accepts
//! the perturbation once the tolerance covers it.

mod common;

use common::cli::{stderr, texflow};

use std::path::Path;
use std::process::Output;

fn render(out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "render",
        "fountain",
        "--frames",
        "6",
        "--particles",
        "16x16",
        "--resolution",
        "16x16",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    texflow(&args)
}

#[test]
fn compare_passes_on_its_own_dump_and_fails_on_a_perturbed_one() {
    let dir = tempfile::tempdir().unwrap();
    let frames = dir.path().join("frames");
    let golden = dir.path().join("golden");
    let o = render(
        &frames,
        &[
            "--dump-state",
            golden.to_str().unwrap(),
            "--dump-every",
            "4",
            "-q",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let reference = golden.join("positions_00004.npy");

    // The same run matches bit for bit, positions and the velocities beside them.
    let o = render(&frames, &["--compare", reference.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("frame 4 matches within 0 ULP"), "{e}");
    assert!(e.contains("velocities_00004.npy"), "{e}");

    // One component moved by 3 ULP: refused with exit 4, the particle and component named.
    let (shape, mut pos) = texflow::npy::read_f32_shaped(&reference).unwrap();
    assert!(shape[0] > 5, "{shape:?}");
    let k = 5 * 4 + 1;
    pos[k] = f32::from_bits(pos[k].to_bits() + 3);
    let perturbed = dir.path().join("perturbed");
    std::fs::create_dir(&perturbed).unwrap();
    let bad = perturbed.join("positions_00004.npy");
    texflow::npy::write_f32_shaped(&bad, &shape, &pos).unwrap();
    let o = render(&frames, &["--compare", bad.to_str().unwrap()]);
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("1 of"), "{e}");
    assert!(e.contains("particle 5"), "{e}");
    assert!(e.contains("positions y"), "{e}");
    assert!(e.contains("3 ULP apart"), "{e}");

    // A tolerance of 3 ULP accepts it; 2 does not.
    let o = render(
        &frames,
        &["--compare", bad.to_str().unwrap(), "--tolerance", "3"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = render(
        &frames,
        &["--compare", bad.to_str().unwrap(), "--tolerance", "2"],
    );
    assert_eq!(o.status.code(), Some(4), "{}", stderr(&o));

    // A reference of a frame the run never reaches is bad input, before anything runs.
    let o = texflow(&[
        "render",
        "fountain",
        "--frames",
        "3",
        "--out",
        dir.path().join("none").to_str().unwrap(),
        "--compare",
        reference.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("run at least 5 frames"),
        "{}",
        stderr(&o)
    );
    assert!(!dir.path().join("none").exists());
}
