//! Colour and opacity over a particle's life (Latta §3.4.6): four keyframes of relative age, in
//! the form the GPU evaluates, and the relative age itself.

use crate::scene::Keyframe;

/// Four keyframes as three linear segments in the GPU's form (Latta §3.4.6: "converted into a
/// form for efficient GPU evaluation"): on segment k, colour = offset[k] + age · slope[k]. The
/// CPU twin of `keyframe_color` in `glsl/render/keyframes.glsl`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyframeRamp {
    /// Keyframe ages.
    pub ages: [f32; 4],
    /// Per segment, the colour its line has at age 0.
    pub offset: [[f32; 4]; 3],
    /// Per segment, the change of colour per unit of age.
    pub slope: [[f32; 4]; 3],
}

impl KeyframeRamp {
    /// Converts keyframes (ages ascending). A segment of zero length is never selected (the
    /// next one starts at the same age); it gets slope 0 and its end colour.
    pub fn new(keys: &[Keyframe; 4]) -> Self {
        let mut offset = [[0f32; 4]; 3];
        let mut slope = [[0f32; 4]; 3];
        for k in 0..3 {
            let (a0, a1) = (keys[k].age, keys[k + 1].age);
            for c in 0..4 {
                let (c0, c1) = (keys[k].rgba[c], keys[k + 1].rgba[c]);
                if a1 > a0 {
                    slope[k][c] = (c1 - c0) / (a1 - a0);
                    offset[k][c] = c0 - a0 * slope[k][c];
                } else {
                    offset[k][c] = c1;
                }
            }
        }
        KeyframeRamp {
            ages: [keys[0].age, keys[1].age, keys[2].age, keys[3].age],
            offset,
            slope,
        }
    }

    /// The segment `age` falls on: 0 below the second keyframe's age, 1 below the third's, else 2.
    pub fn segment(&self, age: f32) -> usize {
        if age < self.ages[1] {
            0
        } else if age < self.ages[2] {
            1
        } else {
            2
        }
    }

    /// Colour and opacity at relative age `age` (before the intensity).
    pub fn eval(&self, age: f32) -> [f32; 4] {
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

    fn keys(ages: [f32; 4], rgba: [[f32; 4]; 4]) -> [Keyframe; 4] {
        std::array::from_fn(|i| Keyframe {
            age: ages[i],
            rgba: rgba[i],
        })
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
        assert_eq!(r.segment(1.0), 2);
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
