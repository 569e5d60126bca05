//! Colliders of the twin: `glsl/sim/colliders.glsl`.

use glam::{Vec2, Vec3};

use super::{Events, Reference, Shape, SKIN};
use crate::sim::fields::HeightField;

impl Reference {
    /// Signed distance and outward normal of `p` to a collider other than the height field:
    /// `plane_distance`, `sphere_distance`, `box_distance`, `sdf_distance`.
    pub(super) fn distance(shape: &Shape, p: Vec3) -> (f32, Vec3) {
        match shape {
            Shape::Plane(pl) => {
                let n = pl.truncate();
                (n.dot(p) - pl.w, n)
            }
            Shape::Sphere(s) => {
                let d = p - s.truncate();
                let r = d.length();
                let n = if r > 0.0 { d / r } else { Vec3::Y };
                (r - s.w, n)
            }
            Shape::Box(lo, hi) => box_distance(*lo, *hi, p),
            Shape::Sdf(lo, hi, field) => {
                if p.cmplt(*lo).any() || p.cmpgt(*hi).any() {
                    return (1e30, Vec3::Y);
                }
                let n = field.normal(p);
                (field.sample(p), n)
            }
        }
    }

    /// `height_distance`: vertical distance to the landscape and its normal there.
    pub(super) fn height_distance(field: &HeightField, p: Vec3) -> (f32, Vec3) {
        let (h, n) = field.sample(p.x, p.z);
        (p.y - h, n)
    }

    /// `collision_response`: Latta eq. 4-5 with the slow-speed threshold.
    pub(super) fn response(&self, v: Vec3, n: Vec3, resp: Vec2, ev: &mut Events) -> Vec3 {
        let vn = v.dot(n);
        if vn >= 0.0 {
            return v;
        }
        ev.hits += 1;
        let v_n = vn * n;
        let v_t = v - v_n;
        let mu = if v.length() < self.slow_speed {
            ev.slow += 1;
            0.0
        } else {
            resp.x
        };
        (1.0 - mu) * v_t - resp.y * v_n
    }

    /// `collide` for the explicit integrators, then nothing else: `keep_outside` follows.
    pub(super) fn collide_explicit(
        &self,
        x: &mut Vec3,
        v: Vec3,
        vb: &mut Vec3,
        xb: &mut Vec3,
        ev: &mut Events,
    ) {
        for c in &self.colliders {
            let (d0, n0) = Self::distance(&c.shape, *x);
            let (d1, n1) = Self::distance(&c.shape, *xb);
            // collide_explicit
            if d1 >= 0.0 {
                continue;
            }
            if d0 < 0.0 {
                *x -= (d0 - SKIN) * n0;
                *vb = caught_response(*vb, n0);
                ev.caught += 1;
            } else {
                *vb = self.response(*vb, n1, c.resp, ev);
            }
            *xb = self.advance(*x, v, *vb);
        }
        if let Some((field, resp)) = &self.height {
            let (d1, _) = Self::height_distance(field, *xb);
            if d1 < 0.0 {
                let (d0, n0) = Self::height_distance(field, *x);
                if d0 < 0.0 {
                    x.y -= d0 - SKIN;
                    *vb = caught_response(*vb, n0);
                    *xb = self.advance(*x, v, *vb);
                    ev.caught += 1;
                } else {
                    let s = d0 / (d0 - d1);
                    let xc = mix(*x, *xb, s);
                    let (_, nc) = Self::height_distance(field, xc);
                    *vb = self.response(*vb, nc, *resp, ev);
                    *xb = xc + *vb * ((1.0 - s) * self.dt);
                    ev.crossings += 1;
                }
            }
        }
    }

    /// `constrain`: Latta eq. 4-5 on Verlet's implied velocity `(xn - x) / dt`; the new
    /// position is `x + v' dt`, so the next step's implied velocity is the response `v'`.
    pub(super) fn constrain(
        &self,
        d: f32,
        n: Vec3,
        resp: Vec2,
        x: Vec3,
        xn: &mut Vec3,
        ev: &mut Events,
    ) {
        if d >= 0.0 {
            return;
        }
        let v = (*xn - x) / self.dt;
        *xn = x + self.response(v, n, resp, ev) * self.dt;
    }

    /// `collide` for Verlet.
    pub(super) fn collide_verlet(&self, x: Vec3, xn: &mut Vec3, ev: &mut Events) {
        for c in &self.colliders {
            let (d, n) = Self::distance(&c.shape, *xn);
            self.constrain(d, n, c.resp, x, xn, ev);
        }
        if let Some((field, resp)) = &self.height {
            let (d, n) = Self::height_distance(field, *xn);
            // Vertical distance to distance along the normal.
            self.constrain(d * n.y, n, *resp, x, xn, ev);
        }
    }

    /// `push_distance`: collider `k` in the sweep's order (planes, spheres, boxes, the distance
    /// field, then the height field): its distance at `p`, the push direction `u`, the normal
    /// and whether it is bounded.
    fn push_distance(&self, k: usize, p: Vec3) -> (f32, Vec3, Vec3, bool) {
        match self.colliders.get(k) {
            Some(c) => {
                let (d, n) = Self::distance(&c.shape, p);
                (d, n, n, !matches!(c.shape, Shape::Plane(_)))
            }
            None => {
                let (field, _) = self.height.as_ref().expect("k counts the height field");
                let (d, n) = Self::height_distance(field, p);
                (d, Vec3::Y, n, false)
            }
        }
    }

    /// `keep_outside`: projects a position still inside a collider out to `SKIN` above its
    /// surface and takes away the velocity into the surface; a push that would undo the previous
    /// one walks on through a bounded collider along the previous push's direction instead.
    pub(super) fn keep_outside(&self, x: &mut Vec3, v: &mut Vec3, ev: &mut Events) {
        let count = self.colliders.len() + self.height.is_some() as usize;
        let mut last = Vec3::ZERO;
        for _ in 0..KEEP_OUTSIDE_SWEEPS {
            let mut moved = false;
            for k in 0..count {
                let (mut d, u, mut n, bounded) = self.push_distance(k, *x);
                if d >= 0.0 {
                    continue;
                }
                if bounded && u.dot(last) < 0.0 {
                    let mut j = 0;
                    while j < EXIT_STEPS && d < 0.0 {
                        *x += (SKIN - d) * last;
                        (d, _, n, _) = self.push_distance(k, *x);
                        j += 1;
                    }
                    ev.walked_out += 1;
                } else {
                    *x -= (d - SKIN) * u;
                    last = u;
                }
                *v -= v.dot(n).min(0.0) * n;
                ev.kept_outside += 1;
                moved = true;
            }
            if !moved {
                break;
            }
        }
    }

    /// The least signed distance of `p` to the scene's colliders (the height field's vertical
    /// one), `+inf` without colliders: for tests that place particles inside, near or far.
    pub fn distance_to_colliders(&self, p: Vec3) -> f32 {
        let mut d = f32::INFINITY;
        for c in &self.colliders {
            d = d.min(Self::distance(&c.shape, p).0);
        }
        if let Some((field, _)) = &self.height {
            d = d.min(Self::height_distance(field, p).0);
        }
        d
    }
}

/// Sweeps of `keep_outside` over all colliders (`KEEP_OUTSIDE_SWEEPS` in colliders.glsl).
const KEEP_OUTSIDE_SWEEPS: usize = 4;

/// Steps of the walk through a collider (`EXIT_STEPS` in colliders.glsl).
const EXIT_STEPS: usize = 24;

/// `caught_response`: Latta eq. 7, the way out of a collider a particle is caught in.
fn caught_response(v: Vec3, n: Vec3) -> Vec3 {
    let vn = v.dot(n);
    if vn < 0.0 {
        v - 2.0 * vn * n
    } else {
        v
    }
}

/// GLSL's `mix(x, y, a) = x (1 - a) + y a`.
fn mix(x: Vec3, y: Vec3, a: f32) -> Vec3 {
    x * (1.0 - a) + y * a
}

/// `box_distance`: exact distance outside a solid axis-aligned box; inside, the distance to the
/// nearest face (negative).
pub(super) fn box_distance(lo: Vec3, hi: Vec3, p: Vec3) -> (f32, Vec3) {
    let c = 0.5 * (lo + hi);
    let h = 0.5 * (hi - lo);
    let rel = p - c;
    let q = rel.abs() - h;
    let sign = |r: f32| if r < 0.0 { -1.0 } else { 1.0 };
    let s = Vec3::new(sign(rel.x), sign(rel.y), sign(rel.z));
    if q.x.max(q.y.max(q.z)) > 0.0 {
        let o = q.max(Vec3::ZERO);
        let d = o.length();
        return (d, s * o / d);
    }
    if q.x >= q.y && q.x >= q.z {
        return (q.x, Vec3::new(s.x, 0.0, 0.0));
    }
    if q.y >= q.z {
        return (q.y, Vec3::new(0.0, s.y, 0.0));
    }
    (q.z, Vec3::new(0.0, 0.0, s.z))
}
