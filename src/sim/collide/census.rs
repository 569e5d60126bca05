//! What a collision frame rate is worth: how many of the overlapping pairs a step's detection
//! found, counted on the CPU from a read-back ([`CollisionStage::census`]).

use std::collections::{HashMap, HashSet};

use glam::Vec3;

use super::{CollisionStage, Readback};
use crate::error::Result;
use crate::scene;

/// How many of the overlapping pairs a step's detection found (see [`CollisionStage::census`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PairCensus {
    /// Pairs of live particles closer than 2 radius.
    pub pairs: usize,
    /// Of those, the ones the detection found (by either lattice; exact mode: from both sides).
    pub found: usize,
}

impl PairCensus {
    /// Found over true pairs (1 when there are none).
    pub fn fraction(&self) -> f64 {
        if self.pairs == 0 {
            1.0
        } else {
            self.found as f64 / self.pairs as f64
        }
    }
}

impl CollisionStage {
    /// Counts, on the CPU, the pairs closer than 2 radius after the last step's detection and
    /// how many of them it found: what a collision frame rate is worth. (`report::collide_stats`
    /// takes the full statistics; this is the number the benchmarks print beside their fps.)
    pub fn census(&self) -> Result<PairCensus> {
        let a = self.read_back(false)?.expect("the first lattice");
        let overlaps = Overlaps::new(&a.positions, 2.0 * self.config.radius);
        if self.config.detection == scene::Detection::Exact {
            return Ok(overlaps.exact_census(&a.partners));
        }
        let found = self.found_pairs(&a, &overlaps.live)?;
        let (mut pairs, mut hit) = (0usize, 0usize);
        overlaps.for_each_pair(&mut |i, j| {
            pairs += 1;
            hit += found.contains(&(i, j)) as usize;
        });
        Ok(PairCensus { pairs, found: hit })
    }

    /// The pairs either lattice's detection found, named by their place in the first lattice's
    /// order `a` (the staggered lattice's particles matched to it by their positions' bits).
    fn found_pairs(&self, a: &Readback, live: &[usize]) -> Result<HashSet<(usize, usize)>> {
        let n = a.positions.len() / 4;
        let mut found: HashSet<(usize, usize)> = HashSet::new();
        let index_a: HashMap<_, usize> = live
            .iter()
            .map(|&i| (key(position(&a.positions, i)), i))
            .collect();
        let staggered = self.read_back(true)?;
        let lattices = [Some(a), staggered.as_ref()];
        for (g, r) in lattices.iter().enumerate() {
            let Some(r) = r else { continue };
            for i in 0..n {
                let raw = r.partners[i * 4 + 3];
                if raw < 0.0 {
                    continue;
                }
                let name = |k: usize| {
                    if g == 0 {
                        Some(k)
                    } else {
                        index_a.get(&key(position(&r.positions, k))).copied()
                    }
                };
                if let (Some(x), Some(y)) = (name(i), name(raw as usize)) {
                    found.insert((x.min(y), x.max(y)));
                }
            }
        }
        Ok(found)
    }
}

/// A position's bits, to match a particle across lattices.
fn key(p: Vec3) -> (u32, u32, u32) {
    (p.x.to_bits(), p.y.to_bits(), p.z.to_bits())
}

/// Particle `i`'s position in RGBA texels `v`.
fn position(v: &[f32], i: usize) -> Vec3 {
    Vec3::new(v[i * 4], v[i * 4 + 1], v[i * 4 + 2])
}

/// The live particles of one lattice's read-back, in cells of side `reach` (2 radius).
struct Overlaps<'a> {
    positions: &'a [f32],
    reach: f32,
    live: Vec<usize>,
    cells: HashMap<glam::IVec3, Vec<usize>>,
}

impl<'a> Overlaps<'a> {
    /// The live particles of `positions` (xyz, life) and their cells.
    fn new(positions: &'a [f32], reach: f32) -> Self {
        let n = positions.len() / 4;
        let live: Vec<usize> = (0..n)
            .filter(|&i| positions[i * 4 + 3] > 0.0 && position(positions, i).is_finite())
            .collect();
        let mut cells: HashMap<glam::IVec3, Vec<usize>> = HashMap::new();
        for &i in &live {
            cells
                .entry((position(positions, i) / reach).floor().as_ivec3())
                .or_default()
                .push(i);
        }
        Overlaps {
            positions,
            reach,
            live,
            cells,
        }
    }

    /// Every overlapping pair once (j > i), from the 27 cells around each particle: linear in
    /// the particles where the density is bounded (as in Table 2's scenes), with no list of the
    /// pairs kept.
    fn for_each_pair(&self, f: &mut dyn FnMut(usize, usize)) {
        let (p, reach) = (self.positions, self.reach);
        for &i in &self.live {
            let c = (position(p, i) / reach).floor().as_ivec3();
            for d in 0..27 {
                let o = glam::IVec3::new(d % 3 - 1, (d / 3) % 3 - 1, d / 9 - 1);
                for &j in self.cells.get(&(c + o)).into_iter().flatten() {
                    if j > i && position(p, i).distance(position(p, j)) < reach {
                        f(i, j);
                    }
                }
            }
        }
    }

    /// The exact mode's census: `partners` holds each particle's count of partners found, so a
    /// pair is missed from a side whose count falls short; missing ends are halved, rounded up.
    fn exact_census(&self, partners: &[f32]) -> PairCensus {
        let n = self.positions.len() / 4;
        let mut pairs = 0usize;
        let mut count = vec![0usize; n];
        self.for_each_pair(&mut |i, j| {
            pairs += 1;
            count[i] += 1;
            count[j] += 1;
        });
        let short: usize = self
            .live
            .iter()
            .map(|&i| count[i].saturating_sub(partners[i * 4].max(0.0) as usize))
            .sum();
        let missed = short.div_ceil(2).min(pairs);
        PairCensus {
            pairs,
            found: pairs - missed,
        }
    }
}
