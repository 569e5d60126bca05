//! Rows-only compact exact entries: the blocked sort of cell keys within rows packs (cell level,
//! column) into one uint. Checked against the CPU reference (a stable sort of each block of rows
//! by (key, id)) and against the same sort with 8-byte entries, bit for bit, with ties, the
//! top cells, dead (+inf) and padding (NaN) keys; and the fallback where the lattice has more
//! cells than the levels hold.

mod common;

use common::{context, no_gl_error};
use texflow::gl::Context;
use texflow::sort::{
    entry_less, row_cell_entry, row_cells_fit, Entry, SortOptions, Sorter, Variant,
};

fn lcg(s: &mut u64) -> u64 {
    *s = s
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    *s >> 33
}

fn bits(v: &[Entry]) -> Vec<[u32; 2]> {
    v.iter().map(|e| [e[0].to_bits(), e[1].to_bits()]).collect()
}

/// The reference: each block of `block` entries sorted by (key, id), stably (ids are distinct,
/// so any correct sort gives this order).
fn reference(input: &[Entry], block: usize) -> Vec<Entry> {
    let mut out = input.to_vec();
    for chunk in out.chunks_mut(block) {
        chunk.sort_by(|a, b| match (entry_less(*a, *b), entry_less(*b, *a)) {
            (true, _) => std::cmp::Ordering::Less,
            (_, true) => std::cmp::Ordering::Greater,
            _ => std::cmp::Ordering::Equal,
        });
    }
    out
}

/// Keys as the key pass writes them: mostly few cells (many ties), some at the top of the
/// lattice, dead particles (+inf) and padding (NaN: past `count`, and a few before, so that
/// NaN and +inf meet in either column order); ids are the indices.
fn cell_entries(n: usize, cells: u64, count: usize, seed: u64) -> Vec<Entry> {
    let mut s = seed;
    (0..n)
        .map(|i| {
            let key = if i >= count {
                f32::from_bits(0x7fc0_0000)
            } else {
                match lcg(&mut s) % 8 {
                    0 => f32::INFINITY,
                    1 => (cells - 1 - lcg(&mut s) % 2) as f32,
                    2 => 0.0,
                    3 => f32::from_bits(0x7fc0_0000),
                    _ => (lcg(&mut s) % 6) as f32,
                }
            };
            [key, i as f32]
        })
        .collect()
}

fn sorted(ctx: &Context, size: [u32; 2], options: SortOptions, input: &[Entry]) -> Vec<Entry> {
    let mut sorter = Sorter::new(ctx, Variant::Blocked, size[0], size[1], options).unwrap();
    assert_eq!(sorter.row_cells(), options.cell_keys.is_some());
    sorter.load(input).unwrap();
    sorter.sort();
    sorter.read().unwrap()
}

#[test]
fn rows_only_exact_compact_entries_sort_as_the_eight_byte_ones() {
    let ctx = context();
    for (w, h, rows) in [(32u32, 32, 1u32), (64, 16, 1), (16, 16, 4), (256, 4, 1)] {
        let block_bits = (w * rows).trailing_zeros();
        // The largest lattice the levels hold: the top cells use the top levels.
        let cells = ((1u64 << (32 - block_bits)) - 3).min(1 << 24);
        assert!(row_cells_fit(cells, block_bits));
        let n = (w * h) as usize;
        for (seed, count) in [(1, n), (2, n - w as usize - 5)] {
            let input = cell_entries(n, cells, count, seed);
            let exact = SortOptions {
                rows: Some(rows),
                ..Default::default()
            };
            let compact = SortOptions {
                cell_keys: Some(cells),
                ..exact
            };
            let got = sorted(&ctx, [w, h], compact, &input);
            let what = format!("{w}x{h}, rows {rows}, seed {seed}");
            let want = reference(&input, (w * rows) as usize);
            assert_eq!(bits(&got), bits(&want), "{what}: against the reference");
            let eight = sorted(&ctx, [w, h], exact, &input);
            assert_eq!(bits(&got), bits(&eight), "{what}: against 8-byte entries");
            // Merge passes after the first (rows wider than a fragment's 32 entries).
            let mut merging = compact;
            merging.blocked.merge = true;
            let merged = sorted(&ctx, [w, h], merging, &input);
            assert_eq!(bits(&merged), bits(&want), "{what}: merging");
            // Not vacuous: ties, top cells, dead and padding keys all occur in one block.
            let row = &input[..(w * rows) as usize];
            assert!(row.iter().filter(|e| e[0] == 0.0).count() >= 2, "{what}");
            assert!(row.iter().any(|e| e[0] == (cells - 1) as f32), "{what}");
            assert!(row.iter().any(|e| e[0].is_infinite()), "{what}");
        }
    }
    no_gl_error(&ctx);
}

/// The CPU twin of the shader's entry orders as (key, id) does, on the boundary cells.
#[test]
fn entry_levels_keep_the_order_of_whole_keys() {
    let block_bits = 10;
    let cells = (1u64 << 22) - 3;
    let keys = [
        f32::NEG_INFINITY,
        0.0,
        1.0,
        (cells - 2) as f32,
        (cells - 1) as f32,
        f32::INFINITY,
        f32::NAN,
    ];
    for (a, &ka) in keys.iter().enumerate() {
        for (b, &kb) in keys.iter().enumerate() {
            for (ia, ib) in [(3u32, 700u32), (700, 3), (5, 5)] {
                let want = entry_less([ka, ia as f32], [kb, ib as f32]);
                let got = row_cell_entry(ka, ia, block_bits) < row_cell_entry(kb, ib, block_bits);
                assert_eq!(got, want, "keys {a} {b}, columns {ia} {ib}");
            }
        }
    }
}

/// 1024 wide: 2^22 - 3 cells fit beside 10 column bits, one more does not; past 2^24 cells keys
/// are no longer exact floats at any width.
#[test]
fn the_fit_is_decided_from_the_lattice() {
    assert!(row_cells_fit((1 << 22) - 3, 10));
    assert!(!row_cells_fit((1 << 22) - 2, 10));
    assert!(row_cells_fit(1 << 24, 5));
    assert!(!row_cells_fit((1 << 24) + 1, 5));
    let options = |cells| SortOptions {
        rows: Some(1),
        cell_keys: Some(cells),
        ..Default::default()
    };
    assert!(options((1 << 22) - 3).row_cells(Variant::Blocked, 1024));
    assert!(!options((1 << 22) - 2).row_cells(Variant::Blocked, 1024));
    assert!(!options(100).row_cells(Variant::Packed, 1024));
    let full = SortOptions {
        rows: None,
        ..options(100)
    };
    assert!(!full.row_cells(Variant::Blocked, 1024));
    // The shape it runs: four-byte entries, one group bit more than the exact default.
    let shape = options(100).blocked_shape(Variant::Blocked, 1024);
    assert!(shape.compact && shape.bits == 5 && !shape.pinned);
}

/// A lattice with more cells than the levels hold keeps 8-byte entries, and still sorts.
#[test]
fn too_many_cells_fall_back_to_eight_byte_entries() {
    let ctx = context();
    let (w, h) = (256, 4);
    let cells = (1u64 << 24) - 2;
    let options = SortOptions {
        rows: Some(1),
        cell_keys: Some(cells),
        ..Default::default()
    };
    let mut sorter = Sorter::new(&ctx, Variant::Blocked, w, h, options).unwrap();
    assert!(!sorter.row_cells());
    assert!(!sorter.blocked_shape().compact);
    let input = cell_entries((w * h) as usize, cells, (w * h) as usize, 9);
    sorter.load(&input).unwrap();
    sorter.sort();
    let got = sorter.read().unwrap();
    assert_eq!(bits(&got), bits(&reference(&input, w as usize)));
    no_gl_error(&ctx);
}

/// Entries the 4-byte levels cannot hold as they are are refused, not rounded.
#[test]
fn entries_that_are_not_cells_are_refused() {
    let ctx = context();
    let options = SortOptions {
        rows: Some(1),
        cell_keys: Some(100),
        ..Default::default()
    };
    let mut sorter = Sorter::new(&ctx, Variant::Blocked, 16, 4, options).unwrap();
    let good = cell_entries(64, 100, 60, 3);
    sorter.load(&good).unwrap();
    for (i, bad) in [[2.5, 7.0], [100.0, 7.0], [-1.0, 7.0], [3.0, 8.0]]
        .into_iter()
        .enumerate()
    {
        let mut e = good.clone();
        e[7] = bad;
        let m = sorter.load(&e).unwrap_err().to_string();
        assert!(
            m.contains("entry 7") && m.contains("cells below 100"),
            "{i}: {m}"
        );
    }
    no_gl_error(&ctx);
}
