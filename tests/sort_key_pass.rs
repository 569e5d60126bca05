//! The sort's key pass and rearrangement on a real GL context, against the CPU: keys are the
//! distances to the eye, the rearrangement keeps each particle's state together, identifiers
//! under 24-bit floats, and compact entries render like exact ones.

mod common;

use common::image::texture;
use common::{context, no_gl_error};
use glam::{UVec3, Vec3};
use texflow::gl::{PingPong, TextureFormat};
use texflow::sort::precision::R300;
use texflow::sort::{KeyMode, SortOptions, Sorter, Variant};

fn lcg(s: &mut u64) -> u32 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*s >> 33) as u32
}

fn random_positions(n: usize, seed: u64) -> Vec<f32> {
    let mut s = seed;
    (0..n)
        .flat_map(|i| {
            let mut c = || (lcg(&mut s) % 20000) as f32 / 1000.0 - 10.0;
            [c(), c(), c(), 1.0 + i as f32]
        })
        .collect()
}

/// The key pass against the CPU: viewer distance (both directions) and grid cells.
#[test]
fn key_pass_matches_the_cpu() {
    let ctx = context();
    let (sw, sh) = (20u32, 10u32); // a state that is not a power of two
    let n = (sw * sh) as usize;
    let pos = random_positions(n, 3);
    let positions = texture(&ctx, "test", (sw, sh), TextureFormat::Rgba32F, &pos);
    let eye = Vec3::new(1.0, 2.0, 30.0);
    for variant in [Variant::Fp, Variant::Packed] {
        let mut sorter = Sorter::new(&ctx, variant, 16, 16, SortOptions::default()).unwrap();
        for back in [false, true] {
            sorter
                .write_keys(
                    &positions,
                    n,
                    &KeyMode::ViewerDistance {
                        eye,
                        back_to_front: back,
                    },
                    false,
                )
                .unwrap();
            let e = sorter.read().unwrap();
            for i in 0..256 {
                if i < n {
                    let p = Vec3::from_slice(&pos[4 * i..4 * i + 3]);
                    let want = p.distance(eye) * if back { -1.0 } else { 1.0 };
                    assert!(
                        (e[i][0] - want).abs() <= 1e-5 * want.abs(),
                        "{variant:?} key {i}"
                    );
                } else {
                    assert!(e[i][0].is_nan(), "padding key {i}");
                }
                assert_eq!(e[i][1], i as f32);
            }
        }
        let (origin, spacing, dims) = (Vec3::splat(-10.0), 2.5, UVec3::new(8, 8, 8));
        sorter
            .write_keys(
                &positions,
                n,
                &KeyMode::GridCell {
                    origin,
                    spacing,
                    dims,
                },
                false,
            )
            .unwrap();
        let e = sorter.read().unwrap();
        for i in 0..n {
            let p = Vec3::from_slice(&pos[4 * i..4 * i + 3]);
            let c = ((p - origin) / spacing).floor().as_uvec3().min(dims - 1);
            assert_eq!(
                e[i][0],
                ((c.z * dims.y + c.y) * dims.x + c.x) as f32,
                "cell of {p}"
            );
        }
    }
    no_gl_error(&ctx);
}

/// Sorting by viewer distance and rearranging keeps every particle's state together.
#[test]
fn rearrangement_keeps_state_together() {
    let ctx = context();
    let (sw, sh) = (24u32, 20u32);
    let n = (sw * sh) as usize;
    let pos = random_positions(n, 8);
    // Velocity texel = a function of the particle's position, so pairs can be checked after.
    let vel: Vec<f32> = pos
        .chunks(4)
        .flat_map(|p| [p[0] * 2.0, p[1] - 1.0, -p[2], p[3] * 3.0])
        .collect();
    let state = PingPong::new(
        &ctx,
        "state",
        &["position", "velocity"],
        &[TextureFormat::Rgba32F; 2],
        sw,
        sh,
    )
    .unwrap();
    state.front().texture(0).upload_f32(&pos).unwrap();
    state.front().texture(1).upload_f32(&vel).unwrap();
    let eye = Vec3::new(0.0, 0.0, 25.0);
    for variant in Variant::ALL {
        let mut sorter = Sorter::new(&ctx, variant, 32, 16, SortOptions::default()).unwrap();
        sorter
            .write_keys(
                state.front().texture(0),
                n,
                &KeyMode::ViewerDistance {
                    eye,
                    back_to_front: true,
                },
                false,
            )
            .unwrap();
        sorter.sort();
        sorter.rearrange(state.front(), state.back()).unwrap();
        let p = state.back().texture(0).read_f32().unwrap();
        let v = state.back().texture(1).read_f32().unwrap();
        let mut seen = vec![false; n];
        let mut last = f32::INFINITY;
        for j in 0..n {
            let (pj, vj) = (&p[4 * j..4 * j + 4], &v[4 * j..4 * j + 4]);
            assert_eq!(
                vj,
                &[pj[0] * 2.0, pj[1] - 1.0, -pj[2], pj[3] * 3.0],
                "{variant:?} texel {j}"
            );
            let id = pj[3] as usize - 1;
            assert!(!seen[id], "{variant:?}: particle {id} twice");
            seen[id] = true;
            let d = Vec3::from_slice(&pj[..3]).distance(eye);
            assert!(d <= last, "{variant:?}: not back to front at {j}");
            last = d;
        }
    }
    no_gl_error(&ctx);
}

fn distinct(v: impl Iterator<Item = f32>) -> usize {
    let mut b: Vec<u32> = v.map(f32::to_bits).collect();
    b.sort_unstable();
    b.dedup();
    b.len()
}

/// UberFlow §4.3.1 under emulated 24-bit floats: plain ids collide beyond 2^17 particles (16
/// stored mantissa bits plus the hidden one), the paper's enumeration keeps 2^20 distinct, and a
/// sort with it loses no particle while one with plain ids does.
#[test]
fn identifiers_under_24_bit_floats() {
    let ctx = context();
    let fp24 = SortOptions {
        precision: Some(R300),
        ..SortOptions::default()
    };
    let table = SortOptions {
        id_table: true,
        ..fp24
    };
    // 2^20 ids from the key pass (no sort: llvmpipe would take seconds for its 210 passes).
    let (w, h) = (1024u32, 1024u32);
    let n = (w * h) as usize;
    let positions = texture(
        &ctx,
        "test",
        (w, h),
        TextureFormat::Rgba32F,
        &vec![1.0; 4 * n],
    );
    let eye = KeyMode::ViewerDistance {
        eye: Vec3::ZERO,
        back_to_front: false,
    };
    let mut plain = Sorter::new(&ctx, Variant::Fp, w, h, fp24).unwrap();
    plain.write_keys(&positions, n, &eye, false).unwrap();
    let ids = plain.read().unwrap();
    assert_eq!(
        distinct(ids.iter().map(|e| e[1])),
        distinct((0..n).map(|i| R300.round(i as f32)))
    );
    assert!(distinct(ids.iter().map(|e| e[1])) < n);
    assert!(
        ids[..=1 << 17]
            .iter()
            .enumerate()
            .all(|(i, e)| e[1] == i as f32),
        "exact up to 2^17"
    );
    drop(plain);
    let mut tabled = Sorter::new(&ctx, Variant::Fp, w, h, table).unwrap();
    tabled.write_keys(&positions, n, &eye, false).unwrap();
    assert_eq!(distinct(tabled.read().unwrap().iter().map(|e| e[1])), n);
    drop(tabled);
    drop(positions);

    // A full sort and rearrangement of 2^18 particles: plain ids lose particles, table ids do not.
    let (w, h) = (512u32, 512u32);
    let n = (w * h) as usize;
    let pos = random_positions(n, 21);
    let state = PingPong::new(&ctx, "s", &["position"], &[TextureFormat::Rgba32F], w, h).unwrap();
    state.front().texture(0).upload_f32(&pos).unwrap();
    let mut survivors = Vec::new();
    for options in [fp24, table] {
        let mut sorter = Sorter::new(&ctx, Variant::Multistep, w, h, options).unwrap();
        sorter
            .write_keys(
                state.front().texture(0),
                n,
                &KeyMode::ViewerDistance {
                    eye: Vec3::ZERO,
                    back_to_front: false,
                },
                false,
            )
            .unwrap();
        sorter.sort();
        sorter.rearrange(state.front(), state.back()).unwrap();
        let out = state.back().texture(0).read_f32().unwrap();
        survivors.push(distinct(out.chunks(4).map(|p| p[3])));
    }
    assert!(
        survivors[0] < n,
        "plain ids should lose particles: {} of {n} survive",
        survivors[0]
    );
    assert_eq!(survivors[1], n, "the paper's ids keep every particle");
    no_gl_error(&ctx);
}

/// The compact sort in a scene: `render.sort.entries = "compact"` draws e3's frame as the exact
/// blocked sort does (at 64², 20 bits of depth beside the identifier: no two particles of this
/// scene fall in one level that close), `texflow diff` measures it, and compact entries without
/// the blocked variant are refused with the key named.
#[test]
fn compact_entries_render_like_exact_ones() {
    use std::process::Command;
    let dir = tempfile::tempdir().unwrap();
    let render = |name: &str, extra: &[&str]| {
        let out = dir.path().join(name);
        let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
            .args([
                "render",
                "e3",
                "--particles",
                "64",
                "--frames",
                "12",
                "--start",
                "11",
            ])
            .args(["--quiet", "--set", "render.sort.variant=blocked", "--out"])
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        out.join("frame_00011.png")
    };
    let exact = render("exact", &[]);
    let compact = render("compact", &["--set", "render.sort.entries=compact"]);
    let d = texflow::output::diff::diff_files(&exact, &compact).unwrap();
    assert!(d.mean < 0.05 && d.max <= 8, "{d:?}");
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .arg("diff")
        .arg(&exact)
        .arg(&compact)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success() && text.contains("PSNR"), "{text}");
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .arg("diff")
        .arg(&exact)
        .arg(&compact)
        .arg("--json")
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["schema"], "texflow.diff/1");
    assert_eq!(v["texflow_version"], env!("CARGO_PKG_VERSION"));
    assert_eq!(v["records"]["max"], d.max);
    let o = Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args([
            "render",
            "e3",
            "--particles",
            "16",
            "--frames",
            "1",
            "--quiet",
        ])
        .args(["--set", "render.sort.entries=compact", "--out"])
        .arg(dir.path().join("refused"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("render.sort.entries") && err.contains("blocked"),
        "{err}"
    );
    assert!(!dir.path().join("refused").exists());
}
