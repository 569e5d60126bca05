//! Distance constraints between particles (Latta §3.4.3): the layout of a cloth sheet or of hair
//! strands in the state texture, the neighbours each texel is joined to, the constraint error,
//! and a CPU twin of the relaxation (`twin`).
//!
//! The GPU pass is `glsl/sim/constrain.frag` (run by `sim::particles`); it and the twin read the
//! same [`Layout`]: a rest texture holding every particle's initial position and whether it is
//! pinned. Rest lengths are distances in that layout, so the same pass serves any layout.

use glam::Vec3;

use crate::scene::{ConstraintKind, SceneFile};

/// The texel offsets a texel is joined to, in the order the pass visits them (structural first,
/// then shear).
pub fn neighbours(kind: ConstraintKind) -> &'static [[i32; 2]] {
    match kind {
        ConstraintKind::Cloth => &[
            [1, 0],
            [-1, 0],
            [0, 1],
            [0, -1],
            [1, 1],
            [-1, -1],
            [1, -1],
            [-1, 1],
        ],
        ConstraintKind::Hair => &[[1, 0], [-1, 0]],
    }
}

/// Half of [`neighbours`]: each constraint once, from the texel it starts at.
fn forward(kind: ConstraintKind) -> &'static [[i32; 2]] {
    match kind {
        ConstraintKind::Cloth => &[[1, 0], [0, 1], [1, 1], [1, -1]],
        ConstraintKind::Hair => &[[1, 0]],
    }
}

/// The edge directions of the Gauss-Seidel sets: each direction gives two sets, the edges that
/// start on an even and on an odd coordinate along [`set_axis`].
fn set_directions(kind: ConstraintKind) -> &'static [[i32; 2]] {
    forward(kind)
}

/// Sets of constraints that share no particle (cloth 8: horizontal, vertical and the two
/// diagonals, each split by the parity of its start; hair 2): one pass each.
pub fn set_count(kind: ConstraintKind) -> u32 {
    2 * set_directions(kind).len() as u32
}

/// Which coordinate's parity splits the edges along `d` into two sets (y for vertical edges,
/// x for the others): two edges of one set never share a texel.
fn set_axis(d: [i32; 2]) -> usize {
    (d[0] == 0) as usize
}

/// The texel that texel `t` is joined to by the constraint of `set` (at most one: the sets
/// share no particle), if inside a `size` texture. `glsl/sim/constrain_set.frag` computes the
/// same.
pub fn set_partner(
    kind: ConstraintKind,
    set: u32,
    t: [i32; 2],
    size: [u32; 2],
) -> Option<[i32; 2]> {
    let d = set_directions(kind)[(set / 2) as usize];
    let a = set_axis(d);
    let starts = t[a].rem_euclid(2) as u32 == set % 2;
    let s = if starts { 1 } else { -1 };
    let q = [t[0] + s * d[0], t[1] + s * d[1]];
    let inside = q[0] >= 0 && q[1] >= 0 && q[0] < size[0] as i32 && q[1] < size[1] as i32;
    inside.then_some(q)
}

/// Golden angle (radians): successive hair roots turn by it, so that they spread evenly.
const GOLDEN_ANGLE: f32 = 2.399_963_2;

/// The constrained particles' initial layout: per texel, its rest position and whether it is
/// pinned (the rest texture's `w`: 1 pinned, 0 free).
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Cloth or hair.
    pub kind: ConstraintKind,
    /// State texture size.
    pub size: [u32; 2],
    /// Per texel (row-major): x, y, z, pinned.
    pub rest: Vec<[f32; 4]>,
}

impl Layout {
    /// The layout `scene`'s `[constraints]` describes (`None` without it).
    ///
    /// Cloth: texel (i, j) at `origin + spacing (i û + j v̂)`. Hair: row j is a strand along the
    /// direction n_j out of its root sphere (centre c, radius R), texel i at
    /// `c + (R + i spacing) n_j`; the n_j spiral over the upper cap of the sphere (y from 1
    /// down to 0.2, turning by the golden angle), and every texel 0 is pinned.
    pub fn of(scene: &SceneFile) -> Option<Self> {
        let c = scene.constraints.as_ref()?;
        let [w, h] = scene.particles.size;
        let mut rest = vec![[0.0; 4]; w as usize * h as usize];
        match c.kind {
            ConstraintKind::Cloth => {
                let o = Vec3::from(c.origin);
                let u = Vec3::from(c.u).normalize() * c.spacing;
                let v = Vec3::from(c.v).normalize() * c.spacing;
                for j in 0..h {
                    for i in 0..w {
                        let x = o + i as f32 * u + j as f32 * v;
                        rest[(j * w + i) as usize] = [x.x, x.y, x.z, 0.0];
                    }
                }
            }
            ConstraintKind::Hair => {
                let s = &scene.colliders.sphere[c.root_sphere.unwrap_or(0)];
                let centre = Vec3::from(s.center);
                for j in 0..h {
                    let y = 1.0 - 0.8 * (j as f32 + 0.5) / h as f32;
                    let r = (1.0 - y * y).max(0.0).sqrt();
                    let phi = j as f32 * GOLDEN_ANGLE;
                    let n = Vec3::new(r * phi.cos(), y, r * phi.sin());
                    for i in 0..w {
                        let x = centre + (s.radius + i as f32 * c.spacing) * n;
                        rest[(j * w + i) as usize] = [x.x, x.y, x.z, (i == 0) as u8 as f32];
                    }
                }
            }
        }
        for p in &c.pinned {
            if let Some([x, y]) = crate::scene::Constraints::pinned_texel(*p, [w, h]) {
                rest[(y * w + x) as usize][3] = 1.0;
            }
        }
        Some(Layout {
            kind: c.kind,
            size: [w, h],
            rest,
        })
    }

    /// The rest texture's floats (4 per texel).
    pub fn rest_floats(&self) -> Vec<f32> {
        self.rest.iter().flatten().copied().collect()
    }

    /// The initial positions as a position texture: the rest positions, life 1 (permanent).
    pub fn initial_positions(&self) -> Vec<f32> {
        self.rest
            .iter()
            .flat_map(|r| [r[0], r[1], r[2], 1.0])
            .collect()
    }

    /// Every constraint once: the two texel indices and the rest length.
    pub fn edges(&self) -> Vec<(usize, usize, f32)> {
        let [w, h] = self.size.map(|s| s as i32);
        let mut out = Vec::new();
        for j in 0..h {
            for i in 0..w {
                for [dx, dy] in forward(self.kind) {
                    let (x, y) = (i + dx, j + dy);
                    if x < 0 || y < 0 || x >= w || y >= h {
                        continue;
                    }
                    let (a, b) = ((j * w + i) as usize, (y * w + x) as usize);
                    let rest = (xyz(self.rest[a]) - xyz(self.rest[b])).length();
                    out.push((a, b, rest));
                }
            }
        }
        out
    }

    /// The pinned texels a free texel `k` is attached to by a long-range attachment: cloth every
    /// pinned texel (a flat sheet: the rest distance is the geodesic one), hair its strand's
    /// root. `pins` is [`pins`](Self::pins), found once by the caller for every texel.
    pub fn attachments<'a>(&self, k: usize, pins: &'a [usize]) -> std::borrow::Cow<'a, [usize]> {
        match self.kind {
            ConstraintKind::Cloth => std::borrow::Cow::Borrowed(pins),
            ConstraintKind::Hair => std::borrow::Cow::Owned(vec![k - k % self.size[0] as usize]),
        }
    }

    /// The pinned texels, in texel order.
    pub fn pins(&self) -> Vec<usize> {
        (0..self.rest.len())
            .filter(|&k| self.rest[k][3] > 0.5)
            .collect()
    }

    /// Constraints longer than `1 + bound` times their rest length (or not finite).
    pub fn stretched(&self, positions: &[f32], bound: f32) -> u64 {
        let at = |k: usize| Vec3::from_slice(&positions[4 * k..4 * k + 3]);
        self.edges()
            .into_iter()
            .filter(|&(a, b, rest)| {
                let l = (at(a) - at(b)).length();
                // NaN counts: a torn sheet is stretched past any bound.
                l.is_nan() || l > (1.0 + bound) * rest
            })
            .count() as u64
    }

    /// The relative constraint error |(|x_a - x_b| - rest) / rest| of every constraint, for
    /// positions read back (4 floats per texel): its mean and its worst.
    pub fn error(&self, positions: &[f32]) -> ConstraintError {
        let at = |k: usize| Vec3::from_slice(&positions[4 * k..4 * k + 3]);
        let (mut sum, mut worst, mut n) = (0.0f64, 0.0f64, 0usize);
        for (a, b, rest) in self.edges() {
            let e = (((at(a) - at(b)).length() - rest) / rest).abs() as f64;
            sum += e;
            // NaN is the worst of all: a blown-up sheet must not report a small error.
            worst = if e.is_nan() { f64::NAN } else { worst.max(e) };
            n += 1;
        }
        ConstraintError {
            mean: if n > 0 { sum / n as f64 } else { 0.0 },
            worst,
            constraints: n,
        }
    }
}

fn xyz(r: [f32; 4]) -> Vec3 {
    Vec3::new(r[0], r[1], r[2])
}

/// Relative constraint error over every constraint of a layout.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ConstraintError {
    /// Mean of |(length - rest) / rest|.
    pub mean: f64,
    /// Largest |(length - rest) / rest| (NaN if any length is not finite).
    pub worst: f64,
    /// Number of constraints.
    pub constraints: usize,
}

/// The stretch census of one frame: constraints longer than `1 + bound` times their rest length.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Stretched {
    /// Constraints stretched past the bound (or of non-finite length).
    pub edges: u64,
    /// Constraints in all.
    pub constraints: u64,
    /// The scene's `stretch_bound` (relative).
    pub bound: f32,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{self, Constraints};

    fn scene(kind: &str, size: [u32; 2], extra: &str) -> SceneFile {
        let src = format!(
            "name = \"t\"\nintegrator = \"verlet\"\n[particles]\nsize = [{}, {}]\n\
             [constraints]\nkind = \"{kind}\"\nspacing = 0.1\n{extra}\n\
             [[colliders.sphere]]\ncenter = [0.0, 1.0, 0.0]\nradius = 0.5\n",
            size[0], size[1]
        );
        scene::parse("t", &src).unwrap_or_else(|e| panic!("{e}\n{src}"))
    }

    #[test]
    fn cloth_has_structural_and_shear_constraints_of_the_layout() {
        let s = scene("cloth", [5, 4], "pinned = [[0, 0], [-1, -1]]");
        let l = Layout::of(&s).unwrap();
        let e = l.edges();
        // 4×4 + 5×3 structural, 2 × 4×3 diagonal.
        assert_eq!(e.len(), 4 * 4 + 5 * 3 + 2 * 4 * 3);
        let diagonals = e.iter().filter(|(_, _, r)| *r > 0.11).count();
        assert_eq!(diagonals, 24);
        for (_, _, r) in &e {
            let want = if *r > 0.11 { 0.1 * 2f32.sqrt() } else { 0.1 };
            assert!((r - want).abs() < 1e-6, "{r}");
        }
        let pinned: Vec<usize> = (0..20).filter(|&k| l.rest[k][3] == 1.0).collect();
        assert_eq!(pinned, [0, 19]);
        // At rest the error is zero; stretching one texel shows in the worst.
        let mut x = l.initial_positions();
        assert_eq!(l.error(&x).worst, 0.0);
        x[4 * 19] += 0.05;
        assert!((l.error(&x).worst - 0.5).abs() < 1e-5);
    }

    #[test]
    fn hair_is_one_chain_per_row_rooted_on_its_sphere() {
        let s = scene("hair", [6, 3], "root_sphere = 0");
        let l = Layout::of(&s).unwrap();
        assert_eq!(l.edges().len(), 3 * 5);
        for j in 0..3 {
            let root = Vec3::from_slice(&l.rest[6 * j][..3]);
            assert!(((root - Vec3::Y).length() - 0.5).abs() < 1e-6);
            assert_eq!(l.rest[6 * j][3], 1.0);
            assert_eq!(l.rest[6 * j + 1][3], 0.0);
        }
    }

    #[test]
    fn pins_count_from_the_far_side_when_negative() {
        assert_eq!(Constraints::pinned_texel([-1, 0], [8, 4]), Some([7, 0]));
        assert_eq!(Constraints::pinned_texel([2, -4], [8, 4]), Some([2, 0]));
        assert_eq!(Constraints::pinned_texel([8, 0], [8, 4]), None);
        assert_eq!(Constraints::pinned_texel([0, -5], [8, 4]), None);
    }

    #[test]
    fn an_orbit_starts_at_the_centre_and_turns_once_per_period() {
        let o = scene::Orbit {
            radius: 2.0,
            period: 4.0,
        };
        let at = |t| Vec3::from(o.offset(t));
        assert!(at(0.0).length() < 1e-6);
        assert!((at(1.0) - Vec3::new(-2.0, 0.0, 2.0)).length() < 1e-6);
        assert!((at(2.0) - Vec3::new(-4.0, 0.0, 0.0)).length() < 1e-6);
        assert!(at(4.0).length() < 1e-5);
    }
}
