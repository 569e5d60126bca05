//! The pass list is what runs: for every built-in scene, the programs one frame draws (recorded
//! by the GL layer, `texflow::gl::DrawRecorder`) are those of the passes its engine lists
//! (`texflow scene passes`), each as many times as listed: the steps' passes times the substeps,
//! the sort's network passes as its schedule has them. A pass whose draws depend on the data
//! (births, half-angle slices over the live particles) draws at most as many, and at least once.

mod common;

use texflow::engine::{build, plan::Plan};
use texflow::EngineKind;

/// The programs `drawn` by count, in the order of their first draw.
fn counts(drawn: &[String]) -> Vec<(String, u64)> {
    let mut out: Vec<(String, u64)> = Vec::new();
    for d in drawn {
        match out.iter_mut().find(|(n, _)| n == d) {
            Some((_, c)) => *c += 1,
            None => out.push((d.clone(), 1)),
        }
    }
    out
}

/// What differs between the listed draws of `plan` and the `drawn` programs of one frame.
fn mismatches(plan: &Plan, drawn: &[String]) -> Vec<String> {
    let listed = plan.frame_draws();
    let drawn = counts(drawn);
    let mut out = Vec::new();
    for (program, n) in &drawn {
        match listed.iter().find(|(p, ..)| p == program) {
            None => out.push(format!("{program}: drawn {n} times, listed in no pass")),
            Some((_, m, true)) if n > m => {
                out.push(format!("{program}: drawn {n} times, listed at most {m}"))
            }
            Some((_, m, false)) if n != m => {
                out.push(format!("{program}: drawn {n} times, listed {m}"))
            }
            Some(_) => {}
        }
    }
    for (program, m, _) in &listed {
        if *m > 0 && !drawn.iter().any(|(p, _)| p == program) {
            out.push(format!("{program}: listed {m} times, never drawn"));
        }
    }
    out
}

/// The mismatches of one frame of `scene` (at 16×16 particles) on a `kind` engine.
fn frame_mismatches(
    ctx: &texflow::gl::Context,
    mut s: texflow::scene::SceneFile,
    kind: EngineKind,
) -> Vec<String> {
    let name = s.name.clone();
    s.particles.size = [16, 16];
    s.render.resolution = [32, 32];
    let mut e = build(ctx, &s, 1, kind).unwrap_or_else(|e| panic!("{name}: {e}"));
    // A first frame, so that the recorded one is an ordinary frame (births under way).
    e.advance_frame().unwrap();
    e.render().unwrap();
    let recorder = texflow::gl::DrawRecorder::start();
    e.advance_frame().unwrap();
    e.draw().unwrap();
    let drawn = recorder.finish();
    let plan = e.plan();
    assert_eq!(plan.passes, e.passes(), "{name}");
    (mismatches(&plan, &drawn).into_iter())
        .map(|m| format!("{name}: {m}"))
        .collect()
}

#[test]
fn every_built_in_scene_draws_the_passes_it_lists() {
    let ctx = common::context();
    let mut failures = Vec::new();
    for name in texflow::scene::BUILTIN {
        let s = texflow::scene::load(name).unwrap();
        failures.extend(frame_mismatches(&ctx, s, EngineKind::Gpu));
    }
    common::no_gl_error(&ctx);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The passes the built-in scenes do not run: every sort variant, a sort spread over frames,
/// the index lookup, separate and stateless updates, Jacobi relaxation, the vertex-buffer path,
/// user states, forces and ribbons of the example scenes, and the CPU engine.
#[test]
fn variants_draw_the_passes_they_list() {
    use texflow::scene::{self, Lookup, RelaxScheme, RenderPath, StateModel, UpdatePasses};
    use texflow::sort::Variant;
    let ctx = common::context();
    let load = |n: &str| scene::load(n).unwrap();
    let mut cases: Vec<(scene::SceneFile, EngineKind)> = Vec::new();
    for v in [
        Variant::Fp,
        Variant::GpFp,
        Variant::Packed,
        Variant::Multistep,
        Variant::Blocked,
    ] {
        let mut s = load("smoke-unlit");
        s.render.sort.variant = Some(v);
        cases.push((s, EngineKind::Gpu));
    }
    let mut s = load("smoke-unlit");
    s.render.sort.passes_per_frame = Some(5);
    cases.push((s, EngineKind::Gpu));
    let mut s = load("smoke-unlit");
    s.render.lookup = Lookup::Index;
    cases.push((s, EngineKind::Gpu));
    let mut s = load("e1");
    s.passes = UpdatePasses::Separate;
    cases.push((s, EngineKind::Gpu));
    let (_, src) = scene::load_source("e1").unwrap();
    let src = src.replace("integrator = \"uberflow\"", "simulation = \"stateless\"");
    let s = scene::parse("stateless e1", &src).unwrap();
    assert_eq!(s.simulation, StateModel::Stateless);
    cases.push((s, EngineKind::Gpu));
    let mut s = load("cloth");
    s.constraints.as_mut().unwrap().scheme = RelaxScheme::Jacobi;
    cases.push((s, EngineKind::Gpu));
    let mut s = load("fountain");
    s.render.path = RenderPath::VertexBuffer;
    cases.push((s, EngineKind::Gpu));
    for file in [
        "examples/boids/boids.toml",
        "examples/heat/heat.toml",
        "examples/heat-fluid/heat_fluid.toml",
        "examples/ribbons/ribbons.toml",
        "examples/terrain/terrain.toml",
    ] {
        cases.push((load(file), EngineKind::Gpu));
    }
    // A state updated inside the integration pass: no pass of its own.
    let mut s = load("examples/heat/heat.toml");
    s.state[0].pass = scene::StatePassKind::Integrate;
    cases.push((s, EngineKind::Gpu));
    // E4's rows-only collision sorts on 4-byte exact entries (cell key and column).
    let e4 = texflow::bench::scenes::e4::scene(16).unwrap();
    let lines = texflow::sim::particles::Features::of(&e4).step_passes();
    let compact = lines
        .iter()
        .filter(|p| p.name.contains("4-byte exact entries"));
    assert_eq!(
        compact.count(),
        2,
        "both lattices' sorts name their entries"
    );
    cases.push((e4, EngineKind::Gpu));
    cases.extend(trimmed_walks());
    cases.push((load("e1"), EngineKind::Cpu));
    cases.push((load("e3"), EngineKind::Cpu));
    let mut failures = Vec::new();
    for (s, kind) in cases {
        failures.extend(frame_mismatches(&ctx, s, kind));
    }
    // The cell-start table of the exact searches, which the built-in scenes' lattices are too
    // large for at 16×16: the neighbour forces, the exact iterations (with spin), the fluid.
    for name in ["dem", "spin", "dam"] {
        let s = load(name);
        let run = || frame_mismatches(&ctx, s, EngineKind::Gpu);
        failures.extend(texflow::sim::collide::cells::with_search(true, run));
    }
    common::no_gl_error(&ctx);
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The exact detection's trimmed walk (a cell below 2 radius), with impulses and with the DEM
/// force: each lists the walk it draws.
fn trimmed_walks() -> Vec<(texflow::scene::SceneFile, EngineKind)> {
    use texflow::scene;
    let mut cases = Vec::new();
    for (name, extra) in [("gas", "detection = \"exact\""), ("dem", "")] {
        let (_, src) = scene::load_source(name).unwrap();
        let src = (src.replace("cell = 0.064\n", "")).replace(
            "[collisions]\n",
            &format!("[collisions]\n{extra}\ncell = 0.012\n"),
        );
        let s = scene::parse(name, &src).unwrap();
        let lines = texflow::sim::particles::Features::of(&s).step_passes();
        assert!(
            lines
                .iter()
                .any(|p| p.name.contains("the cells within 2r of each particle")),
            "{name}: {lines:?}"
        );
        cases.push((s, EngineKind::Gpu));
    }
    cases
}

/// The comparison fails both ways: a program drawn but not listed, and a pass listed but not
/// drawn (here with a plan whose list lost one pass, and one that gained a pass).
#[test]
fn a_pass_drawn_but_not_listed_or_listed_but_not_drawn_fails() {
    let ctx = common::context();
    let mut s = texflow::scene::load("smoke-unlit").unwrap();
    s.particles.size = [16, 16];
    s.render.resolution = [32, 32];
    let mut e = build(&ctx, &s, 1, EngineKind::Gpu).unwrap();
    e.advance_frame().unwrap();
    let recorder = texflow::gl::DrawRecorder::start();
    e.advance_frame().unwrap();
    e.draw().unwrap();
    let drawn = recorder.finish();
    let plan = e.plan();
    assert!(
        mismatches(&plan, &drawn).is_empty(),
        "{:?}",
        mismatches(&plan, &drawn)
    );
    let mut fewer = plan.clone();
    let integrate = fewer
        .passes
        .iter()
        .position(|p| p.stage == "integrate")
        .unwrap();
    fewer.passes.remove(integrate);
    assert!(mismatches(&fewer, &drawn)
        .iter()
        .any(|m| m.contains("sim/integrate.frag") && m.contains("listed in no pass")));
    let mut more = plan.clone();
    more.passes.push(
        texflow::gl::PassInfo::new("render", "composite background under").draws(
            &texflow::gl::Program::new(
                &ctx,
                texflow::gl::FULLSCREEN_VERTEX,
                "render/background.frag",
                &Vec::new(),
            )
            .unwrap(),
            1,
        ),
    );
    assert!(mismatches(&more, &drawn)
        .iter()
        .any(|m| m.contains("background.frag") && m.contains("never drawn")));
    // A sort pass fewer than the schedule has is a count that differs.
    let mut short = plan.clone();
    let sort = short
        .passes
        .iter_mut()
        .find(|p| p.name.starts_with("sort:"))
        .unwrap();
    sort.draws[0].1 -= 1;
    assert!(mismatches(&short, &drawn)
        .iter()
        .any(|m| m.contains("sort/") && m.contains("listed")));
    common::no_gl_error(&ctx);
}
