//! Latta §3.4.4's index lookup (`render.lookup = "index"`): drawing through the sorted (key, id)
//! texture in the vertex stage gives the same frame, byte for byte, as drawing the state the
//! gather copied into sorted order (the reference), for every sort layout the lookup decodes.

mod common;

use common::{context, no_gl_error};
use texflow::scene::{self, DrawPrimitive, Lookup, Precision, SceneFile, Variant};

/// Frames 6 and 12 of `s` drawn with `lookup`.
fn frames(s: &SceneFile, lookup: Lookup) -> Vec<image::RgbImage> {
    let ctx = context();
    let mut s = s.clone();
    s.render.lookup = lookup;
    let mut e = texflow::ParticleEngine::new(&ctx, &s, 3).unwrap();
    let mut out = Vec::new();
    for frame in 1..=12 {
        e.advance_frame().unwrap();
        if frame % 6 == 0 {
            out.push(e.render().unwrap());
        } else {
            e.order_for_drawing().unwrap();
        }
    }
    assert_eq!(e.sorted().is_some(), lookup == Lookup::Gather);
    no_gl_error(&ctx);
    out
}

fn small(name: &str) -> SceneFile {
    let mut s = scene::load(name).unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [48, 48];
    s
}

/// Every layout the lookup decodes (plain, packed, the 24-bit identifier table, the blocked
/// sort's), spread over frames, front to back, and sprites as quads: the same bytes.
#[test]
fn index_lookup_draws_the_gathered_frame() {
    let mut cases = Vec::new();
    cases.push(("smoke-unlit oddeven", small("smoke-unlit")));
    let mut s = small("smoke-unlit");
    s.render.sort.variant = Some(Variant::Packed);
    cases.push(("smoke packed", s));
    let mut s = small("smoke-unlit");
    s.particles.precision = Precision::Fp24;
    s.render.sort.variant = Some(Variant::Fp);
    cases.push(("smoke fp24 id table", s));
    let mut s = small("smoke-unlit");
    s.render.sort.passes_per_frame = Some(3);
    cases.push(("smoke spread", s));
    let mut s = small("smoke-unlit");
    s.render.sort.variant = Some(Variant::Blocked);
    s.render.primitive = DrawPrimitive::Quads;
    cases.push(("smoke blocked quads", s));
    cases.push(("e3 front to back", small("e3")));
    for (what, s) in &cases {
        let gathered = frames(s, Lookup::Gather);
        let looked_up = frames(s, Lookup::Index);
        for (k, (g, l)) in gathered.iter().zip(&looked_up).enumerate() {
            let lit = g.pixels().filter(|p| p.0 != [0, 0, 0]).count();
            assert!(
                lit > 0,
                "{what}: frame {k} draws nothing, so it shows nothing"
            );
            assert!(
                g == l,
                "{what}: frame {k} differs between gather and index lookup"
            );
        }
    }
}

/// Without a sort there is no index to draw through: refused at the key.
#[test]
fn index_lookup_needs_alpha_blending() {
    let fountain = include_str!("../examples/scenes/fountain.toml");
    assert!(
        !fountain.contains("\"alpha\""),
        "the fountain blends additively"
    );
    let text = fountain.replace("[render]\n", "[render]\nlookup = \"index\"\n");
    let err = scene::parse("lookup.toml", &text).unwrap_err().to_string();
    assert!(
        err.contains("lookup.toml:") && err.contains("blending = \"alpha\""),
        "{err}"
    );
}

/// `bench scene` with the index lookup: the sort's key pass and network are timed, no gather
/// phase (there is none), and the render phase says it draws through the index.
#[test]
fn bench_scene_times_the_lookup_without_a_gather() {
    let ctx = context();
    let mut s = scene::load("smoke-unlit").unwrap();
    s.render.lookup = Lookup::Index;
    let opts = texflow::bench::SceneBenchOptions {
        repeats: 2,
        warmup_frames: Some(3),
        resolution: Some([32, 32]),
        ..Default::default()
    };
    let r = texflow::bench::bench_scene(&ctx, &s, &[16], &opts, |_| ()).unwrap();
    let names: Vec<&str> = r[0].phases.iter().map(|p| p.phase.as_str()).collect();
    assert!(
        names.iter().any(|p| p.starts_with("sort network")),
        "{names:?}"
    );
    assert!(!names.iter().any(|p| p.starts_with("gather")), "{names:?}");
    assert!(
        names
            .iter()
            .any(|p| p.starts_with("render") && p.contains("sort's index")),
        "{names:?}"
    );
    no_gl_error(&ctx);
}

/// An accepted index lookup still goes through the checks of the keys after it: soft
/// particles without geometry and a local spread without a spread sort are refused at their
/// place, not at the first frame.
#[test]
fn index_lookup_does_not_skip_the_later_render_checks() {
    let base = scene::builtin_source("smoke-unlit").unwrap();
    let lookup = base.replace("[render]\n", "[render]\nlookup = \"index\"\n");
    assert_ne!(lookup, base, "the scene has a [render] line");
    for (src, key) in [
        (
            lookup.replace("[render]\n", "[render]\nsoft = 0.1\n"),
            "soft",
        ),
        (
            lookup.replace("[render.sort]\n", "[render.sort]\nspread = \"local\"\n"),
            "spread",
        ),
    ] {
        let e = scene::parse("lookup.toml", &src).unwrap_err().to_string();
        assert!(e.contains("lookup.toml:") && e.contains(key), "{e}");
    }
}
