//! Sprite attributes from the relative age and a random number (Latta §3.4.6: "computed inside the
//! vertex shader from the particle type parameters ... Some of them take into account the
//! relative age of the particle or a pseudo-random function"): size over life and the rotation.
//! The CPU twins of `size_scale`, `second_random` and `sprite_angle` in
//! `glsl/render/sprite.glsl`.

/// A sprite's size over its life: four points (relative age, scale), ages ascending from 0 to 1,
/// linear between. A scene's two or three points are padded by repeating the last.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SizeCurve {
    /// Relative ages of the four points.
    pub ages: [f32; 4],
    /// Scale (times the sprite's size) at each point.
    pub scales: [f32; 4],
}

impl Default for SizeCurve {
    /// A constant 1.
    fn default() -> Self {
        SizeCurve {
            ages: [0.0, 1.0, 1.0, 1.0],
            scales: [1.0; 4],
        }
    }
}

impl SizeCurve {
    /// The curve of a scene's `size_over_life` points ([relative age, scale]; validation asks
    /// for two to four); empty or malformed: the constant 1.
    pub fn from_points(points: &[[f32; 2]]) -> Self {
        if !(2..=4).contains(&points.len()) {
            return SizeCurve::default();
        }
        let last = points[points.len() - 1];
        let at = |i: usize| points.get(i).copied().unwrap_or(last);
        SizeCurve {
            ages: std::array::from_fn(|i| at(i)[0]),
            scales: std::array::from_fn(|i| at(i)[1]),
        }
    }

    /// The scale at relative age `age`: on the segment `age` falls on (as the colour keyframes
    /// pick theirs), linear between its ends.
    pub fn eval(&self, age: f32) -> f32 {
        let a = self.ages;
        let k = if age < a[1] {
            0
        } else if age < a[2] {
            1
        } else {
            2
        };
        let t = ((age - a[k]) / (a[k + 1] - a[k]).max(1e-6)).clamp(0.0, 1.0);
        self.scales[k] + t * (self.scales[k + 1] - self.scales[k])
    }
}

/// A second random number in [0, 1) derived from the particle's random number `r` (statics.w)
/// by an integer hash of its bits: it picks the rotation speed within its range, independent of
/// the initial angle, and travels with the particle when a sort rearranges the state.
pub fn second_random(r: f32) -> f32 {
    let mut x = r.to_bits() ^ 0x9e37_79b9;
    x ^= x >> 16;
    x = x.wrapping_mul(0x7feb_352d);
    x ^= x >> 15;
    x = x.wrapping_mul(0x846c_a68b);
    x ^= x >> 16;
    (x >> 8) as f32 / 16_777_216.0
}

/// A third random number in [0, 1) from the particle's random number: the hash applied twice.
/// It picks the size within the type's `size_range`.
pub fn third_random(r: f32) -> f32 {
    second_random(second_random(r))
}

/// The random size factor of a particle with random number `r` in `[lo, hi]` (Latta §3.4.6),
/// written `lo + (hi − lo)·t` so that a range [1, 1] is exactly 1.
pub fn random_size(range: [f32; 2], r: f32) -> f32 {
    range[0] + (range[1] - range[0]) * third_random(r)
}

/// The atlas tile a flipbook shows (the thesis §2.3, animated textures): `frames` tiles from
/// `tile` on, wrapping after the atlas's four; at `rate` tiles per second of age `age_s`,
/// looping, or with no rate (0) spread evenly over the relative age `age`.
pub fn flipbook_tile(tile: u32, frames: u32, rate: f32, age: f32, age_s: f32) -> u32 {
    if frames <= 1 {
        return tile.min(3);
    }
    let k = if rate > 0.0 {
        (age_s * rate).floor() as u32 % frames
    } else {
        ((age * frames as f32).floor() as u32).min(frames - 1)
    };
    (tile.min(3) + k) & 3
}

/// The particle's age in seconds: total − remaining life for a mortal particle, else the time
/// since its birth (permanent particles: total life 0 or +inf).
pub fn age_seconds(remaining: f32, total: f32, birth: f32, time: f32) -> f32 {
    if total.is_finite() && total > 0.0 {
        (total - remaining).max(0.0)
    } else {
        (time - birth).max(0.0)
    }
}

/// The sprite's screen-space angle in radians: angle0 = 2π·r, plus speed·age, the speed drawn
/// in `[min, max]` degrees per second by [`second_random`].
pub fn sprite_angle(r: f32, spin_degrees: [f32; 2], age_s: f32) -> f32 {
    let speed = spin_degrees[0] + second_random(r) * (spin_degrees[1] - spin_degrees[0]);
    std::f32::consts::TAU * r + speed.to_radians() * age_s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn size_curve_is_linear_between_its_points() {
        let c = SizeCurve::from_points(&[[0.0, 1.0], [1.0, 3.0]]);
        assert_eq!(c.eval(0.0), 1.0);
        assert!((c.eval(0.5) - 2.0).abs() < 1e-6);
        assert_eq!(c.eval(1.0), 3.0);
        let c = SizeCurve::from_points(&[[0.0, 0.5], [0.2, 2.0], [0.6, 2.0], [1.0, 0.0]]);
        assert!((c.eval(0.1) - 1.25).abs() < 1e-6);
        assert_eq!(c.eval(0.4), 2.0);
        assert!((c.eval(0.8) - 1.0).abs() < 1e-6);
        assert_eq!(c.eval(1.0), 0.0);
        assert_eq!(SizeCurve::from_points(&[]).eval(0.7), 1.0);
    }

    #[test]
    fn second_random_is_uniform_and_deterministic() {
        let mut bins = [0u32; 10];
        for i in 0..10_000 {
            let r = second_random(i as f32 / 10_000.0);
            assert!((0.0..1.0).contains(&r));
            bins[(r * 10.0) as usize] += 1;
        }
        assert!(bins.iter().all(|b| (850..1150).contains(b)), "{bins:?}");
        assert_eq!(second_random(0.25), second_random(0.25));
    }

    #[test]
    fn angle_grows_with_age() {
        assert_eq!(age_seconds(1.0, 3.0, 0.0, 9.0), 2.0);
        assert_eq!(age_seconds(1.0, 0.0, 2.0, 9.0), 7.0);
        assert_eq!(age_seconds(1.0, f32::INFINITY, 2.0, 1.0), 0.0);
        let a = sprite_angle(0.25, [90.0, 90.0], 2.0);
        assert!((a - (std::f32::consts::FRAC_PI_2 + std::f32::consts::PI)).abs() < 1e-5);
    }
}
