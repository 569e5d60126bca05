//! A sort's schedule is answered without GL (`texflow::sort::passes_of`), and the GPU sorter runs
//! exactly that many passes, for every variant; the engine's plan reads the same count.

mod common;

use common::context;
use texflow::sort::{pass_count, passes_of, NetworkPass, SortOptions, Sorter, Variant};

#[test]
fn the_sorter_runs_the_passes_its_schedule_lists() {
    let ctx = context();
    for variant in Variant::ALL {
        for (w, h, rows) in [
            (16, 16, None),
            (32, 8, None),
            (16, 16, Some(2)),
            (32, 8, Some(1)),
            (64, 64, None),
        ] {
            let options = SortOptions {
                rows,
                ..SortOptions::default()
            };
            let sorter = Sorter::new(&ctx, variant, w, h, options).unwrap();
            let block = rows.map_or(w * h, |k| w * k);
            let listed = pass_count(variant, w, h, block, &options);
            assert_eq!(
                sorter.pass_count(),
                listed,
                "{} {w}x{h} rows {rows:?}",
                variant.name()
            );
            // Only the blocked sort ends with its unpack pass; the others are steps or groups.
            let net = passes_of(variant, w, h, block, &options);
            let unpacks = net.iter().filter(|p| **p == NetworkPass::Unpack).count();
            assert_eq!(unpacks, usize::from(variant == Variant::Blocked));
        }
    }
}

#[test]
fn the_plan_counts_the_passes_the_engines_sorter_runs() {
    let ctx = context();
    for (name, variant) in [("e3", None), ("smoke-unlit", None), ("e3", Some("blocked"))] {
        let mut scene = texflow::scene::load(name).unwrap();
        scene.particles.size = [32, 32];
        if let Some(v) = variant {
            scene.render.sort.variant = Some(Variant::from_name(v).unwrap());
        }
        let (sorter, plan) = texflow::engine::sorter_for(&ctx, &scene).unwrap().unwrap();
        assert_eq!(plan.passes, sorter.pass_count(), "{name} {variant:?}");
    }
}
