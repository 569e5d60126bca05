//! The GPU sorts on a real GL context, against their CPU twins (bit for bit) and `slice::sort`.

mod common;

use common::{context, keyed_entries as entries, lcg, no_gl_error};
use texflow::gl::Context;
use texflow::sort::blocked;
use texflow::sort::network::{
    apply_group, apply_step, bitonic_schedule, blocks_sorted, group_steps, inversions,
    key_order_bits, odd_even_schedule,
};
use texflow::sort::{Entry, SortOptions, Sorter, Variant};

/// The twin: the same schedule on the CPU.
fn twin(
    variant: Variant,
    input: &[Entry],
    width: u32,
    block: u32,
    options: &SortOptions,
) -> Vec<Entry> {
    let mut v = input.to_vec();
    match variant {
        Variant::OddEven => odd_even_schedule(block)
            .iter()
            .for_each(|s| apply_step(&mut v, s, width)),
        Variant::Multistep => group_steps(&bitonic_schedule(width, block), options.steps_per_pass)
            .iter()
            .for_each(|g| apply_group(&mut v, g, width)),
        Variant::Blocked => blocked::apply(&mut v, &blocked::network(block.trailing_zeros())),
        _ => bitonic_schedule(width, block)
            .iter()
            .for_each(|s| apply_step(&mut v, s, width)),
    }
    v
}

fn bits(v: &[Entry]) -> Vec<(u32, u32)> {
    v.iter().map(|e| (e[0].to_bits(), e[1].to_bits())).collect()
}

/// Keys of several kinds: random with duplicates, all equal, sorted, reversed, and specials.
fn key_sets(n: usize, seed: u64) -> Vec<(&'static str, Vec<f32>)> {
    let mut s = seed;
    let specials = [
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        -0.0,
        0.0,
        1e-40,
        -1e-40,
        f32::MAX,
    ];
    vec![
        (
            "random",
            (0..n).map(|_| lcg(&mut s) as f32 / 7919.0 - 1e5).collect(),
        ),
        (
            "duplicates",
            (0..n).map(|_| (lcg(&mut s) % 5) as f32).collect(),
        ),
        ("all equal", vec![3.5; n]),
        ("sorted", (0..n).map(|i| i as f32).collect()),
        ("reversed", (0..n).map(|i| -(i as f32)).collect()),
        (
            "specials",
            (0..n)
                .map(|_| {
                    let r = lcg(&mut s);
                    if r.is_multiple_of(3) {
                        specials[(r / 3) as usize % specials.len()]
                    } else {
                        (r % 100) as f32 - 50.0
                    }
                })
                .collect(),
        ),
    ]
}

fn check_variant(ctx: &Context, variant: Variant, w: u32, h: u32) {
    let options = SortOptions::default();
    let mut sorter = Sorter::new(ctx, variant, w, h, options).unwrap();
    let n = (w * h) as usize;
    for (name, keys) in key_sets(n, (w * 31 + h) as u64) {
        let input: Vec<Entry> = keys
            .iter()
            .enumerate()
            .map(|(i, &k)| [k, i as f32])
            .collect();
        sorter.load(&input).unwrap();
        sorter.sort();
        let got = sorter.read().unwrap();
        let want = twin(variant, &input, w, w * h, &options);
        assert_eq!(
            bits(&got),
            bits(&want),
            "{variant:?} {w}x{h} {name}: GPU differs from its twin"
        );
        // The twin itself against slice::sort on the same order.
        let mut reference = input.clone();
        reference.sort_by_key(|e| (key_order_bits(e[0]), e[1].to_bits()));
        assert_eq!(
            bits(&want),
            bits(&reference),
            "{variant:?} {w}x{h} {name}: twin is not a sort"
        );
        // Ids are a permutation and each carries its own key.
        let mut seen = vec![false; n];
        for e in &got {
            let id = e[1] as usize;
            assert!(!seen[id], "{variant:?} {name}: id {id} duplicated");
            seen[id] = true;
            assert_eq!(
                e[0].to_bits(),
                keys[id].to_bits(),
                "{variant:?} {name}: key of id {id}"
            );
        }
    }
}

#[test]
fn every_variant_matches_its_twin_and_sorts() {
    let ctx = context();
    let sizes = [
        (1, 1),
        (2, 1),
        (1, 2),
        (4, 4),
        (8, 2),
        (2, 8),
        (16, 16),
        (64, 32),
        (32, 128),
        (256, 256),
    ];
    for variant in Variant::ALL {
        for &(w, h) in &sizes {
            if variant.packed() && w < 2 {
                continue; // two entries per texel need rows of at least two
            }
            check_variant(&ctx, variant, w, h);
        }
    }
    no_gl_error(&ctx);
}

#[test]
fn multistep_with_one_and_three_wide_steps_per_pass() {
    let ctx = context();
    for steps in [1, 3] {
        let options = SortOptions {
            steps_per_pass: steps,
            ..SortOptions::default()
        };
        let (w, h) = (32, 16);
        let mut sorter = Sorter::new(&ctx, Variant::Multistep, w, h, options).unwrap();
        let input = entries(w * h, 5, 50, 0.0);
        sorter.load(&input).unwrap();
        sorter.sort();
        let got = sorter.read().unwrap();
        assert_eq!(
            bits(&got),
            bits(&twin(Variant::Multistep, &input, w, w * h, &options))
        );
        assert!(blocks_sorted(&got, (w * h) as usize));
    }
    no_gl_error(&ctx);
}

/// Our blocked sort with 4, 8 and 16 entries per fragment, with and without the pinned lane, on
/// square, wide and tall textures, in blocks of two rows and rows only: bit for bit its twin,
/// and sorted.
#[test]
fn blocked_sort_every_shape() {
    let ctx = context();
    for bits_per_pass in [2, 3, 4] {
        for (pinned, merge) in [(false, false), (true, false), (false, true)] {
            for (w, h, rows) in [
                (32, 32, None),
                (64, 4, None),
                (2, 128, None),
                (16, 16, Some(2)),
                // Rows only (the collision sorts of UberFlow's E4): the network over the low
                // log2(width) bits, down to rows of two entries.
                (16, 16, Some(1)),
                (64, 4, Some(1)),
                (2, 128, Some(1)),
                // Long enough runs for the merges' partition passes at every entries per
                // fragment (runs of 2^(bits + 6) and more), their splits in one row and in rows.
                (128, 64, None),
                (16, 1024, None),
                // ... and within rows and sets of rows (the collision and fluid block sorts).
                (2048, 8, Some(1)),
                (256, 32, Some(4)),
            ] {
                let options = SortOptions {
                    blocked: texflow::sort::BlockedShape {
                        bits: bits_per_pass,
                        pinned,
                        compact: false,
                        merge,
                    },
                    rows,
                    ..SortOptions::default()
                };
                let mut sorter = Sorter::new(&ctx, Variant::Blocked, w, h, options).unwrap();
                let input = entries(w * h, 11 + w as u64, 300, -150.0);
                sorter.load(&input).unwrap();
                sorter.sort();
                let got = sorter.read().unwrap();
                let block = rows.map_or(w * h, |k| w * k);
                let what = format!(
                    "bits {bits_per_pass} pinned {pinned} merge {merge} {w}x{h} rows {rows:?}"
                );
                assert_eq!(
                    bits(&got),
                    bits(&twin(Variant::Blocked, &input, w, block, &options)),
                    "{what}"
                );
                assert!(blocks_sorted(&got, block as usize), "{what}");
            }
        }
    }
    no_gl_error(&ctx);
}

/// Keys in [-150, 150) fine enough that many share a compact level at 2^10 entries (22 key
/// bits), and one in 17 special (infinities, NaN, far out of range).
fn fine_keys(n: u32, seed: u64) -> Vec<Entry> {
    let mut s = seed;
    let specials = [f32::INFINITY, f32::NAN, f32::NEG_INFINITY, -1e9, 1e9];
    (0..n)
        .map(|i| {
            let r = lcg(&mut s);
            let key = if r.is_multiple_of(17) {
                specials[(r / 17) as usize % specials.len()]
            } else {
                (r % 3_000_000) as f32 * 1e-4 - 150.0
            };
            [key, i as f32]
        })
        .collect()
}

/// The blocked sort with compact 4-byte entries (lossy keys), 4 to 32 entries per fragment:
/// the identifiers come out in the order of a CPU sort by (quantisation level, identifier), the
/// levels computed by the twin of the shader's quantiser; keys come back as their level's lower
/// bound; and wherever two keys lie two levels apart or more, the order is the exact one.
#[test]
fn compact_blocked_sort_orders_by_level_then_id() {
    let ctx = context();
    for (bits_per_pass, merge) in [2, 3, 4, 5]
        .into_iter()
        .flat_map(|b| [(b, false), (b, true)])
    {
        for (w, h, rows) in [
            (32, 32, None),
            (64, 4, None),
            (2, 128, None),
            (16, 16, Some(2)),
            // Partition passes (runs of 2^(bits + 6) and more), also within sets of rows.
            (128, 64, None),
            (16, 1024, None),
            (1024, 16, Some(2)),
        ] {
            let options = SortOptions {
                blocked: texflow::sort::BlockedShape {
                    bits: bits_per_pass,
                    pinned: false,
                    compact: true,
                    merge,
                },
                rows,
                ..SortOptions::default()
            };
            let mut sorter = Sorter::new(&ctx, Variant::Blocked, w, h, options).unwrap();
            let (lo, hi) = (-150.0f32, 150.0f32);
            sorter.set_key_range(lo, hi).unwrap();
            let q = sorter.quantiser().unwrap();
            let input = fine_keys(w * h, 5 + w as u64);
            sorter.load(&input).unwrap();
            sorter.sort();
            let got = sorter.read().unwrap();
            let block = rows.map_or(w * h, |k| w * k) as usize;
            let what = format!("bits {bits_per_pass} merge {merge} {w}x{h} rows {rows:?}");
            let mut expected: Vec<(u32, u32)> = Vec::new();
            for chunk in input.chunks(block) {
                let mut c: Vec<(u32, u32)> =
                    chunk.iter().map(|e| (q.level(e[0]), e[1] as u32)).collect();
                c.sort_unstable();
                expected.extend(c);
            }
            let ids: Vec<u32> = got.iter().map(|e| e[1] as u32).collect();
            let want: Vec<u32> = expected.iter().map(|e| e.1).collect();
            assert_eq!(ids, want, "{what}: identifiers");
            let top = (1u32 << (32 - q.id_bits)) - 1;
            for (e, &(level, id)) in got.iter().zip(&expected) {
                if level == top {
                    assert_eq!(e[0], f32::INFINITY, "{what}: id {id} at the top level");
                } else {
                    let bound = q.lo + level as f32 / q.scale;
                    assert!(
                        (e[0] - bound).abs() <= 1e-5 * (1.0 + bound.abs()),
                        "{what}: id {id} key {} for level {level} (lower bound {bound})",
                        e[0]
                    );
                }
            }
            // Against the exact order: keys two levels apart or more never come out swapped.
            for chunk in got.chunks(block) {
                for pair in chunk.windows(2) {
                    let (a, b) = (input[pair[0][1] as usize][0], input[pair[1][1] as usize][0]);
                    if a.is_finite() && b.is_finite() && a - b >= 2.0 / q.scale {
                        panic!("{what}: key {a} before {b}");
                    }
                }
            }
        }
    }
    no_gl_error(&ctx);
}

#[test]
fn blocked_sort_refuses_what_it_cannot_order() {
    let ctx = context();
    // Too many entries for 8 key bits, and pinned lanes, are refused with the fix.
    for (w, h, bits, pinned, compact, merge, needle) in [
        (4096, 8192, 4, false, true, false, "2^24"),
        (32, 32, 4, true, true, false, "pinned"),
        (32, 32, 6, false, true, false, "bits 2 to 5"),
        // Merge passes read row-major entries: no pinned lane, exact or compact.
        (32, 32, 4, true, false, true, "no pinned lane"),
    ] {
        let options = SortOptions {
            blocked: texflow::sort::BlockedShape {
                bits,
                pinned,
                compact,
                merge,
            },
            ..SortOptions::default()
        };
        let err = Sorter::new(&ctx, Variant::Blocked, w, h, options).unwrap_err();
        assert!(err.to_string().contains(needle), "{err}");
    }
    no_gl_error(&ctx);
}

/// The 0-1 principle on the GPU: all 65,536 0/1 inputs of 16 elements, a row of 16 (or 4 rows of
/// 4) per input, sorted in batches with the rows-only modes.
#[test]
fn zero_one_principle_on_the_gpu() {
    let ctx = context();
    let rows_per_batch = 4096u32;
    for variant in Variant::ALL {
        for (w, k) in [(16u32, 1u32), (4, 4)] {
            if variant == Variant::OddEven && w == 4 {
                continue; // odd-even works on the 1D index: one layout covers it
            }
            let options = SortOptions {
                rows: Some(k),
                ..SortOptions::default()
            };
            let h = rows_per_batch;
            let groups_per_batch = (w * h / 16) as usize;
            let mut sorter = Sorter::new(&ctx, variant, w, h, options).unwrap();
            for batch in 0..(65536 / groups_per_batch) {
                let input: Vec<Entry> = (0..w * h)
                    .map(|i| {
                        let case = (batch * groups_per_batch) as u32 + i / 16;
                        [((case >> (i % 16)) & 1) as f32, i as f32]
                    })
                    .collect();
                sorter.load(&input).unwrap();
                sorter.sort();
                let got = sorter.read().unwrap();
                for (g, (out, inp)) in got.chunks(16).zip(input.chunks(16)).enumerate() {
                    let ones = inp.iter().filter(|e| e[0] == 1.0).count();
                    let want: Vec<f32> = (0..16)
                        .map(|i| if i >= 16 - ones { 1.0 } else { 0.0 })
                        .collect();
                    let keys: Vec<f32> = out.iter().map(|e| e[0]).collect();
                    assert_eq!(
                        keys,
                        want,
                        "{variant:?} {w}x{k}: case {}",
                        batch * groups_per_batch + g
                    );
                }
            }
        }
    }
    no_gl_error(&ctx);
}

/// Latta's sort spread over frames: one pass at a time, inversions never increase; 0 at the end.
#[test]
fn odd_even_spread_over_frames_never_loses_sortedness() {
    let ctx = context();
    let (w, h) = (32, 32);
    let mut sorter = Sorter::new(&ctx, Variant::OddEven, w, h, SortOptions::default()).unwrap();
    let input = entries(w * h, 17, 300, 0.0);
    sorter.load(&input).unwrap();
    let mut last = inversions(&input);
    assert!(last > 0);
    let total = sorter.pass_count();
    for pass in 0..total {
        assert_eq!(sorter.run_passes(1), 1);
        let now = inversions(&sorter.read().unwrap());
        assert!(now <= last, "pass {pass}: inversions {last} -> {now}");
        last = now;
    }
    assert_eq!(last, 0);
    assert_eq!(sorter.passes_done(), total);
    no_gl_error(&ctx);
}

/// `passes_per_frame` spreads the sort over frames: after ceil(passes / per_frame) frames the
/// entries are sorted, and the next frame starts the sequence over.
#[test]
fn passes_per_frame_spreads_the_sort() {
    let ctx = context();
    let options = SortOptions {
        passes_per_frame: Some(4),
        ..SortOptions::default()
    };
    let mut sorter = Sorter::new(&ctx, Variant::OddEven, 16, 16, options).unwrap();
    let input = entries(256, 23, 90, 0.0);
    sorter.load(&input).unwrap();
    let total = sorter.pass_count(); // 36
    let frames = total.div_ceil(4);
    for frame in 0..frames {
        let ran = sorter.sort_frame();
        assert_eq!(ran, 4.min(total - 4 * frame));
        let sorted = blocks_sorted(&sorter.read().unwrap(), 256);
        assert_eq!(sorted, frame + 1 == frames, "frame {frame}");
    }
    assert_eq!(sorter.sort_frame(), 4, "the sequence starts again");
    assert!(
        blocks_sorted(&sorter.read().unwrap(), 256),
        "sorted data stays sorted"
    );
    no_gl_error(&ctx);
}

/// What a sort's passes declare they fetch (the cost model's count, in the GL layer's draw
/// counts): two entries a fragment in the fragment-program networks, one texel (two entries)
/// a fragment in the packed one, 2^k texels of two entries in multistep's; the blocked sort at least each entry once a pass that writes
/// them all, and its merges' searches on top.
#[test]
fn every_sort_declares_what_its_passes_fetch() {
    let ctx = context();
    let (w, h) = (64u32, 64u32);
    let n = (w * h) as u64;
    for variant in Variant::ALL {
        let mut sorter = Sorter::new(&ctx, variant, w, h, SortOptions::default()).unwrap();
        let input = entries(w * h, 3, 1000, 0.0);
        sorter.load(&input).unwrap();
        ctx.take_draw_stats();
        sorter.sort();
        let d = ctx.take_draw_stats();
        let passes = sorter.pass_count() as u64;
        assert_eq!(d.draws, passes, "{variant:?}");
        assert_eq!(d.fetches, sorter.network_fetches(), "{variant:?}");
        match variant {
            Variant::Fp | Variant::GpFp | Variant::OddEven => {
                assert_eq!(d.fetches, passes * 2 * n, "{variant:?}")
            }
            Variant::Packed => assert_eq!(d.fetches, passes * n, "{variant:?}"),
            // Two entries a texel, at least one texel a fragment of two entries.
            Variant::Multistep => assert!(d.fetches >= passes * n / 2, "{variant:?}"),
            Variant::Blocked => {
                let entry_passes = sorter.network_pass_count() as u64 + 1;
                assert!(d.fetches > entry_passes * n, "{variant:?}: {}", d.fetches);
            }
        }
    }
    no_gl_error(&ctx);
}

fn rgba_texture(ctx: &Context, w: u32, h: u32) -> texflow::gl::Texture {
    use texflow::gl::{Texture, TextureDesc, TextureFormat};
    let desc = TextureDesc {
        width: w,
        height: h,
        format: TextureFormat::Rgba32F,
        label: "gathered",
    };
    Texture::new(ctx, desc).unwrap()
}

/// A blocked sort that keeps its layout (no unpack pass) gathers exactly what the same sort
/// unpacked gathers, the CPU twin's order, and reads back row-major on demand; a second gather
/// after that reads the unpacked texture, the same. Compact entries unpack as before.
#[test]
fn blocked_sort_kept_in_its_layout_gathers_in_place() {
    let ctx = context();
    let texture = |w, h| rgba_texture(&ctx, w, h);
    for (w, h, rows, merge, compact) in [
        (64, 16, Some(1), true, false),
        (32, 32, None, true, false),
        (2048, 8, Some(1), true, false),
        (16, 16, Some(1), false, false),
        (32, 32, None, false, false),
        (32, 32, None, true, true),
    ] {
        let shape = texflow::sort::BlockedShape {
            bits: if compact { 5 } else { 4 },
            pinned: false,
            compact,
            merge,
        };
        let base = SortOptions {
            blocked: shape,
            rows,
            ..SortOptions::default()
        };
        let what = format!("{w}x{h} rows {rows:?} merge {merge} compact {compact}");
        // Few distinct keys: the order among equal keys is the identifiers'.
        let input = entries(w * h, 5 + w as u64, 40, 0.0);
        // Texel i holds (i, -i, i / 2, 7): what a gather wrote names its source.
        let source = texture(w, h);
        let values = (0..w * h).flat_map(|i| [i as f32, -(i as f32), 0.5 * i as f32, 7.0]);
        source.upload_f32(&values.collect::<Vec<_>>()).unwrap();
        let mut out = Vec::new();
        for o in [
            base,
            SortOptions {
                keep_blocked: true,
                ..base
            },
        ] {
            let mut s = Sorter::new(&ctx, Variant::Blocked, w, h, o).unwrap();
            s.load(&input).unwrap();
            ctx.take_draw_stats();
            s.sort();
            assert_eq!(ctx.take_draw_stats().draws, s.pass_count() as u64, "{what}");
            let dest = texflow::gl::Framebuffer::new(&ctx, "dest", vec![texture(w, h)]).unwrap();
            s.gather(&[&source], &dest).unwrap();
            out.push((s, dest.only_texture().read_f32().unwrap()));
        }
        let (unpacked, kept) = (&out[0], &out[1]);
        let in_place = kept.0.keeps_blocked_layout();
        // Merged exact entries lie row-major within the blocks; a network pass's may too (a
        // block of one fragment), else the sort unpacks.
        assert!(in_place || !merge || compact, "{what}");
        assert!(!(in_place && compact), "{what}");
        assert_eq!(
            kept.0.pass_count() + in_place as usize,
            unpacked.0.pass_count(),
            "{what}"
        );
        assert_eq!(kept.1, unpacked.1, "{what}");
        let sorted = unpacked.0.read().unwrap();
        if !compact {
            let block = rows.map_or(w * h, |k| w * k);
            let want = twin(Variant::Blocked, &input, w, block, &base);
            assert_eq!(bits(&sorted), bits(&want), "{what}");
        }
        for (j, e) in sorted.iter().enumerate() {
            assert_eq!(kept.1[4 * j], e[1], "{what}: texel {j}");
        }
        assert_eq!(bits(&kept.0.read().unwrap()), bits(&sorted), "{what}");
        let again = texflow::gl::Framebuffer::new(&ctx, "again", vec![texture(w, h)]).unwrap();
        kept.0.gather(&[&source], &again).unwrap();
        assert_eq!(again.only_texture().read_f32().unwrap(), kept.1, "{what}");
    }
    no_gl_error(&ctx);
}
