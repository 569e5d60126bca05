//! A gather through two sorts (`Sorter::gather_through`): where a second sort ordered places in
//! the layout a first sort gathered, the sources read through the first land at the place the
//! first sort gave each particle. The staggered collision lattice reads velocity and static this
//! way, so that the first lattice gathers positions alone. Checked against the composition of
//! the two sorts' read-back orders, for every pairing of where the sorts leave their entries.

mod common;

use common::{context, keyed_entries, no_gl_error};
use texflow::gl::{Context, Framebuffer, Texture, TextureDesc, TextureFormat};
use texflow::sort::{Entry, SortOptions, Sorter, Variant};

/// A `w` × `h` RGBA32F texture whose texel i holds (i + offset, -i, tag, 1).
fn named(ctx: &Context, w: u32, h: u32, offset: f32, tag: f32) -> Texture {
    let desc = TextureDesc {
        width: w,
        height: h,
        format: TextureFormat::Rgba32F,
        label: "source",
    };
    let t = Texture::new(ctx, desc).unwrap();
    let v: Vec<f32> = (0..w * h)
        .flat_map(|i| [i as f32 + offset, -(i as f32), tag, 1.0])
        .collect();
    t.upload_f32(&v).unwrap();
    t
}

fn sorter(ctx: &Context, variant: Variant, w: u32, h: u32, kept: bool, input: &[Entry]) -> Sorter {
    let options = SortOptions {
        keep_blocked: kept,
        rows: Some(1),
        ..SortOptions::default()
    };
    let mut s = Sorter::new(ctx, variant, w, h, options).unwrap();
    s.load(input).unwrap();
    s.sort();
    s
}

/// Texel s of the destination: the first source at the second sort's identifier (a place in
/// the first layout), the second and third at the place the first sort gave that particle.
#[test]
fn a_gather_through_two_sorts_composes_their_orders() {
    let ctx = context();
    let (w, h) = (64, 8);
    let n = w * h;
    for (variant, first_kept, second_kept) in [
        (Variant::Blocked, true, true),
        (Variant::Blocked, false, false),
        (Variant::Blocked, true, false),
        (Variant::Blocked, false, true),
        (Variant::Packed, false, false),
        (Variant::Fp, false, false),
    ] {
        let what = format!("{variant:?}, first kept {first_kept}, second kept {second_kept}");
        let first = sorter(
            &ctx,
            variant,
            w,
            h,
            first_kept,
            &keyed_entries(n, 3, 9, 0.0),
        );
        let second = sorter(
            &ctx,
            variant,
            w,
            h,
            second_kept,
            &keyed_entries(n, 11, 7, 0.0),
        );
        // Kept blocked sorts leave their entries in their layout: the lookup reads them there.
        assert_eq!(first.keeps_blocked_layout(), first_kept, "{what}");
        assert_eq!(second.keeps_blocked_layout(), second_kept, "{what}");
        let places = named(&ctx, w, h, 0.0, 1.0);
        let state = named(&ctx, w, h, 0.5, 2.0);
        let statics = named(&ctx, w, h, 0.25, 3.0);
        let dest = Framebuffer::new(
            &ctx,
            "dest",
            (0..3).map(|_| named(&ctx, w, h, 0.0, 0.0)).collect(),
        )
        .unwrap();
        let sources = [&places, &state, &statics];
        (second.gather_through(Some((&first, 0b110)), &sources, &dest)).unwrap();
        // Read the orders only now: a sort that kept its layout unpacks on the first read.
        let order = |s: &Sorter| -> Vec<usize> {
            s.read().unwrap().iter().map(|e| e[1] as usize).collect()
        };
        let (a, b) = (order(&first), order(&second));
        let out: Vec<Vec<f32>> = (dest.textures().iter())
            .map(|t| t.read_f32().unwrap())
            .collect();
        for s in 0..n as usize {
            let (j, i) = (b[s], a[b[s]]);
            let texel = |k: usize| &out[k][4 * s..4 * s + 4];
            assert_eq!(
                texel(0),
                [j as f32, -(j as f32), 1.0, 1.0],
                "{what}: texel {s}"
            );
            assert_eq!(
                texel(1),
                [i as f32 + 0.5, -(i as f32), 2.0, 1.0],
                "{what}: {s}"
            );
            assert_eq!(
                texel(2),
                [i as f32 + 0.25, -(i as f32), 3.0, 1.0],
                "{what}: {s}"
            );
        }
    }
    no_gl_error(&ctx);
}

/// Two sorts of different variants (their identifiers read differently) are refused, and
/// nothing is drawn.
#[test]
fn a_gather_through_a_sort_of_another_variant_is_refused() {
    let ctx = context();
    let (w, h) = (32, 4);
    let first = sorter(
        &ctx,
        Variant::Packed,
        w,
        h,
        false,
        &keyed_entries(w * h, 5, 9, 0.0),
    );
    let second = sorter(
        &ctx,
        Variant::Fp,
        w,
        h,
        false,
        &keyed_entries(w * h, 6, 9, 0.0),
    );
    let source = named(&ctx, w, h, 0.0, 1.0);
    let dest = Framebuffer::new(&ctx, "dest", vec![named(&ctx, w, h, 9.0, 9.0)]).unwrap();
    ctx.take_draw_stats();
    let err = second
        .gather_through(Some((&first, 1)), &[&source], &dest)
        .unwrap_err()
        .to_string();
    assert!(err.contains("same variant and size"), "{err}");
    assert_eq!(ctx.take_draw_stats().draws, 0);
    no_gl_error(&ctx);
}
