//! The `local` spread (`render.sort.spread`): on the GPU, a whole cycle of it, a few passes a
//! frame, sorts keys that hold still, as the CPU's sort does; a scene asking for it elsewhere
//! is refused at the key.

mod common;

use common::{context, no_gl_error};
use texflow::sort::spread::Spread;
use texflow::sort::{SortOptions, Sorter, Variant};

#[test]
fn local_spread_cycle_ends_sorted_on_the_gpu() {
    let ctx = context();
    let options = SortOptions {
        passes_per_frame: Some(5),
        spread: Spread::Local,
        ..SortOptions::default()
    };
    let mut sorter = Sorter::new(&ctx, Variant::OddEven, 16, 16, options).unwrap();
    assert!(sorter.cycle_len() > sorter.pass_count());
    let mut g = 99u64;
    let entries: Vec<[f32; 2]> = (0..256)
        .map(|i| {
            g = g
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            [(g >> 44) as f32, i as f32]
        })
        .collect();
    sorter.load(&entries).unwrap();
    let mut expected = entries.clone();
    expected.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    let frames = sorter.cycle_len().div_ceil(5);
    for frame in 0..frames {
        let before = sorter.read().unwrap();
        assert!(before != expected || frame > 0, "sorted before the cycle");
        sorter.sort_frame();
    }
    assert_eq!(sorter.read().unwrap(), expected);
    no_gl_error(&ctx);
}

#[test]
fn local_spread_needs_the_odd_even_sort_spread_over_frames() {
    let smoke = include_str!("../examples/scenes/smoke.toml");
    for (extra, word) in [
        ("[render.sort]\nspread = \"local\"\n", "passes_per_frame"),
        (
            "[render.sort]\nspread = \"local\"\npasses_per_frame = 4\nvariant = \"fp\"\n",
            "oddeven",
        ),
    ] {
        let text = smoke.replace("[render.sort]\nvariant = \"oddeven\"\n", extra);
        assert!(text != smoke, "the smoke scene's [render.sort] moved");
        let err = texflow::scene::parse("s.toml", &text)
            .unwrap_err()
            .to_string();
        assert!(err.contains("s.toml:") && err.contains(word), "{err}");
    }
}
