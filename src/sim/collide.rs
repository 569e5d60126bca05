//! Collisions between particles as UberFlow does them (§4.3-4.5): every step, after the
//! collisionless motion, the particles are sorted by the index of their cell in a lattice of mesh
//! size g0 (cells enumerated z, y, x), the state is gathered in that order, each particle looks
//! for its closest partner among `neighbours` particles to each side in its row, and a response
//! pass backs colliding spheres up to first contact and exchanges momentum. With the staggered
//! lattice (Fig. 3) the state is sorted a second time on a lattice shifted by g0/2 and the closer
//! partner of the two detections wins. Boundary conditions (colliders, §4.6) follow in the same
//! response pass.
//!
//! Pairing is made symmetric per lattice: a partner counts only if it chose this particle too
//! (`glsl/collide/mutual.frag`), so both sides of a pair apply opposite impulses. Across the two
//! lattices a particle may still take a partner from one lattice while that partner takes a closer
//! one from the other; [`CollisionStats`] counts these conflicts.

use glam::{UVec3, Vec3};

use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, PingPong, Program, Texture, TextureDesc,
    TextureFormat, FULLSCREEN_VERTEX,
};
use crate::scene::{self, SceneFile};
use crate::sort::{KeyMode, SortOptions, Sorter, Variant};

/// Most neighbours per side the detection loop is compiled for.
pub const MAX_NEIGHBOURS: u32 = 32;

/// A lattice: corner of cell (0, 0, 0), mesh size, cells per axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// Corner of cell (0, 0, 0).
    pub origin: Vec3,
    /// Mesh size g0.
    pub spacing: f32,
    /// Cells per axis.
    pub dims: UVec3,
}

impl Lattice {
    /// The lattice of a scene's `[collisions]`, or its staggered twin (shifted by g0/2, one cell
    /// more per axis).
    pub fn of(c: &scene::Collisions, staggered: bool) -> Self {
        let g = c.cell.unwrap_or(2.0 * c.radius);
        let lo = Vec3::from(c.bounds[0]);
        let hi = Vec3::from(c.bounds[1]);
        let dims = ((hi - lo) / g).ceil().max(Vec3::ONE).as_uvec3();
        if staggered {
            Lattice {
                origin: lo - Vec3::splat(0.5 * g),
                spacing: g,
                dims: dims + UVec3::ONE,
            }
        } else {
            Lattice {
                origin: lo,
                spacing: g,
                dims,
            }
        }
    }

    /// The cell of `p`, clamped to the lattice (as the key pass does).
    pub fn cell(&self, p: Vec3) -> UVec3 {
        let c = ((p - self.origin) / self.spacing).floor();
        let max = (self.dims - UVec3::ONE).as_vec3();
        c.clamp(Vec3::ZERO, max).as_uvec3()
    }

    /// The key of a cell, enumerated z, y, x.
    pub fn key(&self, c: UVec3) -> u64 {
        (c.z as u64 * self.dims.y as u64 + c.y as u64) * self.dims.x as u64 + c.x as u64
    }

    fn mode(&self) -> KeyMode {
        KeyMode::GridCell {
            origin: self.origin,
            spacing: self.spacing,
            dims: self.dims,
        }
    }
}

/// One lattice's sort, gathered state and detection output.
#[derive(Debug)]
struct Grid {
    lattice: Lattice,
    sorter: Sorter,
    /// The state in this lattice's sorted order: position, velocity, static (and, for the
    /// staggered lattice, the first lattice's detection, gathered along).
    layout: Framebuffer,
    /// Detection output after the mutual check: (partner or -1, distance, mutual, raw partner).
    partner: Framebuffer,
}

/// The collision stage of a scene.
#[derive(Debug)]
pub struct Collisions {
    ctx: Context,
    config: scene::Collisions,
    first: Grid,
    second: Option<Grid>,
    raw: Framebuffer,
    detect: Program,
    mutual: Program,
    response: Program,
    copy: Program,
    pass: FullscreenPass,
    width: u32,
    dt: f32,
}

fn texture(ctx: &Context, label: &str, w: u32, h: u32, format: TextureFormat) -> Result<Texture> {
    Texture::new(
        ctx,
        TextureDesc {
            width: w,
            height: h,
            format,
            label,
        },
    )
}

impl Collisions {
    /// Builds the stage for `scene` (which has a `[collisions]` section); `defines` are the
    /// simulation's, so the response pass applies the same colliders and precision.
    pub fn new(
        ctx: &Context,
        scene: &SceneFile,
        defines: &Defines,
        velocity_format: TextureFormat,
    ) -> Result<Self> {
        let Some(config) = scene.collisions.clone() else {
            return Err(Error::InvalidInput(
                "the scene has no [collisions] section".into(),
            ));
        };
        let [w, h] = scene.particles.size;
        let options = SortOptions {
            rows: config.rows_only,
            ..Default::default()
        };
        let grid = |staggered: bool, extra: bool| -> Result<Grid> {
            let lattice = Lattice::of(&config, staggered);
            let cells = lattice.dims.x as u64 * lattice.dims.y as u64 * lattice.dims.z as u64;
            if cells > 1 << 24 {
                return Err(Error::InvalidInput(format!(
                    "the collision lattice has {cells} cells; cell keys are exact floats only up \
                     to 2^24: use a larger cell or smaller bounds"
                )));
            }
            let name = if staggered { "staggered" } else { "lattice" };
            let mut textures = vec![
                texture(
                    ctx,
                    &format!("{name} position"),
                    w,
                    h,
                    TextureFormat::Rgba32F,
                )?,
                texture(ctx, &format!("{name} velocity"), w, h, velocity_format)?,
                texture(ctx, &format!("{name} static"), w, h, TextureFormat::Rgba32F)?,
            ];
            if extra {
                textures.push(texture(
                    ctx,
                    &format!("{name} first partner"),
                    w,
                    h,
                    TextureFormat::Rgba32F,
                )?);
            }
            Ok(Grid {
                lattice,
                sorter: Sorter::new(ctx, Variant::Packed, w, h, options)?,
                layout: Framebuffer::new(ctx, &format!("{name} layout"), textures)?,
                partner: Framebuffer::new(
                    ctx,
                    &format!("{name} partner"),
                    vec![texture(
                        ctx,
                        &format!("{name} partner"),
                        w,
                        h,
                        TextureFormat::Rgba32F,
                    )?],
                )?,
            })
        };
        let first = grid(false, false)?;
        let second = if config.staggered {
            Some(grid(true, true)?)
        } else {
            None
        };
        let mut d = defines.clone();
        d.push(("MAX_NEIGHBOURS".into(), MAX_NEIGHBOURS.to_string()));
        if config.staggered {
            d.push(("STAGGERED".into(), "1".into()));
        }
        let stage = Collisions {
            raw: Framebuffer::new(
                ctx,
                "detection",
                vec![texture(ctx, "detection", w, h, TextureFormat::Rgba32F)?],
            )?,
            detect: Program::new(ctx, FULLSCREEN_VERTEX, "collide/detect.frag", &d)?,
            mutual: Program::new(ctx, FULLSCREEN_VERTEX, "collide/mutual.frag", &d)?,
            response: Program::new(ctx, FULLSCREEN_VERTEX, "collide/response.frag", &d)?,
            copy: Program::new(ctx, FULLSCREEN_VERTEX, "collide/copy.frag", &d)?,
            pass: FullscreenPass::new(ctx)?,
            ctx: ctx.clone(),
            config,
            first,
            second,
            width: w,
            dt: scene.time.dt,
        };
        Ok(stage)
    }

    /// The configuration.
    pub fn config(&self) -> &scene::Collisions {
        &self.config
    }

    /// The first lattice and, with the staggered grid, the second.
    pub fn lattices(&self) -> (Lattice, Option<Lattice>) {
        (self.first.lattice, self.second.as_ref().map(|g| g.lattice))
    }

    fn detect_into(&self, positions: &Texture, out: &Framebuffer) {
        let p = &self.detect;
        p.bind();
        positions.bind(0);
        p.set_i32("u_position", 0);
        p.set_i32("u_width", self.width as i32);
        p.set_i32("u_neighbours", self.config.neighbours as i32);
        p.set_f32("u_radius", self.config.radius);
        self.pass.draw(p, &self.raw);
        let m = &self.mutual;
        m.bind();
        self.raw.texture(0).bind(0);
        m.set_i32("u_partner", 0);
        m.set_i32("u_width", self.width as i32);
        self.pass.draw(m, out);
    }

    /// One collision step on the state after the collisionless motion: sorts, detects, responds
    /// into `state.back()` (then swaps) and leaves the static texture in the new order.
    /// `set_response_constants` sets the colliders' uniforms on the response program.
    pub fn run(
        &mut self,
        state: &mut PingPong,
        statics: &Framebuffer,
        dt: f32,
        inv_mass: glam::Vec4,
        set_response_constants: impl Fn(&Program),
    ) -> Result<()> {
        let count = self.width as usize * state.height() as usize;
        // First lattice: keys from the current state, sort, gather.
        let front = state.front();
        let g = &mut self.first;
        g.sorter
            .write_keys(front.texture(0), count, &g.lattice.mode(), true)?;
        g.sorter.sort();
        g.sorter.gather(
            &[front.texture(0), front.texture(1), statics.texture(0)],
            &g.layout,
        )?;
        self.detect_into(self.first.layout.texture(0), &self.first.partner);
        // Staggered lattice: sort the gathered state again, taking the first detection along.
        if let Some(g2) = &mut self.second {
            let a = &self.first.layout;
            g2.sorter
                .write_keys(a.texture(0), count, &g2.lattice.mode(), true)?;
            g2.sorter.sort();
            g2.sorter.gather(
                &[
                    a.texture(0),
                    a.texture(1),
                    a.texture(2),
                    self.first.partner.texture(0),
                ],
                &g2.layout,
            )?;
        }
        if let Some(g2) = &self.second {
            self.detect_into(g2.layout.texture(0), &g2.partner);
        }
        // Response in the last layout.
        let (own, partner) = match &self.second {
            Some(g2) => (&g2.layout, &g2.partner),
            None => (&self.first.layout, &self.first.partner),
        };
        let p = &self.response;
        p.bind();
        set_response_constants(p);
        // Units 0-2 as the simulation's programs; 3-5 hold its fields (colliders); 8-12 here.
        own.texture(0).bind(0);
        own.texture(1).bind(1);
        own.texture(2).bind(2);
        partner.texture(0).bind(8);
        p.set_i32("u_position", 0);
        p.set_i32("u_velocity", 1);
        p.set_i32("u_static", 2);
        p.set_i32("u_partner", 8);
        if self.second.is_some() {
            let a = &self.first.layout;
            own.texture(3).bind(9);
            a.texture(0).bind(10);
            a.texture(1).bind(11);
            a.texture(2).bind(12);
            p.set_i32("u_partner2", 9);
            p.set_i32("u_position2", 10);
            p.set_i32("u_velocity2", 11);
            p.set_i32("u_static2", 12);
        }
        p.set_i32("u_width", self.width as i32);
        p.set_f32("u_radius", self.config.radius);
        p.set_f32("u_restitution", self.config.restitution);
        p.set_f32("u_dt", dt);
        p.set_vec4("u_inv_mass", inv_mass);
        self.pass.draw(p, state.back());
        state.swap();
        let c = &self.copy;
        c.bind();
        own.texture(2).bind(0);
        c.set_i32("u_source", 0);
        self.pass.draw(c, statics);
        Ok(())
    }

    /// Reads back what the last step's detection saw, for statistics.
    pub fn snapshot(&self) -> Result<Snapshot> {
        let read = |g: &Grid| -> Result<LatticeSnapshot> {
            Ok(LatticeSnapshot {
                lattice: g.lattice,
                positions: g.layout.texture(0).read_f32()?,
                velocities: g.layout.texture(1).read_f32()?,
                partners: g.partner.texture(0).read_f32()?,
            })
        };
        Ok(Snapshot {
            width: self.width,
            neighbours: self.config.neighbours,
            radius: self.config.radius,
            dt: self.dt,
            first: read(&self.first)?,
            second: self.second.as_ref().map(read).transpose()?,
        })
    }

    /// The context.
    pub fn context(&self) -> &Context {
        &self.ctx
    }
}

/// One lattice's view of a step: the positions in its sorted order and each one's partner.
#[derive(Debug, Clone)]
pub struct LatticeSnapshot {
    /// The lattice.
    pub lattice: Lattice,
    /// Positions (xyz, life) in this lattice's sorted order.
    pub positions: Vec<f32>,
    /// Velocities in the same order.
    pub velocities: Vec<f32>,
    /// (partner after the mutual check or -1, distance, mutual, partner before the check).
    pub partners: Vec<f32>,
}

/// What the detection of one step saw (see [`Collisions::snapshot`]).
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// State texture width (sorted rows).
    pub width: u32,
    /// Neighbours fetched to each side.
    pub neighbours: u32,
    /// Sphere radius.
    pub radius: f32,
    /// Time step.
    pub dt: f32,
    /// The first lattice.
    pub first: LatticeSnapshot,
    /// The staggered lattice.
    pub second: Option<LatticeSnapshot>,
}

/// How well one step's detection did against the true set of overlapping pairs.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct CollisionStats {
    /// Live particles.
    pub particles: usize,
    /// Pairs closer than 2 radius (CPU, cell lists).
    pub pairs_true: usize,
    /// Pairs the GPU detection reported, by either lattice (before the mutual check).
    pub found: usize,
    /// True pairs not found.
    pub missed: usize,
    /// Found pairs that do not overlap.
    pub false_pairs: usize,
    /// Found pairs that were mutual in their lattice (the response applies these).
    pub mutual: usize,
    /// Particles whose chosen partner took a closer partner from the other lattice.
    pub conflicts: usize,
    /// Missed: the two are in different cells of the first lattice (and of the staggered one).
    pub missed_adjacent_cells: usize,
    /// Missed: same cell, but sorted into different rows.
    pub missed_other_row: usize,
    /// Missed: same row, further apart than `neighbours`.
    pub missed_far_along_row: usize,
    /// Missed: within reach, but each particle keeps only its closest partner.
    pub missed_closer_partner: usize,
    /// Pairs that came closer than 2 radius during the step but no longer overlap at its end
    /// (tunnelling between frames; not among `pairs_true`).
    pub tunnelled: usize,
    /// Mean live particles per occupied cell of the first lattice.
    pub particles_per_cell: f64,
    /// Median GPU time of the collision passes of one step (ms; [`measure`] fills it in).
    pub gpu_ms: f64,
}

fn pos(v: &[f32], i: usize) -> Vec3 {
    Vec3::new(v[i * 4], v[i * 4 + 1], v[i * 4 + 2])
}

fn live(v: &[f32], i: usize) -> bool {
    v[i * 4 + 3] > 0.0 && pos(v, i).is_finite()
}

/// Pairs (i < j) of live particles closer than `reach`, by cell lists of mesh `reach`.
fn close_pairs(points: &[(usize, Vec3)], reach: f32) -> Vec<(usize, usize)> {
    use std::collections::HashMap;
    let cell = |p: Vec3| (p / reach).floor().as_ivec3();
    let mut cells: HashMap<glam::IVec3, Vec<usize>> = HashMap::new();
    for (k, (_, p)) in points.iter().enumerate() {
        cells.entry(cell(*p)).or_default().push(k);
    }
    let mut out = Vec::new();
    for (k, (i, p)) in points.iter().enumerate() {
        let c = cell(*p);
        for dz in -1..=1 {
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let Some(list) = cells.get(&(c + glam::IVec3::new(dx, dy, dz))) else {
                        continue;
                    };
                    for &m in list {
                        let (j, q) = points[m];
                        if m > k && p.distance(q) < reach {
                            out.push(((*i).min(j), (*i).max(j)));
                        }
                    }
                }
            }
        }
    }
    out
}

impl Snapshot {
    /// Compares the detection with the true overlapping pairs; particles are named by their
    /// place in the first lattice's order.
    pub fn stats(&self) -> CollisionStats {
        use std::collections::{HashMap, HashSet};
        let a = &self.first;
        let n = a.positions.len() / 4;
        let w = self.width as usize;
        let k = self.neighbours as usize;
        let reach = 2.0 * self.radius;
        let points: Vec<(usize, Vec3)> = (0..n)
            .filter(|&i| live(&a.positions, i))
            .map(|i| (i, pos(&a.positions, i)))
            .collect();
        let truth: HashSet<(usize, usize)> = close_pairs(&points, reach).into_iter().collect();
        // Lattice B's order -> lattice A's, by the positions' bits (unique in practice).
        let key = |p: Vec3| (p.x.to_bits(), p.y.to_bits(), p.z.to_bits());
        let index_a: HashMap<_, usize> = points.iter().map(|&(i, p)| (key(p), i)).collect();
        let mut found: HashSet<(usize, usize)> = HashSet::new();
        let mut mutual: HashSet<(usize, usize)> = HashSet::new();
        // Each particle's chosen partner and distance per lattice, in A's names.
        let mut choice: Vec<[Option<(usize, f32)>; 2]> = vec![[None, None]; n];
        for (g, snap) in std::iter::once(a).chain(self.second.as_ref()).enumerate() {
            let name = |i: usize| -> Option<usize> {
                if g == 0 {
                    Some(i)
                } else {
                    index_a.get(&key(pos(&snap.positions, i))).copied()
                }
            };
            for i in 0..n {
                let raw = snap.partners[i * 4 + 3];
                if raw < 0.0 {
                    continue;
                }
                let (Some(x), Some(y)) = (name(i), name(raw as usize)) else {
                    continue;
                };
                let pair = (x.min(y), x.max(y));
                found.insert(pair);
                if snap.partners[i * 4 + 2] > 0.5 {
                    mutual.insert(pair);
                    choice[x][g] = Some((y, snap.partners[i * 4 + 1]));
                }
            }
        }
        // A particle takes the closer of its two mutual partners; a conflict is a partner
        // that took someone else.
        let chosen: Vec<Option<usize>> = choice
            .iter()
            .map(|c| match (c[0], c[1]) {
                (Some(p), Some(q)) => Some(if p.1 <= q.1 { p.0 } else { q.0 }),
                (Some(p), None) | (None, Some(p)) => Some(p.0),
                (None, None) => None,
            })
            .collect();
        let conflicts = (0..n)
            .filter(|&i| matches!(chosen[i], Some(j) if chosen[j] != Some(i)))
            .count();
        let false_pairs = found
            .iter()
            .filter(|(i, j)| pos(&a.positions, *i).distance(pos(&a.positions, *j)) >= reach)
            .count();
        let mut s = CollisionStats {
            particles: points.len(),
            pairs_true: truth.len(),
            found: found.len(),
            false_pairs,
            mutual: mutual.len(),
            conflicts,
            ..Default::default()
        };
        for &(i, j) in truth.difference(&found) {
            s.missed += 1;
            let (pi, pj) = (pos(&a.positions, i), pos(&a.positions, j));
            let same_b = self
                .second
                .as_ref()
                .map(|b| b.lattice.cell(pi) == b.lattice.cell(pj));
            if a.lattice.cell(pi) != a.lattice.cell(pj) && same_b != Some(true) {
                s.missed_adjacent_cells += 1;
            } else if i / w != j / w {
                s.missed_other_row += 1;
            } else if i.abs_diff(j) > k {
                s.missed_far_along_row += 1;
            } else {
                s.missed_closer_partner += 1;
            }
        }
        // Tunnelling: with x_prev = x - v dt (the explicit step's last move), pairs whose
        // closest approach during the step was within 2r but which no longer overlap.
        let vmax = (0..n)
            .filter(|&i| live(&a.positions, i))
            .map(|i| pos(&a.velocities, i).length())
            .fold(0.0f32, f32::max);
        let wide = reach + 2.0 * vmax * self.dt;
        for (i, j) in close_pairs(&points, wide) {
            if truth.contains(&(i, j)) {
                continue;
            }
            let (xi, xj) = (pos(&a.positions, i), pos(&a.positions, j));
            let dx = xi - xj;
            let dv = (pos(&a.velocities, i) - pos(&a.velocities, j)) * self.dt;
            // d(s) = dx - s dv for s in [0, 1] back in time.
            let s_min = if dv.length_squared() > 0.0 {
                (dx.dot(dv) / dv.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            if (dx - s_min * dv).length() < reach {
                s.tunnelled += 1;
            }
        }
        let mut cells: HashMap<u64, usize> = HashMap::new();
        for (_, p) in &points {
            *cells.entry(a.lattice.key(a.lattice.cell(*p))).or_default() += 1;
        }
        s.particles_per_cell = points.len() as f64 / cells.len().max(1) as f64;
        s
    }
}

/// Steps at the end of a [`measure`] run whose collision passes are timed (the median is
/// reported: one step alone is at the mercy of a noisy machine).
pub const TIMED_STEPS: u64 = 5;

/// Runs `scene` for `steps` steps and measures the last step's detection against the CPU
/// reference, with the median GPU time of the collision passes over the last [`TIMED_STEPS`]
/// steps (fewer if the run is shorter). `progress` is called after each step.
pub fn measure(
    ctx: &Context,
    scene: &SceneFile,
    steps: u64,
    seed: u32,
    mut progress: impl FnMut(),
) -> Result<CollisionStats> {
    if steps == 0 {
        return Err(Error::InvalidInput(
            "measuring needs at least 1 step".into(),
        ));
    }
    let mut sim = super::ParticleSim::new(ctx, scene, seed)?;
    if sim.collisions().is_none() {
        return Err(Error::InvalidInput(format!(
            "scene `{}` has no [collisions] section",
            scene.name
        )));
    }
    let timer = crate::bench::PassTimer::new(ctx, crate::bench::Clock::for_context(ctx))?;
    let timed = TIMED_STEPS.min(steps);
    for _ in timed..steps {
        sim.step()?;
        progress();
    }
    // Collision scenes emit by time stamps, so a step is the integration pass and the collision
    // stage: the same step, with the stage timed alone.
    let mut times = Vec::new();
    for _ in 0..timed {
        sim.integrate_only();
        let mut result = Ok(());
        times.push(timer.time(|| result = sim.collide())?);
        result?;
        progress();
    }
    let stage = sim.collisions().expect("checked above");
    let mut stats = stage.snapshot()?.stats();
    stats.gpu_ms = crate::bench::median(&times);
    ctx.check_error("measuring collisions")?;
    Ok(stats)
}

/// One row of [`sweep`]: what was varied and what it gave.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct SweepRow {
    /// What differs from the scene's own settings.
    pub variant: String,
    /// Neighbours per side.
    pub k: u32,
    /// Staggered lattice.
    pub staggered: bool,
    /// Rows-only sort sets (None: full sort).
    pub rows_only: Option<u32>,
    /// Lattice mesh size (m).
    pub cell: f32,
    /// The measurement.
    pub stats: CollisionStats,
}

/// The scene's detection measured with one setting changed at a time: k, the staggered lattice,
/// rows-only sorting, and the cell size (particles per cell).
pub fn sweep(
    ctx: &Context,
    scene: &SceneFile,
    steps: u64,
    seed: u32,
    mut progress: impl FnMut(&str),
) -> Result<Vec<SweepRow>> {
    let Some(base) = scene.collisions.clone() else {
        return Err(Error::InvalidInput(format!(
            "scene `{}` has no [collisions] section",
            scene.name
        )));
    };
    let g = base.cell.unwrap_or(2.0 * base.radius);
    let mut variants: Vec<(String, scene::Collisions)> = vec![("scene".into(), base.clone())];
    for k in [1u32, 2, 4, 16] {
        if k != base.neighbours {
            variants.push((
                format!("k = {k}"),
                scene::Collisions {
                    neighbours: k,
                    ..base.clone()
                },
            ));
        }
    }
    variants.push((
        format!("staggered {}", if base.staggered { "off" } else { "on" }),
        scene::Collisions {
            staggered: !base.staggered,
            ..base.clone()
        },
    ));
    for rows in [1u32, 8] {
        variants.push((
            format!(
                "rows-only sort ({rows} row{})",
                if rows == 1 { "" } else { "s" }
            ),
            scene::Collisions {
                rows_only: Some(rows),
                ..base.clone()
            },
        ));
    }
    for f in [2.0f32, 4.0] {
        variants.push((
            format!("cell {f} x"),
            scene::Collisions {
                cell: Some(g * f),
                ..base.clone()
            },
        ));
    }
    let mut rows = Vec::new();
    for (name, c) in variants {
        progress(&name);
        let mut s = scene.clone();
        s.collisions = Some(c.clone());
        let stats = measure(ctx, &s, steps, seed, || {})?;
        rows.push(SweepRow {
            variant: name,
            k: c.neighbours,
            staggered: c.staggered,
            rows_only: c.rows_only,
            cell: c.cell.unwrap_or(2.0 * c.radius),
            stats,
        });
    }
    Ok(rows)
}

/// The sweep as a markdown table.
pub fn sweep_table(rows: &[SweepRow]) -> String {
    let mut out = String::from(
        "| variant | k | staggered | sort | cell (m) | particles/cell | true pairs | found | \
         missed | miss rate | adjacent cells | other row | far along row | closer kept | \
         tunnelled | conflicts | GPU ms |\n\
         | --- | ---: | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: \
         | ---: | ---: | ---: | ---: |\n",
    );
    for r in rows {
        let s = &r.stats;
        out.push_str(&format!(
            "| {} | {} | {} | {} | {:.3} | {:.2} | {} | {} | {} | {:.1}% | {} | {} | {} | {} | {} \
             | {} | {:.2} |\n",
            r.variant,
            r.k,
            if r.staggered { "on" } else { "off" },
            match r.rows_only {
                None => "full".to_owned(),
                Some(1) => "rows".to_owned(),
                Some(n) => format!("{n} rows"),
            },
            r.cell,
            s.particles_per_cell,
            s.pairs_true,
            s.found,
            s.missed,
            100.0 * s.missed as f64 / s.pairs_true.max(1) as f64,
            s.missed_adjacent_cells,
            s.missed_other_row,
            s.missed_far_along_row,
            s.missed_closer_partner,
            s.tunnelled,
            s.conflicts,
            s.gpu_ms
        ));
    }
    out
}
