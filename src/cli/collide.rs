//! `texflow collide-stats`: how well the GPU finds colliding pairs.

use super::overrides::{Overrides, Prepared};
use clap::Args;
use texflow::gl::Context;
use texflow::scene;

use super::{at_least_one, bad, parse_size, positive_finite, progress_bar, Common};

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct CollideStatsArgs {
    /// Scene with a [collisions] section (built-in: collide) or a .toml file.
    #[arg(default_value = "collide")]
    scene: String,
    /// Neighbours fetched to each side in the sorted row (UberFlow: 8).
    #[arg(long)]
    k: Option<u32>,
    /// Second sort and detection on the staggered lattice [default: the scene's].
    #[arg(long, overrides_with = "no_staggered")]
    staggered: bool,
    /// No second sort and detection on the staggered lattice.
    #[arg(long, overrides_with = "staggered")]
    no_staggered: bool,
    /// Sort only within sets of N consecutive rows (1 = rows only); 0 = the whole texture.
    #[arg(long)]
    rows_only: Option<u32>,
    /// Lattice mesh size g0 in metres (default: the scene's).
    #[arg(long, value_parser = positive_finite, allow_hyphen_values = true)]
    cell: Option<f32>,
    /// Detection mode: uberflow (k neighbours per side in the sorted rows) or exact (every
    /// particle of the 27 neighbouring cells).
    #[arg(long, value_parser = ["uberflow", "exact"])]
    detection: Option<String>,
    /// Exact mode: detection and response passes per step (1 to 16).
    #[arg(long)]
    iterations: Option<u32>,
    /// Steps to run; the statistics are taken at the last one.
    #[arg(long, default_value_t = 240, value_parser = at_least_one::<u64>)]
    steps: u64,
    /// State texture size WxH, or N for NxN (powers of two).
    #[arg(long, value_parser = parse_size)]
    particles: Option<[u32; 2]>,
    /// Random seed.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Measure with one setting changed at a time (k, staggered, rows-only, cell size) and
    /// print a table.
    #[arg(long)]
    sweep: bool,
    /// Print JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    set: super::set::SetArgs,
    #[command(flatten)]
    common: Common,
}

/// The scene keys this command's options set, with the option typed, so that an error about
/// the key names the option.
fn option_keys(a: &CollideStatsArgs) -> Vec<(&'static str, &'static str)> {
    let mut v = Vec::new();
    let given = [
        (a.k.is_some(), "collisions.neighbours", "--k"),
        (
            a.staggered || a.no_staggered,
            "collisions.staggered",
            "--staggered",
        ),
        (a.rows_only.is_some(), "collisions.rows_only", "--rows-only"),
        (a.cell.is_some(), "collisions.cell", "--cell"),
        (a.detection.is_some(), "collisions.detection", "--detection"),
        (
            a.iterations.is_some(),
            "collisions.iterations",
            "--iterations",
        ),
    ];
    for (set, key, flag) in given {
        if set {
            v.push((key, flag));
        }
    }
    v
}

pub fn collide_stats(a: CollideStatsArgs) -> texflow::Result<()> {
    let overrides = Overrides {
        particles: a.particles,
        seed: a.seed,
        device: a.common.device,
        set: a.set.set.clone(),
        ..Overrides::default()
    };
    let (label, src) = scene::load_source(&a.scene)?;
    let mut s = scene::parse_with(&label, &src, &overrides.set)?;
    scene::load_custom(&label, &src, &mut s)?;
    let Some(c) = s.collisions.as_mut() else {
        return Err(bad(format!(
            "scene `{}` has no [collisions] section: try `collide`",
            s.name
        )));
    };
    apply_flags(c, &a);
    overrides.apply_naming(&mut s, &option_keys(&a))?;
    let prepared = Prepared {
        label,
        source: src,
        scene: s,
    };
    let s = &prepared.scene;
    let ctx = Context::new(overrides.device)?;
    overrides.check_device(&ctx, &prepared)?;
    let seed = texflow::engine::shader_seed(overrides.seed);
    if a.sweep {
        return sweep(&ctx, s, &a, seed);
    }
    let bar = progress_bar(a.steps, a.common.quiet, "collide-stats");
    let stats = texflow::report::collide_runs::measure(&ctx, s, a.steps, seed, || bar.inc(1))?;
    bar.finish_and_clear();
    let c = s.collisions.as_ref().expect("checked");
    if a.json {
        let mut v = serde_json::to_value(&stats).unwrap_or_default();
        v["scene"] = s.name.clone().into();
        v["k"] = c.neighbours.into();
        v["staggered"] = c.staggered.into();
        v["rows_only"] = c.rows_only.into();
        v["detection"] = format!("{:?}", c.detection).to_lowercase().into();
        v["steps"] = a.steps.into();
        super::print_json("texflow.collide-stats/1", Some(&ctx), &v);
    } else {
        print_stats(&ctx.limits().renderer, s, a.steps, &stats);
    }
    Ok(())
}

/// The command line's collision settings over the scene's.
fn apply_flags(c: &mut scene::Collisions, a: &CollideStatsArgs) {
    if let Some(k) = a.k {
        c.neighbours = k;
    }
    if a.staggered {
        c.staggered = true;
    }
    if a.no_staggered {
        c.staggered = false;
    }
    match a.rows_only {
        Some(0) => c.rows_only = None,
        Some(n) => c.rows_only = Some(n),
        None => {}
    }
    if let Some(g) = a.cell {
        c.cell = Some(g);
    }
    if let Some(n) = a.iterations {
        c.iterations = n;
    }
    if let Some(d) = &a.detection {
        c.detection = if d == "exact" {
            scene::Detection::Exact
        } else {
            scene::Detection::Uberflow
        };
        if c.detection == scene::Detection::Exact {
            c.rows_only = None;
        }
    }
}

/// `--sweep`: one setting changed at a time, as a table or JSON.
fn sweep(
    ctx: &Context,
    s: &scene::SceneFile,
    a: &CollideStatsArgs,
    seed: u32,
) -> texflow::Result<()> {
    let bar = progress_bar(10, a.common.quiet, "collide-stats sweep");
    let rows = texflow::report::collide_runs::sweep(ctx, s, a.steps, seed, |name| {
        bar.set_message(name.to_owned());
        bar.inc(1);
    })?;
    bar.finish_and_clear();
    if a.json {
        super::print_json("texflow.collide-stats.sweep/1", Some(ctx), &rows);
    } else {
        println!(
            "{} on {}, step {} (one setting changed at a time):\n",
            s.name,
            ctx.limits().renderer,
            a.steps
        );
        print!("{}", texflow::report::collide_runs::sweep_table(&rows));
        if rows.iter().all(|r| r.stats.pairs_true == 0) {
            println!("\n{}", nothing_collided(a.steps));
        }
    }
    Ok(())
}

/// One step's detection against the true pairs, as text.
fn print_stats(
    renderer: &str,
    s: &scene::SceneFile,
    steps: u64,
    stats: &texflow::report::collide_stats::CollisionStats,
) {
    let c = s.collisions.as_ref().expect("checked");
    let pct = |n: usize| 100.0 * n as f64 / stats.pairs_true.max(1) as f64;
    println!(
        "{} on {}: step {}, {} live particles, {:.2} per occupied cell; k = {}, staggered {}, \
         sort {}, detection {}",
        s.name,
        renderer,
        steps,
        stats.particles,
        stats.particles_per_cell,
        c.neighbours,
        if c.staggered { "on" } else { "off" },
        match c.rows_only {
            None => "full".to_owned(),
            Some(1) => "rows only".to_owned(),
            Some(r) => format!("within {r} rows"),
        },
        format!("{:?}", c.detection).to_lowercase()
    );
    println!(
        "density      {:>8.2}  overlapping neighbours per particle; mean depth {:.1}% of \
         the diameter",
        stats.overlaps_per_particle,
        100.0 * stats.mean_depth
    );
    println!("pairs_true   {:>8}", stats.pairs_true);
    println!("found        {:>8}", stats.found);
    println!(
        "missed       {:>8}  ({:.1}%)",
        stats.missed,
        pct(stats.missed)
    );
    println!("  adjacent cells      {:>6}", stats.missed_adjacent_cells);
    println!("  partner in another row {:>3}", stats.missed_other_row);
    println!("  far along the row   {:>6}", stats.missed_far_along_row);
    println!("  closer partner kept {:>6}", stats.missed_closer_partner);
    println!(
        "partnered    {:>8}  of {} overlapping particles ({:.1}%) got a partner",
        stats.partnered,
        stats.overlapping,
        100.0 * stats.partnered as f64 / stats.overlapping.max(1) as f64
    );
    if stats.truncated > 0 {
        println!(
            "truncated    {:>8}  particles met a run of cells over the exact search's bound",
            stats.truncated
        );
    }
    if stats.pairs_true == 0 {
        println!("{}", nothing_collided(steps));
    }
    println!("false_pairs  {:>8}", stats.false_pairs);
    println!("mutual       {:>8}", stats.mutual);
    println!(
        "conflicts    {:>8}  (partner took a closer one on the other lattice)",
        stats.conflicts
    );
    println!(
        "tunnelled    {:>8}  (overlapped during the step, apart at its end)",
        stats.tunnelled
    );
    println!(
        "gpu_ms       {:>8.3}  (collision passes of one step)",
        stats.gpu_ms
    );
    for it in &stats.iterations {
        println!(
            "iteration {:>2}  {:>8} true pairs, {} found, {} missed, {} truncated",
            it.iteration, it.pairs_true, it.found, it.missed, it.truncated
        );
    }
    let [e0, e1] = stats.kinetic_energy;
    let [p0, p1] = stats.momentum;
    let dp = (0..3).map(|k| (p1[k] - p0[k]).powi(2)).sum::<f64>().sqrt();
    // A state that starts at rest (a pile poured from above) has no energy to compare with.
    let change = if e0 > 0.0 {
        format!("{:+.2}%", 100.0 * (e1 - e0) / e0)
    } else {
        "no relative change: the live particles started at rest".to_owned()
    };
    println!("energy       {e0:>8.4} J -> {e1:.4} J ({change}); momentum change {dp:.3e} kg m/s");
}

/// Said when no two particles overlap at the measured step: the rates are then 0 of 0.
fn nothing_collided(steps: u64) -> String {
    format!(
        "note: no two particles overlapped at step {steps}: nothing has collided yet, so every \
         count and rate above is of 0 pairs. Run more --steps (a poured scene needs time to \
         pile up) or more --particles."
    )
}
