//! `bench scene`'s floors bound their phases by construction: for every built-in scene at two
//! small sizes (the larger leaves most of a sparse scene's state dead), each floor that is a drawn pass draws no more than its phase drew in the same
//! repetition (draws, vertices, bytes into colour attachments, and for the render pass the
//! fragments a samples query counted). Times are not compared: that part of a floor's claim is
//! the benchmark's to report (⚠ under 0.95), not a test's.
//!
//! Every phase that is not a render pass (or a lit render's passes apart) has the fetch floor beside its first floor, built from
//! its own draws: it draws no more (draws, vertices, bytes). That it fetches no more is not
//! measured (the GL layer counts no fetches); it fetches once per bound texture and fragment by
//! construction (`glsl/bench/fetch_floor.frag`).

mod common;

use texflow::bench::scene::Drawn;
use texflow::bench::{bench_scene, SceneBenchOptions};

/// Whether `floor` draws no more than `phase`, and what is over.
fn over(floor: &Drawn, phase: &Drawn) -> Vec<String> {
    let (f, p) = (floor.stats, phase.stats);
    let mut bad = Vec::new();
    for (what, a, b) in [
        ("draws", f.draws, p.draws),
        ("vertices", f.vertices, p.vertices),
        ("bytes", f.bytes_written, p.bytes_written),
    ] {
        if a > b {
            bad.push(format!("{what} {a} > {b}"));
        }
    }
    if let (Some(a), Some(b)) = (floor.fragments, phase.fragments) {
        if a > b {
            bad.push(format!("fragments {a} > {b}"));
        }
    }
    bad
}

/// Every phase but the render passes has the fetch floor: one full-screen pass for each of the
/// phase's, into the same targets and viewports (the same bytes); a neighbour search (DEM, the
/// fluid) is floored with its walk. Whether it drew, and the draws that walked.
fn fetch_floor(name: &str, p: &texflow::bench::scene::PhaseRecord, phase: &Drawn) -> (usize, u64) {
    let fetch = p.bounds.iter().find(|b| b.floor.starts_with("fetch floor"));
    // A lit render's passes timed apart are render passes too.
    let render = ["render", "light-buffer passes", "eye passes"];
    if render.iter().any(|r| p.phase.starts_with(r)) {
        assert!(fetch.is_none(), "{name}: {}", p.phase);
        return (0, 0);
    }
    let fetch = fetch.unwrap_or_else(|| panic!("{name}: `{}` no fetch floor", p.phase));
    let d = fetch.drawn.expect("the fetch floor is drawn");
    let (f, s) = (d.stats, phase.stats);
    assert_eq!(
        (f.draws, f.passes, f.bytes_written),
        (s.passes, s.passes, s.bytes_written),
        "{name}: `{}`: the fetch floor's draws, passes, bytes",
        p.phase
    );
    let walker = ["dem", "dam", "drop"].contains(&name) && p.phase.starts_with("collide");
    assert!(
        !walker || d.walked > 0,
        "{name}: `{}`: no floor walked the cells",
        p.phase
    );
    ((f.draws > 0) as usize, d.walked)
}

#[test]
fn every_drawn_floor_draws_no_more_than_its_phase() {
    let ctx = common::context();
    let opts = SceneBenchOptions {
        repeats: 1,
        warmup_frames: Some(4),
        resolution: Some([48, 32]),
        ..Default::default()
    };
    let mut checked = 0;
    let mut render_fragments = 0;
    let mut fills = 0;
    let mut fetch_drawn = 0;
    let mut walked = 0;
    for name in texflow::scene::BUILTIN {
        let scene = texflow::scene::load(name).unwrap();
        let records = bench_scene(&ctx, &scene, &[16, 64], &opts, |_| {}).unwrap();
        let fetch_before = fetch_drawn;
        for p in records.iter().flat_map(|r| &r.phases) {
            assert!(!p.bounds.is_empty(), "{name}: {p:?}");
            // The phase is reported against the larger bound.
            let top = p.bounds.iter().map(|b| b.ms).fold(f64::MIN, f64::max);
            assert_eq!(p.floor_ms, top, "{name}: {}", p.phase);
            // A render that depth-tests its particles against geometry drops those behind it:
            // its placed points, drawn without the geometry, write nothing.
            if scene.render.geometry && p.phase.starts_with("render") {
                assert!(
                    p.bounds[0].floor.contains("writing nothing"),
                    "{name}: `{}` placed points write behind the geometry",
                    p.phase
                );
            }
            let Some(phase) = &p.drawn else { continue };
            for b in &p.bounds {
                let Some(floor) = &b.drawn else { continue };
                let bad = over(floor, phase);
                assert!(
                    bad.is_empty(),
                    "{name}: `{}` floor `{}` draws more than the phase: {}",
                    p.phase,
                    b.floor,
                    bad.join(", ")
                );
                checked += 1;
                if floor.fragments.is_some_and(|f| f > 0) {
                    render_fragments += 1;
                }
            }
            let (drawn, w) = fetch_floor(name, p, phase);
            fetch_drawn += drawn;
            walked += w;
            // Points and sprites drawn without geometry have the fill floor beside the placed
            // points.
            fills += p
                .bounds
                .iter()
                .filter(|b| b.floor.starts_with("fill floor"))
                .count();
        }
        // Every scene steps its state in full-screen passes: one fetch floor at least drew.
        assert!(fetch_drawn > fetch_before, "{name}: no fetch floor drawn");
    }
    // Not vacuous: floors were compared, render floors with fragments among them.
    eprintln!(
        "{checked} floors compared, {render_fragments} with fragments, {fills} fill floors, \
         {fetch_drawn} fetch floors drawn"
    );
    assert!(checked >= 2 * texflow::scene::BUILTIN.len(), "{checked}");
    assert!(render_fragments > 0);
    assert!(walked > 0);
    assert!(fills >= 4, "{fills} fill floors");
    common::no_gl_error(&ctx);
}

/// Built-in `name` at 32² into a 48×32 frame, and its engine (seed 1).
fn small_engine(
    ctx: &texflow::gl::Context,
    name: &str,
) -> (texflow::scene::SceneFile, Box<dyn texflow::engine::Stages>) {
    let mut scene = texflow::scene::load(name).unwrap();
    scene.particles.size = [32, 32];
    scene.render.resolution = [48, 32];
    let e = texflow::engine::build_gpu(ctx, &scene, 1).unwrap();
    (scene, e)
}

/// The fill floor and the shading floor draw the pass's fragments and change no pixel: after
/// each the frame is as the clear left it, for every built-in that draws particles alone, while
/// the pass itself draws something. (A GPU that skips blends changing nothing skips every one of the floor's, so the
/// floor is the least any pass of these fragments costs.) Where the pass draws the colliders'
/// geometry or a connected surface (opaque, depth written), the floor draws them too: it passes
/// the depth test with every fragment the pass writes (the same samples; the pass's fragment
/// stage may discard more, never fewer), and a surface's floor with exactly as many; the
/// shading floor, the pass's own fragment stage, with exactly as many.
#[test]
fn the_fill_floor_changes_no_pixel() {
    let ctx = common::context();
    let (mut checked, mut surfaces) = (Vec::new(), Vec::new());
    let mut shaded = 0;
    for name in texflow::scene::BUILTIN {
        let (scene, mut e) = small_engine(&ctx, name);
        if e.lit().is_some() {
            continue;
        }
        let fill = e.renderer().with_fragment("bench/fill_floor.frag").unwrap();
        for _ in 0..6 {
            e.advance_frame().unwrap();
        }
        if scene.render.geometry || e.renderer().draws_connected() {
            let samples = texflow::gl::SamplesQuery::new(&ctx).unwrap();
            let count = |floor: bool| {
                e.renderer().clear(e.target());
                let (r, n) = (samples.count(|| match floor {
                    true => e.render_pass_with(&fill, false),
                    false => e.render_pass(false),
                }))
                .unwrap();
                r.unwrap();
                n
            };
            let (floor, pass) = (count(true), count(false));
            assert!(
                pass > 0 && pass <= floor,
                "{name}: floor {floor}, pass {pass} samples"
            );
            // The shading floor is the pass's own fragment stage: the same samples.
            if let Some(shade) = e.renderer().shading_floor().unwrap() {
                e.renderer().clear(e.target());
                let (r, n) = samples.count(|| e.render_pass_with(&shade, false)).unwrap();
                r.unwrap();
                assert_eq!(n, pass, "{name}: the shading floor's samples");
                shaded += 1;
            }
            if e.renderer().draws_connected() {
                assert_eq!(floor, pass, "{name}");
            }
            surfaces.push(name);
            continue;
        }
        e.renderer().clear(e.target());
        let clear = e.target().read_rgb().unwrap();
        e.render_pass_with(&fill, false).unwrap();
        assert!(
            e.target().read_rgb().unwrap() == clear,
            "{name}: the fill floor drew"
        );
        let shade = e.renderer().shading_floor().unwrap();
        let shade = shade.expect("points and sprites have a shading floor");
        e.render_pass_with(&shade, false).unwrap();
        assert!(
            e.target().read_rgb().unwrap() == clear,
            "{name}: the shading floor drew"
        );
        shaded += 1;
        e.render_pass(false).unwrap();
        assert!(
            e.target().read_rgb().unwrap() != clear,
            "{name}: nothing drawn"
        );
        checked.push(name);
    }
    assert!(shaded >= 12, "{shaded} shading floors");
    assert!(checked.len() >= 8, "{checked:?}");
    // cloth and hair (surfaces); snow, fountain, mesh, collide (geometry).
    assert!(surfaces.len() >= 6, "{surfaces:?}");
    common::no_gl_error(&ctx);
}

/// A lit render's fill floor (the same slices with a constant fragment) and its shading floor
/// (the slices' own passes, their colours made zero) change no pixel of the frame and no texel
/// of their light buffers: after them the frame is what the slices' clear and background
/// composite alone leave (the slices of no particle), while the render's own slices draw
/// something.
#[test]
fn the_lit_floors_change_no_pixel() {
    use texflow::render::{FrameState, SlicePasses};
    use texflow::sim::state::{POSITION, STATIC};
    let ctx = common::context();
    let mut lit_scenes = 0;
    for name in texflow::scene::BUILTIN {
        let (_, mut e) = small_engine(&ctx, name);
        let Some(fill) = e
            .lit()
            .map(|l| l.with_fragment("bench/fill_floor.frag").unwrap())
        else {
            continue;
        };
        for _ in 0..6 {
            e.advance_frame().unwrap();
        }
        e.draw().unwrap();
        let (lit, sorted) = (e.lit().unwrap(), e.sorted().unwrap());
        let state = |count| FrameState {
            positions: sorted.texture(POSITION),
            statics: sorted.texture(STATIC),
            motion: None,
            time: e.sim().time() as f32,
            spins: None,
            count,
            user: &[],
        };
        let count = e.sim().drawn().count;
        let (target, camera, atlas) = (e.target(), e.camera(), e.renderer().atlas());
        let draw = |r: &texflow::render::HalfAngleRenderer, count, atlas| {
            r.draw_passes(target, &state(count), camera, atlas, SlicePasses::Both)
                .unwrap();
            target.read_rgb().unwrap()
        };
        let empty = draw(&fill, 0, None);
        // The shading floor: every fetch and computation of the slices, their colours made
        // ones that their blends leave unchanged, the frame and its own light buffer alike.
        let shade = lit.shading_floor().unwrap();
        for (floor, atlas, what) in [(&fill, None, "fill"), (&shade, atlas, "shading")] {
            // Compared whole, not printed: a frame is thousands of bytes.
            assert!(
                draw(floor, count, atlas) == empty,
                "{name}: the {what} floor drew"
            );
            let light = floor.light_buffer().only_texture().read_f32().unwrap();
            assert!(
                light.iter().all(|&t| t == 1.0),
                "{name}: the {what} floor's light passes dimmed the light buffer"
            );
        }
        assert!(draw(lit, count, atlas) != empty, "{name}: nothing drawn");
        lit_scenes += 1;
    }
    assert!(lit_scenes >= 1, "no lit built-in");
    common::no_gl_error(&ctx);
}
