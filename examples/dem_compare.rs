//! The impulse and the penalty (DEM) response on the same scene: the built-in `dem` (a granular
//! column collapsing in a box) at 32×32 particles, run for 1.5 simulated seconds with
//! `response = "dem"` and with UberFlow's impulse (restitution 0.37, the head-on restitution of
//! the DEM's damping ratio 0.3) at 1 and 4 iterations. Prints the table of docs/collisions.md.
//!
//!     cargo run --release --example dem_compare
//!
//! Overlap: every pair closer than 2r at the end, its depth (2r - d) as a share of the diameter.
//! Energy: kinetic + gravitational (m g y) + the DEM springs' ½ k δ² (dem only), at the start
//! and the end; "largest rise" is the largest increase of that total between two samples 100
//! steps apart (a response that adds energy shows there). Cost: the median wall time of one
//! whole step (integration and collision stage, `glFinish` after each) over the last 100 steps.

use std::time::Instant;

use texflow::gl::Context;
use texflow::scene::{self, Response, SceneFile};
use texflow::sim::ParticleSim;

const STEPS: usize = 1500;

struct Row {
    name: String,
    mean_depth: f64,
    max_depth: f64,
    pairs_per_particle: f64,
    energy: [f64; 2],
    rise: f64,
    kinetic: f64,
    ms: f64,
}

/// (total energy, kinetic energy, mean depth, max depth, overlapping pairs per particle).
fn measure(sim: &ParticleSim, s: &SceneFile) -> (f64, f64, f64, f64, f64) {
    let x = sim.read_positions().unwrap();
    let v = sim.read_velocities().unwrap();
    let c = s.collisions.as_ref().unwrap();
    let reach = 2.0 * c.radius as f64;
    let spring = match (c.response, c.dem) {
        (Response::Dem, Some(d)) => d.spring as f64,
        _ => 0.0,
    };
    let m = s.particles.mass as f64;
    let live: Vec<usize> = (0..x.len() / 4).filter(|&i| x[i * 4 + 3] > 0.0).collect();
    let (mut kinetic, mut potential) = (0.0, 0.0);
    for &i in &live {
        kinetic += 0.5 * m * (0..3).map(|k| (v[i * 4 + k] as f64).powi(2)).sum::<f64>();
        potential += m * 9.81 * x[i * 4 + 1] as f64;
    }
    let (mut elastic, mut sum, mut max, mut pairs) = (0.0, 0.0, 0.0f64, 0usize);
    for (a, &i) in live.iter().enumerate() {
        for &j in &live[a + 1..] {
            let d = (0..3)
                .map(|k| (x[i * 4 + k] as f64 - x[j * 4 + k] as f64).powi(2))
                .sum::<f64>()
                .sqrt();
            if d < reach {
                let depth = reach - d;
                elastic += 0.5 * spring * depth * depth;
                sum += depth / reach;
                max = max.max(depth / reach);
                pairs += 1;
            }
        }
    }
    let mean = if pairs > 0 { sum / pairs as f64 } else { 0.0 };
    (
        kinetic + potential + elastic,
        kinetic,
        100.0 * mean,
        100.0 * max,
        pairs as f64 / live.len() as f64,
    )
}

fn run(ctx: &Context, name: &str, s: SceneFile) -> Row {
    let mut sim = ParticleSim::new(ctx, &s, 1).unwrap();
    let (e0, ..) = measure(&sim, &s);
    let mut last = e0;
    let mut rise = 0.0f64;
    let mut times = Vec::new();
    for step in 1..=STEPS {
        ctx.finish();
        let t = Instant::now();
        sim.step().unwrap();
        ctx.finish();
        if step > STEPS - 100 {
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        if step % 100 == 0 {
            let (e, ..) = measure(&sim, &s);
            rise = rise.max(e - last);
            last = e;
        }
    }
    let (e1, kinetic, mean_depth, max_depth, pairs_per_particle) = measure(&sim, &s);
    times.sort_by(f64::total_cmp);
    Row {
        name: name.to_owned(),
        mean_depth,
        max_depth,
        pairs_per_particle,
        energy: [e0, e1],
        rise,
        kinetic,
        ms: times[times.len() / 2],
    }
}

fn main() {
    let ctx = Context::new(0).expect("an EGL device");
    let mut base = scene::load("dem").unwrap();
    base.particles.size = [32, 32];
    let mut rows = vec![run(&ctx, "dem (spring 2e5 N/m, ζ = 0.3)", base.clone())];
    for iterations in [1, 4] {
        let mut s = base.clone();
        let c = s.collisions.as_mut().unwrap();
        c.response = Response::Impulse;
        c.dem = None;
        c.restitution = 0.37;
        c.iterations = iterations;
        s.validate().map_err(|e| e.message).unwrap();
        rows.push(run(
            &ctx,
            &format!("impulse (e = 0.37), {iterations} iteration(s)"),
            s,
        ));
    }
    println!(
        "`dem` at 32x32, {STEPS} steps of {} s on {}",
        base.time.dt,
        ctx.limits().renderer
    );
    println!(
        "| response | mean overlap (% of diameter) | largest overlap | overlapping pairs per particle | energy start → end (J) | largest rise per 100 steps (J) | kinetic energy at the end (J) | ms per step |"
    );
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for r in rows {
        println!(
            "| {} | {:.2} | {:.1} | {:.2} | {:.1} → {:.1} | {:.3} | {:.4} | {:.1} |",
            r.name,
            r.mean_depth,
            r.max_depth,
            r.pairs_per_particle,
            r.energy[0],
            r.energy[1],
            r.rise,
            r.kinetic,
            r.ms
        );
    }
}
