//! `texflow trace SCENE --frame N`: a scene run to frame N, then frame N pass by pass, each
//! pass's output textures read back and drawn, with an index naming the pass, its paper and
//! section, its inputs and outputs.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::picture::{finite_range, live_bounds, positions, scalar, sparse_rows};
use super::Written;
use crate::engine::Stages;
use crate::error::{Error, Result};
use crate::gl::{Context, Texture};
use crate::output::{write_atomic, write_png_atomic};
use crate::scene::SceneFile;
use crate::sim::state::POSITION;
use crate::sim::{Simulation, Stage};

/// The largest state texture side a scene trace draws (256×256 particles: pictures of 512×512
/// pixels, two pixels a texel).
pub const MAX_TRACE_SIDE: u32 = 256;

/// The last frame a scene trace runs to.
pub const MAX_TRACE_FRAME: u64 = 10_000;

/// Refuses a trace too large to draw or too long to run, before any GPU work.
pub fn check_scene_trace(scene: &SceneFile, frame: u64) -> Result<()> {
    let [w, h] = scene.particles.size;
    if w > MAX_TRACE_SIDE || h > MAX_TRACE_SIDE {
        return Err(Error::InvalidInput(format!(
            "scene `{}` has a {w}x{h} state texture: a trace draws at most \
             {MAX_TRACE_SIDE}x{MAX_TRACE_SIDE}; pass --particles {MAX_TRACE_SIDE} or less",
            scene.name
        )));
    }
    if frame > MAX_TRACE_FRAME {
        return Err(Error::InvalidInput(format!(
            "--frame {frame}: a trace runs to frame {MAX_TRACE_FRAME} at most"
        )));
    }
    Ok(())
}

/// One texture of a pass, drawn.
struct Shot {
    /// What it shows ("position", "velocity", ...).
    what: String,
    /// The picture.
    image: image::RgbImage,
    /// How to read it: the colours and the range.
    legend: String,
}

/// The pictures and the index of a trace being written.
struct Recorder<'a> {
    out: &'a Path,
    md: String,
    files: Vec<PathBuf>,
    passes: usize,
    /// The box positions are coloured within, fixed at the first position picture.
    bounds: Option<[[f32; 3]; 2]>,
    from_scene: bool,
}

impl Recorder<'_> {
    fn pass(
        &mut self,
        name: &str,
        source: &str,
        inputs: &str,
        outputs: &str,
        shots: Vec<Shot>,
    ) -> Result<()> {
        self.passes += 1;
        let n = self.passes;
        let _ = writeln!(
            self.md,
            "## {n}. {name}\n\n- Source: {source}\n- Reads: {inputs}\n- Writes: {outputs}\n"
        );
        for s in shots {
            let slug: String = s
                .what
                .chars()
                .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
                .collect();
            let file = format!("{n:02}_{slug}.png");
            let path = self.out.join(&file);
            write_png_atomic(&path, &s.image)?;
            let _ = writeln!(
                self.md,
                "**{}**: {}\n\n![{}]({file})\n",
                s.what, s.legend, s.what
            );
            self.files.push(path);
        }
        Ok(())
    }

    /// Positions (xyz, life) as colours within the trace's box.
    fn positions(&mut self, what: &str, texels: &[f32], size: [u32; 2]) -> Shot {
        let any_live = texels.chunks_exact(4).any(|p| p[3] > 0.0);
        if self.bounds.is_none() && any_live {
            self.bounds = Some(live_bounds(texels));
        }
        let b = self.bounds.unwrap_or([[0.0; 3], [1.0; 3]]);
        let live = texels.chunks_exact(4).filter(|p| p[3] > 0.0).count();
        let rows = sparse_rows(texels, size[0], size[1]);
        let (shown, shown_size) = crop(texels, 4, size, rows);
        Shot {
            what: what.to_owned(),
            image: positions(shown, shown_size[0], shown_size[1], b),
            legend: format!(
                "red, green, blue = x, y, z within [{:.3}, {:.3}] × [{:.3}, {:.3}] × [{:.3}, \
                 {:.3}] ({}); black: dead (life ≤ 0). {live} of {} texels live.{}",
                b[0][0],
                b[1][0],
                b[0][1],
                b[1][1],
                b[0][2],
                b[1][2],
                if self.from_scene {
                    "the scene's collision bounds"
                } else {
                    "the live particles' box at the first picture of the frame"
                },
                texels.len() / 4,
                rows_note(rows, size[1])
            ),
        }
    }
}

/// `values` (`channels` floats a texel, `size` texels) cropped to the rows `rows` (first,
/// last), and the cropped size; all of them without rows.
fn crop(
    values: &[f32],
    channels: usize,
    size: [u32; 2],
    rows: Option<(u32, u32)>,
) -> (&[f32], [u32; 2]) {
    match rows {
        None => (values, size),
        Some((a, b)) => {
            let w = size[0] as usize * channels;
            let end = ((b as usize + 1) * w).min(values.len());
            (
                &values[(a as usize * w).min(end)..end],
                [size[0], b - a + 1],
            )
        }
    }
}

/// What a legend says of a picture cropped to the rows of the live particles (sparse states
/// are black but for a strip otherwise).
fn rows_note(rows: Option<(u32, u32)>, height: u32) -> String {
    rows.map(|(a, b)| {
        format!(" Rows {a}..{b} of {height} hold the live particles; only they are drawn.")
    })
    .unwrap_or_default()
}

/// Speeds of the live particles on the ramp, cropped to the rows the position picture shows.
fn speed_shot(velocities: &[f32], positions: &[f32], size: [u32; 2], note: &str) -> Shot {
    let rows = sparse_rows(positions, size[0], size[1]);
    let all = speeds(velocities, positions);
    let (shown, shown_size) = crop(&all, 1, size, rows);
    let mut shot = ramp_shot("velocity", shown, shown_size, note);
    shot.legend.push_str(&rows_note(rows, size[1]));
    shot
}

/// A scalar per texel on the ramp over its finite range, the range in the legend.
fn ramp_shot(what: &str, values: &[f32], size: [u32; 2], note: &str) -> Shot {
    let range = finite_range(values.iter().copied()).unwrap_or((0.0, 1.0));
    Shot {
        what: what.to_owned(),
        image: scalar(values, size[0], size[1], range),
        legend: format!(
            "{note}, on the ramp from dark blue ({:.4}) to yellow ({:.4}); magenta: not finite.",
            range.0, range.1
        ),
    }
}

/// Speeds |v| of RGBA velocity texels, 0 where the particle is dead.
fn speeds(velocities: &[f32], positions: &[f32]) -> Vec<f32> {
    velocities
        .chunks_exact(4)
        .zip(positions.chunks_exact(4))
        .map(|(v, p)| {
            if p[3] > 0.0 {
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
            } else {
                f32::NAN
            }
        })
        .collect()
}

fn size_of(t: &Texture) -> [u32; 2] {
    [t.width(), t.height()]
}

fn frame_shot(image: image::RgbImage) -> Shot {
    Shot {
        what: "frame".to_owned(),
        image,
        legend: "the frame as `texflow render` writes it.".to_owned(),
    }
}

/// Runs `scene` to frame `frame` (frames 0..frame as `render` runs them), then traces frame
/// `frame` pass by pass into `out` (which must exist): PNGs of each pass's outputs and
/// `index.md`.
pub fn trace_scene(
    ctx: &Context,
    scene: &SceneFile,
    seed: u64,
    frame: u64,
    out: &Path,
) -> Result<Written> {
    check_scene_trace(scene, frame)?;
    let mut r = Recorder {
        out,
        md: String::new(),
        files: Vec::new(),
        passes: 0,
        bounds: scene.collisions.as_ref().map(|c| c.bounds),
        from_scene: scene.collisions.is_some(),
    };
    let _ = writeln!(
        r.md,
        "# Trace of scene `{}`, frame {frame}\n\n`texflow trace {} --frame {frame} --seed {seed}`: \
         frames 0 to {} ran as `texflow render` runs them; then each pass of frame {frame} ran \
         alone and its output textures were read back. Each picture has one square per texel, \
         texel (0, 0) at the top left. `texflow scene passes {}` lists the same passes.\n",
        scene.name,
        scene.name,
        frame.saturating_sub(1),
        scene.name
    );
    let mut engine = crate::engine::build_gpu(ctx, scene, seed)?;
    let e = engine.as_mut();
    for _ in 0..frame {
        e.advance_frame()?;
        e.order_for_drawing()?;
    }
    trace_frame(e, &mut r)?;
    let index = out.join("index.md");
    write_atomic(&index, r.md.as_bytes())?;
    r.files.push(index);
    Ok(Written {
        files: r.files,
        passes: r.passes,
        ok: true,
    })
}

/// The state outputs of a simulation pass: positions, velocities (or Verlet's implied ones),
/// and the user's states.
fn state_shots(sim: &dyn Simulation, r: &mut Recorder<'_>) -> Result<Vec<Shot>> {
    let size = sim.size();
    let (p, v) = sim.read_state()?;
    let note = match sim.drawn().velocities {
        Some(_) => "speed |v| of live particles",
        None => "speed |x − x_prev| / dt of live particles (Verlet keeps no velocity)",
    };
    let mut shots = vec![
        r.positions("position", &p, size),
        speed_shot(&v, &p, size, note),
    ];
    // The user's states (`[[state]]`), written by their passes at the end of the integration.
    for (name, values) in sim.read_more()? {
        let Some(name) = name.strip_prefix("state_") else {
            continue;
        };
        let x: Vec<f32> = (values.chunks_exact(4).zip(p.chunks_exact(4)))
            .map(|(u, p)| if p[3] > 0.0 { u[0] } else { f32::NAN })
            .collect();
        let note = format!(
            "user state `{name}` (x channel) of live particles, written by its own pass \
             (`glsl/sim/user_state.frag`) after the integration"
        );
        // Cropped to the live rows as the position picture is.
        let rows = sparse_rows(&p, size[0], size[1]);
        let (shown, shown_size) = crop(&x, 1, size, rows);
        let mut shot = ramp_shot(&format!("state {name}"), shown, shown_size, &note);
        shot.legend.push_str(&rows_note(rows, size[1]));
        shots.push(shot);
    }
    Ok(shots)
}

/// How the index words a stage of a step: its title, what it reads and what it writes (its
/// passes, in the papers' words, are its source).
fn stage_words(stage: Stage, state: &str) -> [String; 3] {
    match stage {
        Stage::Births => [
            "births (points)".into(),
            "a vertex buffer of this step's births, from the CPU allocator".into(),
            format!("front: {state} and static, in place at the allocated texels"),
        ],
        Stage::Integrate => [
            "integrate".into(),
            format!("front: {state}; static; the scene's fields"),
            format!("back: {state} (MRT), then swap"),
        ],
        Stage::Relax => [
            "constraint relaxation".into(),
            "current position, rest texture".into(),
            "current position (the ring's free side, then swapped)".into(),
        ],
        Stage::Collide => [
            "collision stage (cell keys, sort, gather, detection, response)".into(),
            "position, velocity, static".into(),
            "position, velocity (swap); static copied in the new order".into(),
        ],
    }
}

/// Frame N pass by pass: each stage of each step (as the simulation's pass list has them), the
/// frame's sort, and the render pass with the frame `render` writes.
fn trace_frame(e: &mut dyn Stages, r: &mut Recorder<'_>) -> Result<()> {
    let substeps = e.sim().substeps();
    let state = match e.sim().drawn().velocities {
        Some(_) => "position, velocity",
        None => "previous and current position",
    };
    let size = e.sim().size();
    let passes = e.sim().passes();
    for k in 0..substeps {
        let step = format!("step {} of {substeps}", k + 1);
        for stage in e.sim().stages() {
            e.sim_mut().run(stage)?;
            let mut shots = state_shots(e.sim(), r)?;
            if stage == Stage::Births {
                let more = e.sim().read_more()?;
                if let Some((_, statics)) = more.iter().find(|(n, _)| *n == "statics") {
                    let births: Vec<f32> = statics.chunks_exact(4).map(|c| c[0]).collect();
                    shots.push(ramp_shot(
                        "static birth time",
                        &births,
                        size,
                        "birth time (s)",
                    ));
                }
            }
            if stage == Stage::Collide {
                shots.extend(cell_shots(e.sim())?);
            }
            let source = (passes.iter())
                .filter(|p| p.stage == stage)
                .map(|p| p.name.as_str())
                .collect::<Vec<_>>()
                .join("; ");
            let [title, reads, writes] = stage_words(stage, state);
            r.pass(&format!("{step}: {title}"), &source, &reads, &writes, shots)?;
        }
    }
    trace_sort(e, r)?;
    // The render lines of the engine's pass list: what `scene passes` prints.
    let names: Vec<String> = (e.passes().into_iter())
        .filter(|p| p.stage == "render")
        .map(|p| p.name)
        .collect();
    let img = e.render()?;
    r.pass(
        "render (`glsl/render/particle.vert` + `particle.frag`)",
        &names.join("; "),
        "position and static (sorted ones with alpha blending), by vertex texture fetch or vertex \
         buffers",
        "the frame (RGBA8), read back",
        vec![frame_shot(img)],
    )?;
    Ok(())
}

/// The frame's sorting, where alpha blending needs it: keys, the network's passes of this frame,
/// and the gather.
fn trace_sort(e: &mut dyn Stages, r: &mut Recorder<'_>) -> Result<()> {
    if e.sorter().is_none() {
        return Ok(());
    }
    let mut shots: Vec<(String, Vec<Shot>)> = Vec::new();
    e.order_for_drawing_observed(&mut |phase, sorter| {
        let entries = sorter.read()?;
        let sz = [sorter.width(), sorter.height()];
        let keys: Vec<f32> = entries.iter().map(|x| x[0]).collect();
        let ids: Vec<f32> = entries.iter().map(|x| x[1]).collect();
        shots.push((
            phase.to_owned(),
            vec![
                ramp_shot("sort key", &keys, sz, "key: signed distance to the viewer"),
                ramp_shot("sort id", &ids, sz, "id: the particle's texel index"),
            ],
        ));
        Ok(())
    })?;
    let variant = e.sorter().map_or("", |s| s.variant().name());
    for (phase, s) in shots {
        match phase.as_str() {
            "keys" => r.pass(
                "sort keys (`glsl/sort/keys.frag`)",
                "UberFlow §4.3 (keys by viewer distance); Latta §3.4.4",
                "position",
                "sort texture: (key, id) per entry; dead particles +inf (last)",
                s,
            )?,
            _ => r.pass(
                &format!(
                    "sort network: {variant}, this frame's passes (`texflow trace sort \
                     --variant {variant}` shows them one by one)"
                ),
                "UberFlow §4.3.2-4.3.3, Fig. 1-2 (bitonic); Latta §3.4.4, Fig. 3-5 \
                 (odd-even merge)",
                "sort texture (ping-pong)",
                "sort texture in order of key, then id",
                s,
            )?,
        }
    }
    if let Some(sorted) = e.sorted() {
        let p = sorted.texture(POSITION).read_f32()?;
        let sz = size_of(sorted.texture(POSITION));
        let shots = vec![r.positions("sorted position", &p, sz)];
        r.pass(
            "gather (`glsl/sort/rearrange.frag`)",
            "UberFlow §4.3 (the state re-ordered by the sorted ids)",
            "sort texture (ids), position, static",
            "sorted position and static (MRT), in drawing order",
            shots,
        )?;
    }
    Ok(())
}

/// The first lattice's view after the collision stage: each texel's cell index (UberFlow's sort
/// key) in the lattice's sorted order, and the partner found.
fn cell_shots(sim: &dyn Simulation) -> Result<Vec<Shot>> {
    let Some(c) = sim.collision_stage() else {
        return Ok(Vec::new());
    };
    let Some(back) = c.read_back(false)? else {
        return Ok(Vec::new());
    };
    let size = sim.size();
    let (lattice, _) = c.lattices();
    let cells: Vec<f32> = back
        .positions
        .chunks_exact(4)
        .map(|p| {
            if p[3] > 0.0 {
                lattice.key(lattice.cell(glam::Vec3::new(p[0], p[1], p[2]))) as f32
            } else {
                f32::NAN
            }
        })
        .collect();
    let partners: Vec<f32> = back.partners.chunks_exact(4).map(|q| q[0]).collect();
    Ok(vec![
        ramp_shot(
            "cell index",
            &cells,
            size,
            "lattice cell index of each texel in the cell-sorted order (rows read left to right \
             rise)",
        ),
        ramp_shot(
            "partner",
            &partners,
            size,
            "partner found by the detection (texel index, −1 none)",
        ),
    ])
}
