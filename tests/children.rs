//! Emitters that emit (the thesis §2, `[[emitters.child]]`): child texels born in the integration
//! pass from their parent texels, against CPU twins worked out here from the scene's numbers and
//! the parents' initial state: the discrete closed form of Latta's Euler step for the parents'
//! last positions, and an integer-step model of the trail's asks, lives and dropped births.

mod common;

use common::{context, no_gl_error};
use texflow::scene;
use texflow::sim::ParticleSim;

fn parse(src: &str) -> scene::SceneFile {
    scene::parse("children.toml", src).unwrap_or_else(|e| panic!("{e}\n{src}"))
}

const SIDE: usize = 16;

/// P parents of one fixed life under gravity, each bursting into B children when it dies.
fn burst_scene(b: u32, life_steps: u32) -> String {
    format!(
        "name = \"burst\"\nintegrator = \"euler\"\n[particles]\nsize = [{SIDE}, {SIDE}]\n\
         [time]\ndt = 0.015625\n\
         [[emitters.initial]]\nshape = \"box\"\nsize = [2.0, 1.0, 2.0]\ndirection = [0.0, 1.0, 0.0]\n\
         cone_degrees = 30.0\nspeed = [2.0, 4.0]\nlife = [{l}, {l}]\n\
         [[emitters.child]]\nparent = 0\nper_parent = {b}\non_death = {b}\nshape = \"sphere\"\n\
         radius = 0.05\ndirection = [0.0, 1.0, 0.0]\ncone_degrees = 180.0\nspeed = [0.5, 0.5]\n\
         inherit_velocity = 1.0\nlife = [5.0, 5.0]\n\
         [[forces.gravity]]\nacceleration = [0.0, -9.81, 0.0]\n",
        l = life_steps as f64 * 0.015625
    )
}

fn live(pos: &[f32], range: std::ops::Range<usize>) -> usize {
    pos.chunks_exact(4)
        .skip(range.start)
        .take(range.len())
        .filter(|p| p[3] > 0.0)
        .count()
}

/// After the parents die, exactly P·B children live, none before; each was born within the
/// spread (radius 0.05) of its own parent's last position, with its parent's velocity plus 0.5
/// m/s, both from the discrete closed form of Euler's step: after n steps v_n = v0 + n a dt and
/// x_n = x0 + n v0 dt + a dt² n(n+1)/2.
#[test]
fn death_bursts_give_p_times_b_children_at_their_parents_last_positions() {
    let ctx = context();
    let b = 5u32;
    let life_steps = 24u32;
    let s = parse(&burst_scene(b, life_steps));
    let layout = s.child_layout();
    let p = layout.parent_slots as usize;
    assert_eq!(p, SIDE * SIDE / (1 + b as usize), "P = ⌊N / (1 + K)⌋");
    let mut sim = ParticleSim::new(&ctx, &s, 3).unwrap();
    let x0 = sim.read_positions().unwrap();
    let v0 = sim.read_velocities().unwrap();
    let children = p..p + p * b as usize;
    let (dt, g) = (0.015625f64, -9.81f64);
    // The parents' lives count down by dt, exactly (dt and the life are binary fractions): a
    // parent alive at the start of step n dies in it when n = life_steps - 1.
    let death = life_steps as usize - 1;
    for step in 0..death {
        sim.step().unwrap();
        let pos = sim.read_positions().unwrap();
        assert_eq!(live(&pos, 0..p), p, "parents alive after step {step}");
        assert_eq!(
            live(&pos, children.clone()),
            0,
            "no births while parents live"
        );
    }
    sim.step().unwrap();
    let pos = sim.read_positions().unwrap();
    let vel = sim.read_velocities().unwrap();
    assert_eq!(live(&pos, 0..p), 0, "every parent died in step {death}");
    assert_eq!(live(&pos, children.clone()), p * b as usize, "P·B children");
    let n = death as f64;
    let mut worst = 0.0f64;
    for parent in 0..p {
        let last: [f64; 3] = std::array::from_fn(|a| {
            let a_acc = if a == 1 { g } else { 0.0 };
            x0[parent * 4 + a] as f64
                + n * v0[parent * 4 + a] as f64 * dt
                + a_acc * dt * dt * n * (n + 1.0) / 2.0
        });
        let last_v: [f64; 3] = std::array::from_fn(|a| {
            v0[parent * 4 + a] as f64 + if a == 1 { n * g * dt } else { 0.0 }
        });
        for j in 0..b as usize {
            let c = p + parent * b as usize + j;
            let d = (0..3)
                .map(|a| (pos[c * 4 + a] as f64 - last[a]).powi(2))
                .sum::<f64>()
                .sqrt();
            let dv = (0..3)
                .map(|a| (vel[c * 4 + a] as f64 - last_v[a]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(d <= 0.05 + 1e-4, "child {c} of parent {parent}: {d} m away");
            assert!((dv - 0.5).abs() < 1e-3, "child {c}: spread speed {dv}");
            worst = worst.max(d);
        }
    }
    assert!(
        worst > 0.01,
        "the children are spread, not stacked: {worst}"
    );
    assert_eq!(sim.dropped_child_births().unwrap(), 0);
    // The texels past the layout stay dead, as do the parents; the children live on.
    for _ in 0..5 {
        sim.step().unwrap();
    }
    let pos = sim.read_positions().unwrap();
    assert_eq!(live(&pos, children.clone()), p * b as usize);
    assert_eq!(live(&pos, children.end..SIDE * SIDE), 0);
    no_gl_error(&ctx);
}

/// Stationary permanent parents with a trail of `rate` per second over `k` texels of children
/// that live `life_steps` steps.
fn trail_scene(k: u32, rate: f64, life_steps: u32) -> String {
    format!(
        "name = \"trail\"\nintegrator = \"euler\"\n[particles]\nsize = [{SIDE}, {SIDE}]\n\
         [time]\ndt = 0.015625\n\
         [[emitters.initial]]\nshape = \"box\"\nsize = [2.0, 2.0, 2.0]\ndirection = [0.0, 1.0, 0.0]\n\
         speed = [0.0, 0.0]\n\
         [[emitters.child]]\nper_parent = {k}\ntrail_rate = {rate:?}\ndirection = [0.0, 1.0, 0.0]\n\
         speed = [1.0, 1.0]\nlife = [{l}, {l}]\n",
        l = life_steps as f64 * 0.015625
    )
}

/// The twin of the trail: birth n of a parent is asked at the step whose age interval
/// (s dt, (s + 1) dt] holds n / rate, of texel n mod k; a texel whose child still lives after
/// that step (more than one step of life left) drops it, else the child is born with
/// `life_steps` steps and loses one per step, dying when none would be left. Returns the live
/// children of one parent after every step, and the drops.
fn trail_twin(k: usize, per_step: f64, life_steps: u32, steps: usize) -> (Vec<usize>, u64) {
    let mut remaining = vec![0u32; k];
    let mut drops = 0;
    let mut live = Vec::new();
    for s in 0..steps {
        let (n0, n1) = (
            (s as f64 * per_step).floor() as i64,
            ((s + 1) as f64 * per_step).floor() as i64,
        );
        let mut asked = vec![0u32; k];
        for n in n0 + 1..=n1 {
            asked[n as usize % k] += 1;
        }
        for j in 0..k {
            let occupied = remaining[j] > 1;
            if asked[j] > 0 {
                drops += (asked[j] - if occupied { 0 } else { 1 }) as u64;
                if !occupied {
                    remaining[j] = life_steps;
                    continue;
                }
            }
            remaining[j] = remaining[j].saturating_sub(1);
        }
        live.push(remaining.iter().filter(|r| **r > 0).count());
    }
    (live, drops)
}

/// Trails against the twin, step by step: live children per parent, born at their parent's
/// position, and the exact count of births dropped for want of a free texel (none when each
/// texel's child dies before its next turn; 2 per parent per turn-around otherwise).
#[test]
fn trails_follow_the_rate_and_dropped_births_are_counted_exactly() {
    let ctx = context();
    // rate 8/s at dt 1/64: a birth every 8 steps; texel j's turn comes every 8 k steps.
    for (k, life_steps) in [(3u32, 40u32), (4, 20)] {
        let s = parse(&trail_scene(k, 8.0, life_steps));
        let p = s.child_layout().parent_slots as usize;
        let mut sim = ParticleSim::new(&ctx, &s, 9).unwrap();
        let parents = sim.read_positions().unwrap();
        let steps = 100;
        let (want, drops) = trail_twin(k as usize, 8.0 / 64.0, life_steps, steps);
        for (step, want) in want.iter().enumerate() {
            sim.step().unwrap();
            let pos = sim.read_positions().unwrap();
            for parent in [0, p / 2, p - 1] {
                let block = p + parent * k as usize..p + (parent + 1) * k as usize;
                assert_eq!(
                    live(&pos, block.clone()),
                    *want,
                    "k {k}, life {life_steps}: parent {parent} after step {step}"
                );
            }
            assert_eq!(live(&pos, p..p + p * k as usize), p * want);
            // A child born in this step sits on its parent (a point emitter, no offset).
            if step % 8 == 7 {
                let j = ((step + 1) / 8) % k as usize;
                for parent in [0, p - 1] {
                    let c = p + parent * k as usize + j;
                    if pos[c * 4 + 3] == (life_steps as f32) * 0.015625 {
                        assert_eq!(&pos[c * 4..c * 4 + 3], &parents[parent * 4..parent * 4 + 3]);
                    }
                }
            }
        }
        let total = drops * p as u64;
        assert_eq!(sim.dropped_child_births().unwrap(), total, "k {k}");
        if life_steps < 8 * k {
            assert_eq!(total, 0);
        } else {
            assert!(total > 0);
        }
    }
    no_gl_error(&ctx);
}

/// Bad child emitters are refused with the key and the fix.
#[test]
fn child_emitters_that_cannot_work_are_refused() {
    let ok = trail_scene(4, 8.0, 20);
    for (change, key, says) in [
        ("per_parent = 4", "per_parent = 0", "needs per_parent"),
        (
            "trail_rate = 8.0",
            "trail_rate = 8.0\non_death = 9",
            "raise per_parent to at least 9",
        ),
        (
            "trail_rate = 8.0",
            "parent = 3\ntrail_rate = 8.0",
            "parent 3 is not an emitter",
        ),
        ("trail_rate = 8.0", "trail_rate = 0.0", "never emits"),
        (
            "integrator = \"euler\"",
            "integrator = \"verlet\"",
            "Verlet keeps no velocity",
        ),
    ] {
        let src = ok.replacen(change, key, 1);
        assert_ne!(src, ok, "{change}");
        let e = scene::parse("children.toml", &src)
            .expect_err(key)
            .to_string();
        assert!(e.contains(says), "{key}: {e}");
    }
    let no_parent = "name = \"x\"\n[particles]\nsize = [8, 8]\n[[emitters.child]]\nper_parent = 2\non_death = 2\n\
                     direction = [0.0, 1.0, 0.0]\nspeed = [1.0, 1.0]\nlife = [1.0, 1.0]\n";
    let e = scene::parse("x.toml", no_parent)
        .expect_err("no parent")
        .to_string();
    assert!(e.contains("needs a parent"), "{e}");
}

/// `render` warns once, at the end, about the child births dropped, and counts them in its
/// line and in `--json`: the twin's count for the run's steps, for every parent.
#[test]
fn render_warns_once_and_counts_dropped_child_births_in_json() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("trail.toml");
    std::fs::write(&path, trail_scene(3, 8.0, 40)).unwrap();
    let s = parse(&trail_scene(3, 8.0, 40));
    let p = s.child_layout().parent_slots as u64;
    let frames = 60;
    let (_, drops) = trail_twin(3, 8.0 / 64.0, 40, frames);
    let out = dir.path().join("out");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args([
            "render",
            path.to_str().unwrap(),
            "--frames",
            "60",
            "--every",
            "59",
        ])
        .args([
            "--resolution",
            "32",
            "--json",
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    assert_eq!(err.matches("child birth(s) dropped").count(), 1, "{err}");
    assert!(
        err.contains(&format!("{} child births dropped", drops * p)),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(v["records"]["dropped_child_births"], drops * p, "{v}");
    assert!(drops > 0);
    assert!(err.contains("per_parent = 6 would hold"), "{err}");
    // `scene check` predicts it: 8/s × 0.625 s = 5 children in 3 trail texels.
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_texflow"))
        .args(["scene", "check", path.to_str().unwrap()])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        o.status.success() && text.contains("use per_parent = 6"),
        "{text}"
    );
}

/// The built-in `fireworks` (time-stamped rockets, UberFlow §4.1): every rocket that dies, at
/// the end of its life, gives exactly its 128 sparks in one step, each on the rocket's last
/// position (a point emitter), and none is dropped over 20 s, past its third cycle (the rocket
/// stamped at 0.2 s, a step boundary, was once born twice in a row from the fourth cycle on);
/// the trails never overflow their 32 texels.
#[test]
fn fireworks_rockets_burst_into_their_128_sparks_where_they_die() {
    let ctx = context();
    let s = scene::load("fireworks").unwrap();
    let layout = s.child_layout();
    let (p, sparks) = (layout.parent_slots as usize, layout.ranges[0]);
    let b = sparks.on_death as usize;
    assert_eq!((b, sparks.per_parent), (128, 128));
    let mut sim = ParticleSim::new(&ctx, &s, 1).unwrap();
    let statics = sim.statics().read_f32().unwrap();
    let mut before = sim.read_positions().unwrap();
    let (mut deaths, mut born) = (0usize, 0usize);
    for _ in 0..1200 {
        sim.step().unwrap();
        let after = sim.read_positions().unwrap();
        for rocket in 0..p {
            let (w0, w1) = (before[rocket * 4 + 3], after[rocket * 4 + 3]);
            // Alive before; after, dead or born again in a new cycle (more life left).
            if !(w0 > 0.0 && (w1 <= 0.0 || w1 > w0)) {
                continue;
            }
            deaths += 1;
            let first = sparks.start as usize + rocket * b;
            let new: Vec<usize> = (first..first + b)
                .filter(|&c| after[c * 4 + 3] == statics[c * 4 + 2])
                .collect();
            assert_eq!(new.len(), b, "rocket {rocket}'s burst");
            for c in new {
                assert_eq!(
                    &after[c * 4..c * 4 + 3],
                    &before[rocket * 4..rocket * 4 + 3]
                );
            }
            born += b;
        }
        before = after;
    }
    // 20 s: past three 6 s cycles, each rocket dies three or four times.
    assert!(deaths >= 75, "{deaths} rockets died in 20 s");
    assert_eq!(born, b * deaths);
    assert_eq!(sim.dropped_child_births().unwrap(), 0);
    no_gl_error(&ctx);
}

/// Allocator parents (Latta §3.4.1): the allocator hands out only the parent texels, so a burst
/// of P + 3 parents drops 3 (counted by the allocator), and the P that were born give exactly
/// P·B children when they die, in the step the life count-down predicts.
#[test]
fn allocator_parents_stay_in_their_texels_and_burst_too() {
    let ctx = context();
    let (b, life_steps) = (3u32, 16usize);
    let probe = parse(&burst_scene(b, 1));
    let p = probe.child_layout().parent_slots as usize;
    let src = burst_scene(b, life_steps as u32).replace(
        "[[emitters.initial]]",
        &format!(
            "[[emitters.allocator]]\nbursts = [{{ time = 0.0, count = {} }}]",
            p + 3
        ),
    );
    let s = parse(&src);
    let mut sim = ParticleSim::new(&ctx, &s, 4).unwrap();
    let children = p..p + p * b as usize;
    for step in 0..life_steps + 3 {
        sim.step().unwrap();
        let pos = sim.read_positions().unwrap();
        let (parents, kids) = (live(&pos, 0..p), live(&pos, children.clone()));
        if step + 1 < life_steps {
            assert_eq!((parents, kids), (p, 0), "after step {step}");
        } else {
            assert_eq!((parents, kids), (0, p * b as usize), "after step {step}");
        }
    }
    assert_eq!(
        sim.dropped_births(),
        3,
        "the allocator had P texels for P + 3 births"
    );
    assert_eq!(sim.dropped_child_births().unwrap(), 0);
    no_gl_error(&ctx);
}

/// At a dt that is no binary fraction (1/60 s) the trail's births of consecutive steps still
/// tile the parent's life: a parent living 0.537 s with 60 births per second asks for exactly
/// ⌊life · 60⌋ = 32, none twice (a second ask would find its texel taken and count a drop) and
/// none skipped. (Taking the end of a step as age + dt instead, as a first version did, asks
/// twice or skips at these numbers: the remaining life counted down by dt in floats is not
/// age + dt.)
#[test]
fn trail_births_tile_the_parents_life_at_an_inexact_dt() {
    let ctx = context();
    let src = trail_scene(40, 60.0, 5)
        .replace("dt = 0.015625", "dt = 0.016666668")
        .replace(
            "speed = [0.0, 0.0]\n",
            "speed = [0.0, 0.0]\nlife = [0.537, 0.537]\n",
        );
    let s = parse(&src);
    let p = s.child_layout().parent_slots as usize;
    let mut sim = ParticleSim::new(&ctx, &s, 2).unwrap();
    let statics = sim.statics().read_f32().unwrap();
    let mut births = vec![0usize; p];
    for _ in 0..40 {
        sim.step().unwrap();
        let pos = sim.read_positions().unwrap();
        for (parent, n) in births.iter_mut().enumerate() {
            let block = p + parent * 40..p + (parent + 1) * 40;
            *n += block
                .filter(|&c| pos[c * 4 + 3] > 0.0 && pos[c * 4 + 3] == statics[c * 4 + 2])
                .count();
        }
    }
    // Births n = 1 ..= ⌊total life · rate⌋, the product in f32 as the shader takes it.
    let want: Vec<usize> = (0..p)
        .map(|i| (statics[i * 4 + 2] * 60.0f32).floor() as usize)
        .collect();
    assert!(want.iter().all(|n| *n == 32), "{want:?}");
    assert_eq!(births, want);
    assert_eq!(sim.dropped_child_births().unwrap(), 0);
    no_gl_error(&ctx);
}

/// The steps in which an instant `t` (s) may fall, a step s covering (s·dt, (s+1)·dt]: one, or
/// the two beside a boundary within `tol` of it (f32 time stamps of f64 instants).
fn steps_holding(t: f64, dt: f64, tol: f64) -> std::ops::RangeInclusive<usize> {
    let lo = ((t - tol) / dt).ceil() - 1.0;
    let hi = ((t + tol) / dt).ceil() - 1.0;
    lo.max(0.0) as usize..=hi.max(0.0) as usize
}

/// Matches the steps `seen` against the instants `want` (ascending, one per cycle): each
/// instant in one of its steps, once, and nothing else seen. Instants whose steps may lie past
/// the run need not be seen.
fn match_instants(what: &str, seen: &[usize], want: &[f64], dt: f64, steps: usize) {
    let mut rest = seen.iter().peekable();
    for &t in want {
        let range = steps_holding(t, dt, 1e-4);
        match rest.peek() {
            Some(&&s) if range.contains(&s) => {
                rest.next();
            }
            _ if *range.end() >= steps => {}
            _ => panic!("{what}: at {t} s, in steps {range:?}; seen in {seen:?}"),
        }
    }
    let extra: Vec<_> = rest.collect();
    assert!(
        extra.is_empty(),
        "{what}: seen in steps {extra:?}, which no instant predicts ({seen:?})"
    );
}

/// Time-stamped parents (UberFlow §4.1) are born once and burst once in every cycle, against
/// the closed form of their time stamps: parent i, of phase φ_i and life L, is born at
/// φ_i + n·cycle and dies at φ_i + n·cycle + L, in the steps that hold those instants, over 3⅓
/// cycles at an inexact dt. Four bursts stamp 32 parents on step boundaries (0.05 s = 3 steps of
/// 1/60 s), where a birth test of the end age against dt was true in two consecutive steps: the
/// parent was born again, its children read that as a death and burst, and the real death's
/// burst found their texels taken (sparks living longer than the parent).
#[test]
fn timestamp_parents_are_born_and_burst_once_per_cycle() {
    let ctx = context();
    let (b, cycle) = (4usize, 0.5f64);
    let src = format!(
        "name = \"stamps\"\nintegrator = \"euler\"\n[particles]\nsize = [{SIDE}, {SIDE}]\n\
         [time]\ndt = 0.016666668\n\
         [[emitters.timestamp]]\ncycle = {cycle:?}\nshape = \"point\"\ncenter = [0.0, 0.0, 0.0]\n\
         direction = [0.0, 1.0, 0.0]\ncone_degrees = 10.0\nspeed = [2.0, 3.0]\nlife = [0.2, 0.2]\n\
         bursts = [{{ time = 0.05, count = 8 }}, {{ time = 0.1, count = 8 }}, \
         {{ time = 0.2, count = 8 }}, {{ time = 0.25, count = 8 }}]\n\
         [[emitters.child]]\nparent = 0\nper_parent = {b}\non_death = {b}\nshape = \"point\"\n\
         direction = [0.0, 1.0, 0.0]\ncone_degrees = 180.0\nspeed = [0.5, 0.5]\n\
         life = [0.25, 0.25]\n"
    );
    let s = parse(&src);
    let p = s.child_layout().parent_slots as usize;
    assert_eq!(p, SIDE * SIDE / (1 + b));
    let mut sim = ParticleSim::new(&ctx, &s, 5).unwrap();
    let statics = sim.statics().read_f32().unwrap();
    let dt = 0.016666668f32 as f64;
    let steps = 100;
    let (mut births, mut bursts) = (vec![Vec::new(); p], vec![Vec::new(); p]);
    for step in 0..steps {
        sim.step().unwrap();
        let pos = sim.read_positions().unwrap();
        for parent in 0..p {
            // Born in this step: alive on the emitter's point, which a flying parent leaves.
            let x = &pos[parent * 4..parent * 4 + 4];
            if x[3] > 0.0 && x[..3] == [0.0, 0.0, 0.0] {
                births[parent].push(step);
            }
            // Children born in this step: their full life left.
            let block = p + parent * b..p + (parent + 1) * b;
            let new = block
                .filter(|&c| pos[c * 4 + 3] > 0.0 && pos[c * 4 + 3] == statics[c * 4 + 2])
                .count();
            if new > 0 {
                assert_eq!(new, b, "parent {parent}'s burst in step {step}");
                bursts[parent].push(step);
            }
        }
    }
    let on_boundary = (0..p)
        .filter(|&i| {
            let k = statics[i * 4] as f64 / dt;
            k > 0.5 && (k - k.round()).abs() < 1e-3
        })
        .count();
    assert!(on_boundary >= 32, "{on_boundary} phases on step boundaries");
    let end = steps as f64 * dt + dt;
    for parent in 0..p {
        let (phase, life) = (statics[parent * 4] as f64, statics[parent * 4 + 2] as f64);
        let born: Vec<f64> = (0..)
            .map(|n| phase + n as f64 * cycle)
            .take_while(|t| *t < end)
            .collect();
        let dies: Vec<f64> = born.iter().map(|t| t + life).filter(|t| *t < end).collect();
        // A birth at φ happens in the step whose end passes it, as a death does.
        let what = format!("parent {parent} (phase {phase}), births");
        match_instants(&what, &births[parent], &born, dt, steps);
        let what = format!("parent {parent} (phase {phase}), bursts");
        match_instants(&what, &bursts[parent], &dies, dt, steps);
        assert!(bursts[parent].len() >= 3, "{:?}", bursts[parent]);
    }
    assert_eq!(sim.dropped_child_births().unwrap(), 0);
    no_gl_error(&ctx);
}
