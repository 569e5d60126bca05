//! The distance constraints' error (Latta §3.4.3) against the relaxation passes per step, and
//! its stability against the time step and the stiffness, on the GPU next to the CPU twin
//! (`sim::reference::constraints`). Prints the tables of docs/pipeline.md.
//!
//!     cargo run --release --example constraint_error [jacobi | gauss-seidel]
//!
//! `jacobi` (the default here, Jacobi without attachments: the tables of docs/pipeline.md) or
//! `gauss-seidel` (Gauss-Seidel sets with long-range attachments, the scenes' default).
//!
//! Relative error of a constraint: |(|x_a - x_b| - rest) / rest|; its mean and its worst over
//! every constraint of the scene after each step, averaged over one simulated second (and the
//! largest worst of any step, "peak").

use texflow::gl::Context;
use texflow::scene::{self, SceneFile};
use texflow::sim::constraints::ConstraintError;
use texflow::sim::reference::constraints::Twin;
use texflow::sim::ParticleSim;

/// The errors of one run, averaged over its steps.
#[derive(Default)]
struct Run {
    /// Time average of the mean relative error.
    mean: f64,
    /// Time average of the worst relative error.
    worst: f64,
    /// Largest worst relative error of any step.
    peak: f64,
}

impl Run {
    fn add(&mut self, e: ConstraintError, steps: usize) {
        self.mean += e.mean / steps as f64;
        self.worst += e.worst / steps as f64;
        self.peak = if e.worst.is_nan() {
            f64::NAN
        } else {
            self.peak.max(e.worst)
        };
    }
}

/// Runs `scene` for one simulated second on the GPU and on the twin, measuring the error after
/// every step: both runs, the largest |GPU - CPU| coordinate at the end, and the fastest particle
/// on the GPU then (m/s).
fn run(ctx: &Context, scene: &SceneFile) -> texflow::Result<(Run, Run, f32, f32)> {
    let mut sim = ParticleSim::new(ctx, scene, 1)?;
    let mut twin = Twin::new(scene)?;
    let steps = (1.0 / scene.time.dt).round() as usize;
    let (mut g, mut c) = (Run::default(), Run::default());
    let layout = sim
        .constraint_layout()
        .expect("a constrained scene")
        .clone();
    for _ in 0..steps {
        sim.step()?;
        twin.step();
        g.add(layout.error(&sim.read_positions()?), steps);
        c.add(twin.error(), steps);
    }
    let gpu = sim.read_positions()?;
    let diff = gpu
        .iter()
        .zip(twin.positions())
        .map(|(a, b)| (a - b).abs())
        .fold(0.0f32, |m, d| if d.is_nan() { f32::NAN } else { m.max(d) });
    let speed = sim
        .read_velocities()?
        .chunks(4)
        .map(|v| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt())
        .fold(0.0f32, |m, s| if s.is_nan() { f32::NAN } else { m.max(s) });
    Ok((g, c, diff, speed))
}

fn pct(e: f64) -> String {
    format!("{:.3} %", 100.0 * e)
}

/// `name` with the scheme of the command line.
fn load(name: &str) -> texflow::Result<SceneFile> {
    let mut s = scene::load(name)?;
    let scheme = std::env::args().nth(1).unwrap_or_else(|| "jacobi".into());
    let c = s.constraints.as_mut().expect("constraints");
    (c.scheme, c.attachments) = match scheme.as_str() {
        "jacobi" => (scene::RelaxScheme::Jacobi, false),
        "gauss-seidel" => (scene::RelaxScheme::GaussSeidel, true),
        other => {
            return Err(texflow::Error::InvalidInput(format!(
                "unknown scheme `{other}`: give jacobi or gauss-seidel"
            )))
        }
    };
    Ok(s)
}

fn main() -> texflow::Result<()> {
    let ctx = Context::new(0)?;
    println!("device: {}", ctx.limits().renderer);
    for name in ["cloth", "hair"] {
        let base = load(name)?;
        println!(
            "\n{name}: error after 1 s against relaxation passes per step (dt {:.5} s)",
            base.time.dt
        );
        println!(
            "| passes | GPU mean | GPU worst | GPU peak worst | twin mean | twin worst | \
             twin peak worst | max abs(GPU - twin) at 1 s |"
        );
        println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
        for n in [1, 2, 4, 8, 16] {
            let mut s = base.clone();
            s.constraints.as_mut().expect("constraints").iterations = n;
            let (g, c, diff, _) = run(&ctx, &s)?;
            println!(
                "| {n} | {} | {} | {} | {} | {} | {} | {diff:.1e} m |",
                pct(g.mean),
                pct(g.worst),
                pct(g.peak),
                pct(c.mean),
                pct(c.worst),
                pct(c.peak)
            );
        }
    }
    let base = load("cloth")?;
    println!("\ncloth, 8 passes: error after 1 s against dt and stiffness (GPU; twin mean beside)");
    println!(
        "| dt (s) | stiffness | GPU mean | GPU worst | GPU peak worst | twin mean | twin peak \
         worst | fastest particle at 1 s |"
    );
    println!("| ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |");
    for dt in [
        1.0 / 480.0,
        1.0 / 240.0,
        1.0 / 120.0,
        1.0 / 60.0,
        1.0 / 30.0,
    ] {
        for k in [0.25, 0.5, 1.0] {
            let mut s = base.clone();
            s.time.dt = dt;
            let c = s.constraints.as_mut().expect("constraints");
            c.iterations = 8;
            c.stiffness = k;
            let (g, t, _, speed) = run(&ctx, &s)?;
            println!(
                "| 1/{:.0} | {k} | {} | {} | {} | {} | {} | {speed:.2} m/s |",
                1.0 / dt,
                pct(g.mean),
                pct(g.worst),
                pct(g.peak),
                pct(t.mean),
                pct(t.peak)
            );
        }
    }
    Ok(())
}
