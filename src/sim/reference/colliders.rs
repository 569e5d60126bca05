//! Colliders of the twin: `glsl/sim/colliders.glsl`.

use glam::{Vec2, Vec3};

use super::{Collider, Events, Reference, Shape, SKIN};
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
        let bounded = |c: &Collider| !matches!(c.shape, Shape::Sdf(..));
        if self.colliders.iter().any(bounded) && !self.bounce_on(*x, vb, xb, ev) {
            ev.bounces_truncated += 1;
        }
    }

    /// `first_entry`: the earliest point where the path `a -> b` enters a plane, sphere or box
    /// while `vb` moves into it: its fraction of the path, the normal there and the response.
    fn first_entry(&self, a: Vec3, b: Vec3, vb: Vec3) -> Option<(f32, Vec3, Vec2)> {
        let mut best: Option<(f32, Vec3, Vec2)> = None;
        let dir = b - a;
        let earlier = |best: &Option<(f32, Vec3, Vec2)>, t: f32| best.is_none_or(|b| t < b.0);
        for c in &self.colliders {
            match &c.shape {
                Shape::Plane(pl) => {
                    let m = pl.truncate();
                    let (d0, d1) = (m.dot(a) - pl.w, m.dot(b) - pl.w);
                    if d0 >= 0.0 && d1 < 0.0 && vb.dot(m) < 0.0 {
                        let t = d0 / (d0 - d1);
                        if earlier(&best, t) {
                            best = Some((t, m, c.resp));
                        }
                    }
                }
                Shape::Sphere(sp) => {
                    let o = a - sp.truncate();
                    let (qa, qb, qc) = (dir.dot(dir), o.dot(dir), o.dot(o) - sp.w * sp.w);
                    let disc = qb * qb - qa * qc;
                    if qc >= 0.0 && qb < 0.0 && qa > 0.0 && disc >= 0.0 {
                        let t = (-qb - disc.sqrt()) / qa;
                        let m = (o + t * dir).normalize();
                        if t <= 1.0 && earlier(&best, t) && vb.dot(m) < 0.0 {
                            best = Some((t, m, c.resp));
                        }
                    }
                }
                Shape::Box(lo, hi) => {
                    if let Some((t, m)) = box_entry(*lo, *hi, a, dir) {
                        if earlier(&best, t) && vb.dot(m) < 0.0 {
                            best = Some((t, m, c.resp));
                        }
                    }
                }
                Shape::Sdf(..) => {}
            }
        }
        best
    }

    /// `bounce_on`: what the replayed path `x -> xb` still enters bounces at the entry point
    /// (the response, then the rest of the step's time along the new velocity), up to
    /// `MAX_BOUNCES` times. False if an entry was still ahead at the bound.
    fn bounce_on(&self, x: Vec3, vb: &mut Vec3, xb: &mut Vec3, ev: &mut Events) -> bool {
        let mut a = x;
        let mut t = self.dt;
        for _ in 0..crate::sim::MAX_BOUNCES {
            let Some((s, n, resp)) = self.first_entry(a, *xb, *vb) else {
                return true;
            };
            a += s * (*xb - a);
            *vb = self.response(*vb, n, resp, ev);
            t *= 1.0 - s;
            *xb = a + *vb * t;
            ev.bounces += 1;
        }
        self.first_entry(a, *xb, *vb).is_none()
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

/// The slab test of `first_entry`: where the path `a + t dir`, t in [0, 1], from outside the box
/// enters it, and the outward normal of the face it enters through.
fn box_entry(lo: Vec3, hi: Vec3, a: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
    if box_distance(lo, hi, a).0 < 0.0 {
        return None;
    }
    let (mut t0, mut t1, mut axis) = (0.0f32, 1.0f32, None);
    for k in 0..3 {
        if dir[k] == 0.0 {
            if a[k] < lo[k] || a[k] > hi[k] {
                return None;
            }
            continue;
        }
        let u0 = (lo[k] - a[k]) / dir[k];
        let u1 = (hi[k] - a[k]) / dir[k];
        if u0.min(u1) >= t0 {
            t0 = u0.min(u1);
            axis = Some(k);
        }
        t1 = t1.min(u0.max(u1));
    }
    let k = axis?;
    if t0 > t1 {
        return None;
    }
    let mut m = Vec3::ZERO;
    m[k] = if dir[k] > 0.0 { -1.0 } else { 1.0 };
    Some((t0, m))
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
