//! The sort key of alpha blending (`render.sort.key`): the viewer's distance (the default) or the
//! particle's age, youngest or oldest on top, through every GPU sort variant and the CPU engine,
//! against an ordering computed on the CPU from the state read back.

mod common;

use common::{context, no_gl_error};
use texflow::scene::{self, DrawOrder, SceneFile, SortKey};
use texflow::sort::Variant;

/// A 16x16 allocator scene with alpha blending, sorted by `key` with `variant`, drawn `order`.
fn scene(variant: Variant, key: SortKey, order: DrawOrder, emitter: &str) -> SceneFile {
    let order = match order {
        DrawOrder::BackToFront => "back_to_front",
        DrawOrder::FrontToBack => "front_to_back",
    };
    let src = format!(
        "name = \"ages\"\n[particles]\nsize = [16, 16]\n[time]\ndt = 0.02\n\
         {emitter}\
         [[forces.gravity]]\nacceleration = [0.0, -1.0, 0.0]\n\
         [render]\nresolution = [32, 32]\nblending = \"alpha\"\norder = \"{order}\"\n\
         [render.sort]\nvariant = \"{}\"\nkey = \"{}\"\n",
        variant.name(),
        key.name()
    );
    scene::parse("ages", &src).unwrap()
}

const ALLOCATOR: &str = "[[emitters.allocator]]\nrate = 250.0\nshape = \"sphere\"\nradius = 0.3\n\
    direction = [0.0, 1.0, 0.0]\ncone_degrees = 30.0\nspeed = [0.5, 1.0]\nlife = [0.4, 0.9]\n";
const TIMESTAMP: &str = "[[emitters.timestamp]]\ncycle = 1.0\nshape = \"sphere\"\nradius = 0.3\n\
    direction = [0.0, 1.0, 0.0]\ncone_degrees = 30.0\nspeed = [0.5, 1.0]\nlife = [0.3, 0.9]\n";

/// The drawing order the key asks for, from positions (x, y, z, remaining life) and statics
/// (birth, type, total life, random): live particles by m (smaller on top; m = age for the
/// youngest on top, -age for the oldest), the least on top first when drawn back to front, the
/// most on top first when front to back; equal keys in index order.
fn expected(positions: &[f32], statics: &[f32], key: SortKey, order: DrawOrder) -> Vec<u32> {
    let mut live: Vec<(f32, u32)> = positions
        .chunks(4)
        .zip(statics.chunks(4))
        .enumerate()
        .filter(|(_, (p, _))| p[3] > 0.0)
        .map(|(i, (p, s))| {
            let age = s[2] - p[3];
            let m = if key == SortKey::YoungestOnTop {
                age
            } else {
                -age
            };
            let k = if order == DrawOrder::BackToFront {
                -m
            } else {
                m
            };
            (k, i as u32)
        })
        .collect();
    live.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap().then(a.1.cmp(&b.1)));
    live.into_iter().map(|(_, i)| i).collect()
}

/// Every GPU variant, both age keys, both drawing orders: the sorted identifiers of the live
/// particles are the CPU's ordering of their ages (read back from the state), and the youngest
/// is on top (drawn last with the over operator, first with the under operator) or the oldest.
#[test]
fn gpu_sorts_by_age_in_every_variant() {
    let ctx = context();
    for variant in Variant::ALL {
        for key in [SortKey::YoungestOnTop, SortKey::OldestOnTop] {
            for order in [DrawOrder::BackToFront, DrawOrder::FrontToBack] {
                let s = scene(variant, key, order, ALLOCATOR);
                let mut engine = texflow::engine::ParticleEngine::new(&ctx, &s, 5).unwrap();
                for _ in 0..30 {
                    engine.advance_frame().unwrap();
                }
                assert!(engine.order_for_drawing().unwrap());
                let positions = engine.sim().read_positions().unwrap();
                let statics = engine.sim().statics().read_f32().unwrap();
                let want = expected(&positions, &statics, key, order);
                let entries = engine.sorter().unwrap().read().unwrap();
                let got: Vec<u32> = entries[..want.len()].iter().map(|e| e[1] as u32).collect();
                let case = format!("{} {key:?} {order:?}", variant.name());
                assert!(want.len() > 60, "{case}: {} live particles", want.len());
                assert_eq!(got, want, "{case}");
                // The ages do spread: the first and last drawn differ in age by a good part of
                // a life, in the direction the key names.
                let age = |i: u32| statics[i as usize * 4 + 2] - positions[i as usize * 4 + 3];
                let (first, last) = (age(got[0]), age(*got.last().unwrap()));
                let top_is_young = key == SortKey::YoungestOnTop;
                let last_on_top = order == DrawOrder::BackToFront;
                let young_last = last < first - 0.2;
                let young_first = first < last - 0.2;
                assert!(
                    if top_is_young == last_on_top {
                        young_last
                    } else {
                        young_first
                    },
                    "{case}: first drawn {first} s old, last {last} s"
                );
            }
        }
    }
    no_gl_error(&ctx);
}

/// Latta's sort spread over frames refreshes the keys in place: by age too. With as many passes
/// per frame as the whole sort has, every frame ends fully sorted by the ages of that frame,
/// starting from the last frame's order (the re-keyed path of the key pass).
#[test]
fn a_sort_spread_over_frames_refreshes_age_keys() {
    let ctx = context();
    let key = SortKey::YoungestOnTop;
    let mut s = scene(Variant::OddEven, key, DrawOrder::BackToFront, ALLOCATOR);
    let passes = texflow::engine::plan::sort_plan(&s).unwrap().passes;
    s.render.sort.passes_per_frame = Some(passes as u32);
    let mut engine = texflow::engine::ParticleEngine::new(&ctx, &s, 5).unwrap();
    for frame in 0..30 {
        engine.advance_frame().unwrap();
        assert!(engine.order_for_drawing().unwrap());
        if frame % 10 != 9 {
            continue;
        }
        let positions = engine.sim().read_positions().unwrap();
        let statics = engine.sim().statics().read_f32().unwrap();
        let want = expected(&positions, &statics, key, DrawOrder::BackToFront);
        let entries = engine.sorter().unwrap().read().unwrap();
        let got: Vec<u32> = entries[..want.len()].iter().map(|e| e[1] as u32).collect();
        assert_eq!(got, want, "frame {frame}");
    }
    no_gl_error(&ctx);
}

/// The CPU engine (E5) sorts by the same key: its drawing order is the CPU ordering of the ages
/// of its own state, for both keys.
#[test]
fn cpu_engine_sorts_by_age() {
    let ctx = context();
    for key in [SortKey::YoungestOnTop, SortKey::OldestOnTop] {
        let s = scene(Variant::OddEven, key, DrawOrder::BackToFront, TIMESTAMP);
        let mut engine = texflow::engine::CpuEngine::new(&ctx, &s, 5).unwrap();
        for _ in 0..40 {
            engine.advance_frame();
        }
        engine.draw().unwrap();
        let flat = |v: &[glam::Vec4]| v.iter().flat_map(|p| p.to_array()).collect::<Vec<f32>>();
        let want = expected(
            &flat(engine.sim().positions()),
            &flat(engine.sim().statics()),
            key,
            DrawOrder::BackToFront,
        );
        assert!(want.len() > 60, "{key:?}: {} live particles", want.len());
        assert_eq!(engine.draw_order(), want, "{key:?}");
    }
    no_gl_error(&ctx);
}

/// The distance stays the default key, and a scene names the keys and variants by word: an
/// unknown one is an error at its line and column with a suggestion; an age key without alpha
/// blending is refused (it would order nothing).
#[test]
fn keys_and_variants_parse_as_words() {
    let base = "name = \"p\"\n[particles]\nsize = [8, 8]\n\
        [[emitters.initial]]\ndirection = [0.0, 1.0, 0.0]\nspeed = [0.0, 0.0]\n";
    let s = scene::parse("p", &format!("{base}[render]\nblending = \"alpha\"\n")).unwrap();
    assert_eq!(s.render.sort.key, SortKey::Distance);
    assert_eq!(s.render.sort.variant, None);
    let plan = common::plan_of(&common::context(), &s).to_string();
    assert!(plan.contains("sort keys: distance to the viewer"), "{plan}");
    assert_eq!(
        texflow::engine::plan::sort_plan(&s).unwrap().variant,
        Variant::OddEven
    );
    let err = |src: String| match scene::parse("p.toml", &src).unwrap_err() {
        texflow::Error::Scene {
            line,
            column,
            message,
            ..
        } => (line, column, message),
        other => panic!("expected a scene error, got {other:?}"),
    };
    let (l, c, m) = err(format!(
        "{base}[render]\nblending = \"alpha\"\n[render.sort]\nvariant = \"oddeveb\"\n"
    ));
    assert_eq!((l, c), (10, 11), "{m}");
    assert!(
        m.contains("unknown variant `oddeveb`") && m.contains("did you mean `oddeven`?"),
        "{m}"
    );
    let (l, _, m) = err(format!(
        "{base}[render]\nblending = \"alpha\"\n[render.sort]\nkey = \"youngest_on_tpo\"\n"
    ));
    assert_eq!(l, 10, "{m}");
    assert!(m.contains("did you mean `youngest_on_top`?"), "{m}");
    let (l, _, m) = err(format!(
        "{base}[render]\n[render.sort]\nkey = \"oldest_on_top\"\n"
    ));
    assert_eq!(l, 9, "{m}");
    assert!(
        m.contains("blending = \"additive\"") && m.contains("set blending = \"alpha\""),
        "{m}"
    );
    let s = scene::parse(
        "p",
        &format!("{base}[render]\nblending = \"alpha\"\nsort = {{ key = \"oldest_on_top\" }}\n"),
    )
    .unwrap();
    let plan = common::plan_of(&common::context(), &s).to_string();
    assert!(plan.contains("sort keys: age, the oldest on top"), "{plan}");
}
