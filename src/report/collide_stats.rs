//! `texflow collide-stats`: how well the collision detection of [`crate::sim::collide`] did. A
//! step's detection is read back ([`Snapshot::read`]) and compared on the CPU with the true set of
//! overlapping pairs (cell lists), each miss put down to its cause; `collide_runs` runs a scene
//! and times the collision passes, and varies one setting at a time.
//!
//! This is measurement, not simulation: it lives in `report` so that `sim` needs nothing from
//! `bench` (its timers and median).

use glam::Vec3;

use crate::error::{Error, Result};
use crate::scene;
use crate::sim::collide::{CollisionStage, Lattice};

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

/// What the detection of one step saw (see [`Snapshot::read`]).
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
    /// The exact mode: `first.partners` holds (partners found, truncated, 0, 0) per particle.
    pub exact: bool,
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
    /// Missed: the two are in different cells of every lattice, and no lattice fetched them.
    pub missed_adjacent_cells: usize,
    /// Missed: in one cell of a lattice, but sorted into different rows of its layout.
    pub missed_other_row: usize,
    /// Missed: in one cell and one row of a lattice's layout, further apart than `neighbours`.
    pub missed_far_along_row: usize,
    /// Missed: fetched by some lattice (same row of its layout, at most `neighbours` apart) but
    /// each particle keeps only its closest partner.
    pub missed_closer_partner: usize,
    /// Pairs that came closer than 2 radius during the step but no longer overlap at its end
    /// (tunnelling between frames; not among `pairs_true`).
    pub tunnelled: usize,
    /// Mean live particles per occupied cell of the first lattice.
    pub particles_per_cell: f64,
    /// Overlapping neighbours per live particle (2 x true pairs / particles): the density.
    pub overlaps_per_particle: f64,
    /// Particles that overlap at least one other.
    pub overlapping: usize,
    /// Of those, the ones the response acts on: a mutual partner (UberFlow), or at least one
    /// partner found (exact).
    pub partnered: usize,
    /// Mean overlap depth of the true pairs, as a fraction of the diameter:
    /// mean of (2r - |x_i - x_j|) / 2r.
    pub mean_depth: f64,
    /// Exact mode: particles whose search met a run of cells holding more particles than it
    /// walks (`sim::collide::EXACT_SCAN`); their missing partners are missed for that reason.
    pub truncated: usize,
    /// Median GPU time of the collision passes of one step (ms; [`measure`](super::collide_runs::measure) fills it in).
    pub gpu_ms: f64,
    /// Exact mode: found and missed per iteration of the last step ([`measure`](super::collide_runs::measure) fills it in).
    pub iterations: Vec<IterationStats>,
    /// Total kinetic energy of the live particles before the first step and after the last
    /// (J, each particle with its own mass; [`measure`](super::collide_runs::measure) fills it in).
    pub kinetic_energy: [f64; 2],
    /// Total momentum before the first step and after the last (kg m/s).
    pub momentum: [[f64; 3]; 2],
}

/// Found and missed pairs of one iteration of the exact mode, against the true pairs of the
/// state that iteration searched.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct IterationStats {
    /// 1-based.
    pub iteration: u32,
    /// Pairs closer than 2 radius in the state the iteration searched (CPU, cell lists).
    pub pairs_true: usize,
    /// Pairs its search found.
    pub found: usize,
    /// True pairs it did not find.
    pub missed: usize,
    /// Particles whose search met a run of cells holding more than it walks.
    pub truncated: usize,
}

fn pos(v: &[f32], i: usize) -> Vec3 {
    Vec3::new(v[i * 4], v[i * 4 + 1], v[i * 4 + 2])
}

fn live(v: &[f32], i: usize) -> bool {
    crate::sim::particle_live([v[i * 4], v[i * 4 + 1], v[i * 4 + 2], v[i * 4 + 3]])
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
    /// Reads back what the last step's detection of `stage` saw.
    /// In the exact mode with [`CollisionStage::record_iterations`] on, the first iteration's.
    pub fn read(stage: &CollisionStage) -> Result<Snapshot> {
        let (first, second) = stage.lattices();
        let lattice = |lattice: Lattice, staggered: bool| -> Result<LatticeSnapshot> {
            let r = match stage.recorded().first() {
                Some(r) if !staggered => r.clone(),
                _ => stage
                    .read_back(staggered)?
                    .ok_or_else(|| Error::Gl("a lattice without its read-back".into()))?,
            };
            Ok(LatticeSnapshot {
                lattice,
                positions: r.positions,
                velocities: r.velocities,
                partners: r.partners,
            })
        };
        Ok(Snapshot {
            width: stage.width(),
            neighbours: stage.config().neighbours,
            radius: stage.config().radius,
            dt: stage.dt(),
            first: lattice(first, false)?,
            second: second.map(|l| lattice(l, true)).transpose()?,
            exact: stage.detection() == scene::Detection::Exact,
        })
    }

    /// Compares the detection with the true overlapping pairs; particles are named by their
    /// place in the first lattice's order.
    pub fn stats(&self) -> CollisionStats {
        use std::collections::{HashMap, HashSet};
        let a = &self.first;
        let n = a.positions.len() / 4;
        let reach = 2.0 * self.radius;
        let points: Vec<(usize, Vec3)> = (0..n)
            .filter(|&i| live(&a.positions, i))
            .map(|i| (i, pos(&a.positions, i)))
            .collect();
        let truth: HashSet<(usize, usize)> = close_pairs(&points, reach).into_iter().collect();
        let mut true_count = vec![0usize; n];
        for &(i, j) in &truth {
            true_count[i] += 1;
            true_count[j] += 1;
        }
        let overlapping = true_count.iter().filter(|&&c| c > 0).count();
        let mean_depth = truth
            .iter()
            .map(|&(i, j)| {
                (1.0 - pos(&a.positions, i).distance(pos(&a.positions, j)) / reach) as f64
            })
            .sum::<f64>()
            / truth.len().max(1) as f64;
        let density = 2.0 * truth.len() as f64 / points.len().max(1) as f64;
        if self.exact {
            let mut s = self.exact_stats(&points, &truth, &true_count, overlapping, density);
            s.mean_depth = mean_depth;
            return s;
        }
        // Lattice B's order -> lattice A's, by the positions' bits (unique in practice).
        let index_a: HashMap<_, usize> = points.iter().map(|&(i, p)| (bits(p), i)).collect();
        let (found, mutual, choice) = self.detected(n, &index_a);
        // A conflict is a partner that took someone else.
        let chosen = chosen_partners(&choice);
        let partnered = (0..n)
            .filter(|&i| true_count[i] > 0 && chosen[i].is_some())
            .count();
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
            overlaps_per_particle: density,
            overlapping,
            partnered,
            mean_depth,
            ..Default::default()
        };
        self.classify_missed(&mut s, &truth, &found, &index_a);
        s.tunnelled = self.tunnelled(&points, &truth, reach);
        s.particles_per_cell = particles_per_cell(a.lattice, &points);
        s
    }
}

impl Snapshot {
    /// The pairs either lattice found (before the mutual check), the mutual ones, and each
    /// particle's chosen partner and distance per lattice, all in the first lattice's names.
    fn detected(
        &self,
        n: usize,
        index_a: &std::collections::HashMap<Bits, usize>,
    ) -> (PairSet, PairSet, Choices) {
        use std::collections::HashSet;
        let a = &self.first;
        let mut found: HashSet<(usize, usize)> = HashSet::new();
        let mut mutual: HashSet<(usize, usize)> = HashSet::new();
        // Each particle's chosen partner and distance per lattice, in A's names.
        let mut choice: Choices = vec![[None, None]; n];
        for (g, snap) in std::iter::once(a).chain(self.second.as_ref()).enumerate() {
            let name = |i: usize| -> Option<usize> {
                if g == 0 {
                    Some(i)
                } else {
                    index_a.get(&bits(pos(&snap.positions, i))).copied()
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
        (found, mutual, choice)
    }

    /// The exact mode's statistics: its search only counts particles closer than 2r, so what it
    /// found of particle i's true partners is its count, and a pair is missed from i's side if
    /// the count falls short. `missed` counts the missing ends of pairs halved, rounded up (a
    /// pair missed from both sides counts once, from one side half); `found` is the rest.
    fn exact_stats(
        &self,
        points: &[(usize, Vec3)],
        truth: &std::collections::HashSet<(usize, usize)>,
        true_count: &[usize],
        overlapping: usize,
        density: f64,
    ) -> CollisionStats {
        let a = &self.first;
        let mut short = 0usize;
        let mut extra = 0usize;
        let mut partnered = 0usize;
        let mut truncated = 0usize;
        for &(i, _) in points {
            let found = a.partners[i * 4].max(0.0) as usize;
            short += true_count[i].saturating_sub(found);
            extra += found.saturating_sub(true_count[i]);
            if true_count[i] > 0 && found > 0 {
                partnered += 1;
            }
            if a.partners[i * 4 + 1] > 0.5 {
                truncated += 1;
            }
        }
        let missed = short.div_ceil(2);
        let mut cells: std::collections::HashMap<u64, usize> = Default::default();
        for (_, p) in points {
            *cells.entry(a.lattice.key(a.lattice.cell(*p))).or_default() += 1;
        }
        CollisionStats {
            particles: points.len(),
            pairs_true: truth.len(),
            found: truth.len() - missed.min(truth.len()) + extra.div_ceil(2),
            missed,
            false_pairs: extra.div_ceil(2),
            mutual: truth.len() - missed.min(truth.len()),
            overlaps_per_particle: density,
            overlapping,
            partnered,
            truncated,
            particles_per_cell: points.len() as f64 / cells.len().max(1) as f64,
            ..Default::default()
        }
    }
}

type Bits = (u32, u32, u32);

/// A position's bits: B's order is mapped to A's by them (unique in practice).
/// A set of pairs (i < j) of particles.
type PairSet = std::collections::HashSet<(usize, usize)>;

/// Each particle's chosen partner and its distance, per lattice.
type Choices = Vec<[Option<(usize, f32)>; 2]>;

/// Each particle's partner: the closer of its two mutual partners.
fn chosen_partners(choice: &Choices) -> Vec<Option<usize>> {
    choice
        .iter()
        .map(|c| match (c[0], c[1]) {
            (Some(p), Some(q)) => Some(if p.1 <= q.1 { p.0 } else { q.0 }),
            (Some(p), None) | (None, Some(p)) => Some(p.0),
            (None, None) => None,
        })
        .collect()
}

fn bits(p: Vec3) -> Bits {
    (p.x.to_bits(), p.y.to_bits(), p.z.to_bits())
}

/// Live particles per occupied cell of `lattice`.
fn particles_per_cell(lattice: Lattice, points: &[(usize, Vec3)]) -> f64 {
    let mut cells: std::collections::HashMap<u64, usize> = Default::default();
    for (_, p) in points {
        *cells.entry(lattice.key(lattice.cell(*p))).or_default() += 1;
    }
    points.len() as f64 / cells.len().max(1) as f64
}

impl Snapshot {
    /// Each missed pair is put down to the lattice that could have found it, in that
    /// lattice's own layout: fetched in some lattice (same row, at most k apart) but lost to
    /// a closer partner; else sharing a cell in some lattice (the first that does) but sorted
    /// into different rows there or further apart than k; else in different cells of every
    /// lattice.
    fn classify_missed(
        &self,
        s: &mut CollisionStats,
        truth: &std::collections::HashSet<(usize, usize)>,
        found: &std::collections::HashSet<(usize, usize)>,
        index_a: &std::collections::HashMap<Bits, usize>,
    ) {
        let a = &self.first;
        let n = a.positions.len() / 4;
        let (w, k) = (self.width as usize, self.neighbours as usize);
        let b_of: Option<Vec<usize>> = self.second.as_ref().map(|b| {
            let mut m = vec![usize::MAX; n];
            for ib in 0..n {
                if let Some(&ia) = index_a.get(&bits(pos(&b.positions, ib))) {
                    m[ia] = ib;
                }
            }
            m
        });
        for &(i, j) in truth.difference(found) {
            s.missed += 1;
            let (pi, pj) = (pos(&a.positions, i), pos(&a.positions, j));
            let mut layouts = vec![(a.lattice, i, j)];
            if let (Some(b), Some(m)) = (&self.second, &b_of) {
                layouts.push((b.lattice, m[i], m[j]));
            }
            let fetched =
                |&(_, x, y): &(Lattice, usize, usize)| x / w == y / w && x.abs_diff(y) <= k;
            if layouts.iter().any(fetched) {
                s.missed_closer_partner += 1;
            } else if let Some(&(_, x, y)) =
                layouts.iter().find(|(l, _, _)| l.cell(pi) == l.cell(pj))
            {
                if x / w != y / w {
                    s.missed_other_row += 1;
                } else {
                    s.missed_far_along_row += 1;
                }
            } else {
                s.missed_adjacent_cells += 1;
            }
        }
    }

    /// Tunnelling: with x_prev = x - v dt (the explicit step's last move), pairs whose
    /// closest approach during the step was within 2r but which no longer overlap.
    fn tunnelled(
        &self,
        points: &[(usize, Vec3)],
        truth: &std::collections::HashSet<(usize, usize)>,
        reach: f32,
    ) -> usize {
        let a = &self.first;
        let n = a.positions.len() / 4;
        let mut tunnelled = 0;
        let vmax = (0..n)
            .filter(|&i| live(&a.positions, i))
            .map(|i| pos(&a.velocities, i).length())
            .fold(0.0f32, f32::max);
        let wide = reach + 2.0 * vmax * self.dt;
        for (i, j) in close_pairs(points, wide) {
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
                tunnelled += 1;
            }
        }
        tunnelled
    }
}
