//! Emitter values that change over the run (the thesis §5.2: a fire that flickers by varying its
//! emitter's direction and speed): a constant, or a curve of keyframes with an optional periodic
//! and noise term. The one place curves are read and evaluated: the GPU's per-step uniforms,
//! the CPU allocator's births and the CPU engine all call [`Animated::at`].
//!
//! In TOML a value is a plain number (or array) as before, or a table:
//! `speed = { keys = [[0.0, 1.0], [2.0, 3.0]], interpolation = "smooth",
//! periodic = { amplitude = 0.2, period = 0.5 }, noise = { amplitude = 0.1, frequency = 4.0,
//! seed = 7 } }`. A key is `[time, value]`, its value a number or an array of the constant's
//! length.

use std::fmt;
use std::marker::PhantomData;

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

/// A value of type `T` that is a constant or a [`Curve`] over the emitter's time (seconds).
#[derive(Debug, Clone, PartialEq)]
pub enum Animated<T> {
    /// The same value all the time.
    Constant(T),
    /// Keyframes and terms evaluated at each time.
    Curve(Curve),
}

/// A value a curve can give: a number, a range [min, max] or a vector [x, y, z].
pub trait CurveValue: Copy + fmt::Debug + PartialEq {
    /// Components of the value.
    const LEN: usize;
    /// The components of one key move together (a range: min and max share their periodic and
    /// noise terms, so that min <= max holds wherever it holds at the keys).
    const SHARED: bool;
    /// What a key's value must look like, for errors (`a number`, `[x, y, z]`).
    const WHAT: &'static str;
    /// The value from its components: `LEN` of them, or one for every component of a range.
    fn from_components(c: &[f32]) -> Option<Self>;
    /// The components.
    fn components(&self) -> Vec<f32>;
}

impl CurveValue for f32 {
    const LEN: usize = 1;
    const SHARED: bool = true;
    const WHAT: &'static str = "a number";
    fn from_components(c: &[f32]) -> Option<Self> {
        (c.len() == 1).then(|| c[0])
    }
    fn components(&self) -> Vec<f32> {
        vec![*self]
    }
}

impl CurveValue for [f32; 2] {
    const LEN: usize = 2;
    const SHARED: bool = true;
    const WHAT: &'static str = "a number or [min, max]";
    fn from_components(c: &[f32]) -> Option<Self> {
        match c {
            [v] => Some([*v, *v]),
            [lo, hi] => Some([*lo, *hi]),
            _ => None,
        }
    }
    fn components(&self) -> Vec<f32> {
        self.to_vec()
    }
}

impl CurveValue for [f32; 3] {
    const LEN: usize = 3;
    const SHARED: bool = false;
    const WHAT: &'static str = "[x, y, z]";
    fn from_components(c: &[f32]) -> Option<Self> {
        c.try_into().ok()
    }
    fn components(&self) -> Vec<f32> {
        self.to_vec()
    }
}

impl CurveValue for [f32; 4] {
    const LEN: usize = 4;
    const SHARED: bool = false;
    const WHAT: &'static str = "[r, g, b, a]";
    fn from_components(c: &[f32]) -> Option<Self> {
        c.try_into().ok()
    }
    fn components(&self) -> Vec<f32> {
        self.to_vec()
    }
}

/// Keyframes `[time, value]` (times ascending) and optional periodic and noise terms added to
/// every component. Before the first key the curve holds the first value, after the last the
/// last.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Curve {
    /// `[time, value]` pairs, times in seconds, ascending; value a number or an array.
    pub keys: Vec<(f32, Components)>,
    /// Between keys: `linear` or `smooth` (smoothstep, which stays within the two keys).
    #[serde(default)]
    pub interpolation: Interpolation,
    /// `amplitude · sin(2π (t / period + phase))`.
    pub periodic: Option<Periodic>,
    /// `amplitude · n(t · frequency)`, with `n` a 1-D value noise in [-1, 1] of `seed`.
    pub noise: Option<Noise>,
}

/// A key's value or an amplitude: one number, or one per component.
#[derive(Debug, Clone, PartialEq)]
pub struct Components(pub Vec<f32>);

impl Components {
    /// Component `i` (one number stands for every component).
    pub fn get(&self, i: usize) -> f32 {
        component(&self.0, i)
    }
}

/// How a curve runs between two keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Interpolation {
    /// A straight line.
    #[default]
    Linear,
    /// Smoothstep `3u² - 2u³`: flat at every key, never beyond the two keys' values.
    Smooth,
}

/// A sine added to the keys.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Periodic {
    /// Peak deviation: a number, or one per component.
    pub amplitude: Components,
    /// Seconds per cycle, above 0.
    pub period: f32,
    /// Fraction of a cycle at time 0. Default 0.
    #[serde(default)]
    pub phase: f32,
}

/// Deterministic 1-D value noise added to the keys: random values in [-1, 1] at every
/// `1 / frequency` seconds, smoothstep between, times `amplitude` (so never beyond it).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Noise {
    /// Largest deviation: a number, or one per component.
    pub amplitude: Components,
    /// Random values per second, above 0.
    pub frequency: f32,
    /// Seed of the random values. Default 0.
    #[serde(default)]
    pub seed: u32,
}

/// A key time, value or amplitude, if it has a component `i` (one number stands for all).
fn component(c: &[f32], i: usize) -> f32 {
    if c.len() == 1 {
        c[0]
    } else {
        c.get(i).copied().unwrap_or(0.0)
    }
}

fn hash(v: u32) -> u32 {
    // PCG (as glsl/common/rng.glsl): well mixed for consecutive lattice points.
    let state = v.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277_803_737);
    (word >> 22) ^ word
}

fn smoothstep(u: f32) -> f32 {
    u * u * (3.0 - 2.0 * u)
}

/// 1-D value noise of `seed` at `x`: a random value in [-1, 1] at every integer, smoothstep
/// between. Deterministic and never beyond [-1, 1].
pub fn value_noise(seed: u32, x: f64) -> f32 {
    let cell = x.floor();
    let lattice = |i: f64| {
        let h = hash((i as i64 as u32) ^ hash(seed));
        (h >> 8) as f32 * (2.0 / 16_777_216.0) - 1.0
    };
    let (a, b) = (lattice(cell), lattice(cell + 1.0));
    a + (b - a) * smoothstep((x - cell) as f32)
}

impl Curve {
    /// Component `i` of the keyframes alone at time `t`.
    fn keys_at(&self, t: f32, i: usize) -> f32 {
        let keys = &self.keys;
        let Some(next) = keys.iter().position(|k| k.0 > t) else {
            return keys.last().map_or(0.0, |k| component(&k.1 .0, i));
        };
        if next == 0 {
            return component(&keys[0].1 .0, i);
        }
        let ((t0, a), (t1, b)) = (&keys[next - 1], &keys[next]);
        let u = (t - t0) / (t1 - t0);
        let u = match self.interpolation {
            Interpolation::Linear => u,
            Interpolation::Smooth => smoothstep(u),
        };
        let (a, b) = (component(&a.0, i), component(&b.0, i));
        a + (b - a) * u
    }

    /// The periodic and noise terms of component `i` at `t` (`shared`: every component gets the
    /// noise of component 0).
    fn terms_at(&self, t: f32, i: usize, shared: bool) -> f32 {
        let mut v = 0.0;
        if let Some(p) = &self.periodic {
            let turns = t as f64 / p.period as f64 + p.phase as f64;
            v += component(&p.amplitude.0, i) * (std::f64::consts::TAU * turns).sin() as f32;
        }
        if let Some(n) = &self.noise {
            let seed = n.seed.wrapping_add(if shared { 0 } else { i as u32 });
            v += component(&n.amplitude.0, i) * value_noise(seed, t as f64 * n.frequency as f64);
        }
        v
    }

    /// Component `i` at time `t`.
    pub fn component_at(&self, t: f32, i: usize, shared: bool) -> f32 {
        self.keys_at(t, i) + self.terms_at(t, i, shared)
    }

    /// Bounds [lo, hi] of component `i` over all time: the keys' extremes (linear and smooth
    /// segments stay between their keys) widened by the terms' amplitudes.
    pub fn bounds(&self, i: usize) -> [f32; 2] {
        let values = self.keys.iter().map(|k| component(&k.1 .0, i));
        let lo = values.clone().fold(f32::INFINITY, f32::min);
        let hi = values.fold(f32::NEG_INFINITY, f32::max);
        let reach = self.reach(i);
        [lo - reach, hi + reach]
    }

    /// The most the periodic and noise terms move component `i` from the keys' curve.
    pub fn reach(&self, i: usize) -> f32 {
        let amp = |a: &Components| component(&a.0, i).abs();
        self.periodic.as_ref().map_or(0.0, |p| amp(&p.amplitude))
            + self.noise.as_ref().map_or(0.0, |n| amp(&n.amplitude))
    }

    /// The key values as `T` (validation checked their length; a bad one reads as zeros).
    pub fn key_values<T: CurveValue>(&self) -> Vec<T> {
        let zero = vec![0.0; T::LEN];
        let parse = |c: &Components| T::from_components(&c.0);
        self.keys
            .iter()
            .map(|k| {
                parse(&k.1)
                    .or_else(|| T::from_components(&zero))
                    .expect("zeros fit")
            })
            .collect()
    }

    /// ∫ component 0 dt over [a, b]: exact for the keys and the noise (cubic between their
    /// breakpoints, where Simpson's rule is exact) and for the sine (closed form).
    pub fn integral(&self, a: f64, b: f64) -> f64 {
        if b <= a {
            return 0.0;
        }
        let mut cuts = vec![a, b];
        cuts.extend(
            self.keys
                .iter()
                .map(|k| k.0 as f64)
                .filter(|t| *t > a && *t < b),
        );
        if let Some(n) = &self.noise {
            let f = n.frequency as f64;
            let mut k = (a * f).floor() + 1.0;
            while k / f < b && cuts.len() < 100_000 {
                cuts.push(k / f);
                k += 1.0;
            }
        }
        cuts.sort_by(f64::total_cmp);
        let smooth = |t: f64| {
            let t = t as f32;
            let noise = self.noise.as_ref().map_or(0.0, |n| {
                component(&n.amplitude.0, 0) * value_noise(n.seed, t as f64 * n.frequency as f64)
            });
            (self.keys_at(t, 0) + noise) as f64
        };
        let mut sum = 0.0;
        for w in cuts.windows(2) {
            let (x0, x1) = (w[0], w[1]);
            // Simpson's rule (the curve is continuous at the cuts).
            let mid = 0.5 * (x0 + x1);
            sum += (x1 - x0) / 6.0 * (smooth(x0) + 4.0 * smooth(mid) + smooth(x1));
        }
        if let Some(p) = &self.periodic {
            let (amp, period) = (component(&p.amplitude.0, 0) as f64, p.period as f64);
            let w = std::f64::consts::TAU / period;
            let c = |t: f64| (w * t + std::f64::consts::TAU * p.phase as f64).cos();
            sum += amp / w * (c(a) - c(b));
        }
        sum
    }
}

impl<T: CurveValue> Animated<T> {
    /// The value at time `t` (seconds of the run).
    pub fn at(&self, t: f32) -> T {
        match self {
            Animated::Constant(v) => *v,
            Animated::Curve(c) => {
                let parts: Vec<f32> = (0..T::LEN)
                    .map(|i| c.component_at(t, i, T::SHARED))
                    .collect();
                // Validation checked every key's length: a curve always fills its value.
                T::from_components(&parts).expect("a curve value of the checked length")
            }
        }
    }

    /// The curve, if the value is one.
    pub fn curve(&self) -> Option<&Curve> {
        match self {
            Animated::Constant(_) => None,
            Animated::Curve(c) => Some(c),
        }
    }

    /// Bounds [lo, hi] of every component over all time (a constant's own value).
    pub fn bounds(&self) -> Vec<[f32; 2]> {
        match self {
            Animated::Constant(v) => v.components().iter().map(|x| [*x, *x]).collect(),
            Animated::Curve(c) => (0..T::LEN).map(|i| c.bounds(i)).collect(),
        }
    }
}

impl Animated<f32> {
    /// ∫ value dt over [a, b] seconds (births owed by a rate).
    pub fn integral(&self, a: f64, b: f64) -> f64 {
        match self {
            Animated::Constant(v) => *v as f64 * (b - a).max(0.0),
            Animated::Curve(c) => c.integral(a, b),
        }
    }
}

impl crate::scene::Emitter {
    /// The emitter with every curve replaced by its value at `t` (for code that takes an
    /// emitter's constants, such as the CPU reference's types).
    pub fn frozen(&self, t: f32) -> Self {
        let mut e = self.clone();
        e.rate = e.rate.map(|r| r.at(t).into());
        e.center = e.center.at(t).into();
        e.radius = e.radius.at(t).into();
        e.direction = e.direction.at(t).into();
        e.cone_degrees = e.cone_degrees.at(t).into();
        e.speed = e.speed.at(t).into();
        e.life = e.life_at(t).map(Into::into);
        e
    }

    /// The life range [min, max] of a birth at `t` seconds; `None` for permanent particles.
    pub fn life_at(&self, t: f32) -> Option<[f32; 2]> {
        self.life.as_ref().map(|l| l.at(t))
    }

    /// The longest life any birth can draw (a curve's upper bound); `None` for permanent
    /// particles.
    pub fn longest_life(&self) -> Option<f32> {
        self.life.as_ref().map(|l| l.bounds()[1][1])
    }
}

impl<T: Default> Default for Animated<T> {
    fn default() -> Self {
        Animated::Constant(T::default())
    }
}

impl<T> From<T> for Animated<T> {
    fn from(v: T) -> Self {
        Animated::Constant(v)
    }
}

impl<T: Serialize> Serialize for Animated<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Animated::Constant(v) => v.serialize(s),
            Animated::Curve(c) => c.serialize(s),
        }
    }
}

impl Serialize for Components {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self.0.as_slice() {
            [v] => v.serialize(s),
            v => v.serialize(s),
        }
    }
}

/// Reads a number or an array of numbers.
struct NumbersVisitor;

impl<'de> Visitor<'de> for NumbersVisitor {
    type Value = Vec<f32>;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number or an array of numbers")
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
        Ok(vec![v as f32])
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        Ok(vec![v as f32])
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        Ok(vec![v as f32])
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = Vec::new();
        while let Some(v) = seq.next_element::<f32>()? {
            out.push(v);
        }
        Ok(out)
    }
}

impl<'de> Deserialize<'de> for Components {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(NumbersVisitor).map(Components)
    }
}

/// Reads a constant like the plain key did, or a curve table.
struct AnimatedVisitor<T>(PhantomData<T>);

impl<T: CurveValue> AnimatedVisitor<T> {
    fn constant<E: de::Error>(c: &[f32]) -> Result<Animated<T>, E> {
        T::from_components(c)
            .map(Animated::Constant)
            .ok_or_else(|| {
                E::custom(format!(
                    "expected {}, or a curve {{ keys = [[time, value], ...] }}, found {} numbers",
                    T::WHAT,
                    c.len()
                ))
            })
    }
}

impl<'de, T: CurveValue> Visitor<'de> for AnimatedVisitor<T> {
    type Value = Animated<T>;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(
            f,
            "{}, or a curve {{ keys = [[time, value], ...] }}",
            T::WHAT
        )
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
        Self::constant(&[v as f32])
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        Self::constant(&[v as f32])
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        Self::constant(&[v as f32])
    }
    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        let c = NumbersVisitor.visit_seq(seq)?;
        // An array is the constant's own form only: `[5.0]` is no number, `[1.0]` no range.
        if T::LEN == 1 || c.len() != T::LEN {
            return Err(de::Error::custom(format!(
                "expected {}, or a curve {{ keys = [[time, value], ...] }}, found an array of \
                 {} numbers",
                T::WHAT,
                c.len()
            )));
        }
        Self::constant(&c)
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Self::Value, A::Error> {
        Curve::deserialize(de::value::MapAccessDeserializer::new(map)).map(Animated::Curve)
    }
}

impl<'de, T: CurveValue> Deserialize<'de> for Animated<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(AnimatedVisitor(PhantomData))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curve(src: &str) -> Animated<f32> {
        #[derive(Deserialize)]
        struct Doc {
            v: Animated<f32>,
        }
        toml::from_str::<Doc>(src).unwrap().v
    }

    #[test]
    fn plain_numbers_stay_constants() {
        assert_eq!(curve("v = 2.5"), Animated::Constant(2.5));
        assert_eq!(curve("v = 3"), Animated::Constant(3.0));
    }

    #[test]
    fn keys_interpolate_and_hold_their_ends() {
        let c = curve("v = { keys = [[1.0, 2.0], [3.0, 6.0]] }");
        assert_eq!(
            (c.at(0.0), c.at(1.0), c.at(2.0), c.at(9.0)),
            (2.0, 2.0, 4.0, 6.0)
        );
        let s = curve("v = { keys = [[0.0, 0.0], [4.0, 8.0]], interpolation = \"smooth\" }");
        // Smoothstep at a quarter: 3/16 - 2/64 = 0.15625 of the way.
        assert!((s.at(1.0) - 8.0 * 0.15625).abs() < 1e-6);
    }

    #[test]
    fn integral_matches_the_closed_form() {
        let c = curve(
            "v = { keys = [[0.0, 10.0], [2.0, 30.0]], periodic = { amplitude = 3.0, period = 0.7 } }",
        );
        // Keys: 10 t + 5 t²; sine: -3·0.7/2π·cos(2πt/0.7).
        let f = |t: f64| {
            10.0 * t.min(2.0) + 5.0 * t.min(2.0).powi(2) + 30.0 * (t - 2.0).max(0.0)
                - 3.0 * 0.7 / std::f64::consts::TAU * (std::f64::consts::TAU * t / 0.7).cos()
        };
        for (a, b) in [(0.0, 0.5), (1.9, 2.3), (0.1, 3.0)] {
            assert!((c.integral(a, b) - (f(b) - f(a))).abs() < 1e-4, "{a} {b}");
        }
    }
}
