//! Colour and opacity over a particle's life (Latta §3.4.6, which uses four): 1 to
//! [`MAX_KEYFRAMES`] keyframes of relative age, in the form the GPU evaluates, and the relative
//! age itself.

use crate::scene::Keyframe;
pub use crate::scene::MAX_KEYFRAMES;

/// Keyframes as linear segments in the GPU's form (Latta §3.4.6: "converted into a form for
/// efficient GPU evaluation"): on segment k, colour = `offset[k] + age · slope[k]`. Fewer than
/// [`MAX_KEYFRAMES`] keyframes are padded with copies of the last; before the first keyframe's
/// age the colour is the first's, from the last's age on it is the last's. The CPU twin of
/// `keyframe_color` in `glsl/render/keyframes.glsl`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyframeRamp {
    /// Keyframe ages, padded with the last.
    pub ages: [f32; MAX_KEYFRAMES],
    /// Per segment, the colour its line has at age 0.
    pub offset: [[f32; 4]; MAX_KEYFRAMES],
    /// Per segment, the change of colour per unit of age.
    pub slope: [[f32; 4]; MAX_KEYFRAMES],
}

impl KeyframeRamp {
    /// Converts 1 to [`MAX_KEYFRAMES`] keyframes (ages ascending; more are ignored, none is
    /// white). Segment k runs from keyframe k to k + 1; one of zero length is never selected
    /// (the next starts at the same age) and gets slope 0 and its end colour; the last segment
    /// holds the last colour.
    pub fn new(keys: &[Keyframe]) -> Self {
        let n = keys.len().clamp(1, MAX_KEYFRAMES);
        let key = |i: usize| match keys.get(i.min(n - 1)) {
            Some(k) => (k.age, k.rgba),
            None => (0.0, [1.0; 4]),
        };
        let mut offset = [[0f32; 4]; MAX_KEYFRAMES];
        let mut slope = [[0f32; 4]; MAX_KEYFRAMES];
        for k in 0..MAX_KEYFRAMES {
            let (a0, c0) = key(k);
            let (a1, c1) = key(k + 1);
            for c in 0..4 {
                if k + 1 < MAX_KEYFRAMES && a1 > a0 {
                    slope[k][c] = (c1[c] - c0[c]) / (a1 - a0);
                    offset[k][c] = c0[c] - a0 * slope[k][c];
                } else {
                    offset[k][c] = c1[c];
                }
            }
        }
        KeyframeRamp {
            ages: std::array::from_fn(|i| key(i).0),
            offset,
            slope,
        }
    }

    /// The segment `age` falls on: how many keyframes after the first have an age at or below
    /// it.
    pub fn segment(&self, age: f32) -> usize {
        self.ages[1..].iter().filter(|a| age >= **a).count()
    }

    /// Colour and opacity at relative age `age` (before the intensity).
    pub fn eval(&self, age: f32) -> [f32; 4] {
        let age = age.max(self.ages[0]);
        let k = self.segment(age);
        std::array::from_fn(|c| self.offset[k][c] + age * self.slope[k][c])
    }
}

/// Relative age from the remaining life and the total life, as the shader computes it.
pub fn relative_age(remaining: f32, total: f32) -> f32 {
    if !(total.is_finite() && total > 0.0) {
        return 0.0;
    }
    (1.0 - remaining / total).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn keys(ages: [f32; 4], rgba: [[f32; 4]; 4]) -> Vec<Keyframe> {
        (0..4)
            .map(|i| Keyframe {
                age: ages[i],
                rgba: rgba[i],
            })
            .collect()
    }

    fn close(a: [f32; 4], b: [f32; 4]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-5)
    }

    #[test]
    fn ramp_hits_every_keyframe_and_is_linear_between() {
        let k = keys(
            [0.0, 0.2, 0.7, 1.0],
            [
                [1.0, 0.9, 0.5, 1.0],
                [1.0, 0.5, 0.1, 0.8],
                [0.4, 0.1, 0.0, 0.5],
                [0.1, 0.1, 0.1, 0.0],
            ],
        );
        let r = KeyframeRamp::new(&k);
        for key in &k {
            assert!(close(r.eval(key.age), key.rgba), "at {}", key.age);
        }
        // Midpoints of the three segments.
        let mid = |a: usize, t: f32| -> [f32; 4] {
            std::array::from_fn(|c| k[a].rgba[c] + t * (k[a + 1].rgba[c] - k[a].rgba[c]))
        };
        assert!(close(r.eval(0.1), mid(0, 0.5)));
        assert!(close(r.eval(0.45), mid(1, 0.5)));
        assert!(close(r.eval(0.85), mid(2, 0.5)));
        assert!(close(r.eval(0.325), mid(1, 0.25)));
        assert_eq!(r.segment(0.0), 0);
        assert_eq!(r.segment(0.2), 1);
        assert_eq!(r.segment(0.69), 1);
        assert_eq!(r.segment(0.7), 2);
        assert!(close(r.eval(1.0), k[3].rgba));
    }

    /// Linear interpolation between the keyframes around `age`, held outside them: the
    /// definition, written without segments.
    fn lerp(keys: &[Keyframe], age: f32) -> [f32; 4] {
        if age <= keys[0].age {
            return keys[0].rgba;
        }
        for w in keys.windows(2) {
            if age < w[1].age {
                let t = (age - w[0].age) / (w[1].age - w[0].age);
                return std::array::from_fn(|c| w[0].rgba[c] + t * (w[1].rgba[c] - w[0].rgba[c]));
            }
        }
        keys[keys.len() - 1].rgba
    }

    #[test]
    fn any_number_of_keyframes_interpolates_them() {
        for n in 1..=MAX_KEYFRAMES {
            // Ages spread over [0.1, 0.9] (held before and after), colours varying per key.
            let keys: Vec<Keyframe> = (0..n)
                .map(|i| Keyframe {
                    age: if n == 1 {
                        0.4
                    } else {
                        0.1 + 0.8 * i as f32 / (n - 1) as f32
                    },
                    rgba: [i as f32, (i * i) as f32 * 0.1, 1.0 - 0.1 * i as f32, 0.5],
                })
                .collect();
            let r = KeyframeRamp::new(&keys);
            for step in 0..=100 {
                let age = step as f32 / 100.0;
                assert!(
                    close(r.eval(age), lerp(&keys, age)),
                    "{n} keyframes, age {age}: {:?} vs {:?}",
                    r.eval(age),
                    lerp(&keys, age)
                );
            }
        }
    }

    #[test]
    fn zero_length_segments_are_skipped() {
        let k = keys(
            [0.0, 0.0, 1.0, 1.0],
            [
                [9.0; 4],
                [1.0, 0.0, 0.0, 1.0],
                [0.0, 0.0, 1.0, 0.0],
                [7.0; 4],
            ],
        );
        let r = KeyframeRamp::new(&k);
        assert!(r.slope.iter().flatten().all(|v| v.is_finite()));
        assert!(close(r.eval(0.0), [1.0, 0.0, 0.0, 1.0]));
        assert!(close(r.eval(0.5), [0.5, 0.0, 0.5, 0.5]));
        // Age 1 falls on the zero-length last segment: its end colour.
        assert!(close(r.eval(1.0), [7.0; 4]));
    }

    #[test]
    fn relative_age_of_permanent_and_mortal_particles() {
        assert_eq!(relative_age(2.0, 4.0), 0.5);
        assert_eq!(relative_age(4.0, 4.0), 0.0);
        assert_eq!(relative_age(5.0, 4.0), 0.0);
        assert_eq!(relative_age(0.0, 4.0), 1.0);
        assert_eq!(relative_age(3.0, 0.0), 0.0);
        assert_eq!(relative_age(3.0, f32::INFINITY), 0.0);
        assert_eq!(relative_age(3.0, f32::NAN), 0.0);
    }
}
