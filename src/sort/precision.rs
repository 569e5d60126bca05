//! Identifiers under 24-bit floats (UberFlow §4.3.1).
//!
//! The ATI R300 computed in 24-bit floats: 16 stored mantissa bits and a 7-bit exponent (as the
//! paper states; the widths are parameters here). The emulation rounds every value the sort
//! passes write to that format (`glsl/common/precision.glsl`; [`FloatFormat::round`] is its twin):
//! round to nearest even, overflow to infinity, no denormals.
//!
//! Plain integer identifiers are exact only up to 2^(mantissa+1) (the stored bits plus the hidden
//! one): beyond that, neighbouring particles share an identifier and the rearrangement duplicates
//! some and loses others. The paper's enumeration uses 2^mantissa equally spaced values in each
//! of the binades [2^s, 2^(s+1)), s = 0, 1, ...: 16 binades give 2^20 distinct values, kept in
//! ascending row-major order in a look-up texture ([`id_table`]); [`decode_id`] finds the binade
//! by successive subtraction, as the paper does, and then the index inside it.

/// A binary floating-point format with `mantissa_bits` stored bits and `exponent_bits` bits of
/// exponent (IEEE-like bias, no denormals).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct FloatFormat {
    /// Stored mantissa bits (the hidden bit not counted).
    pub mantissa_bits: u32,
    /// Exponent bits.
    pub exponent_bits: u32,
}

/// The ATI R300's 24-bit float as UberFlow states it: 16-bit mantissa, 7-bit exponent.
pub const R300: FloatFormat = FloatFormat {
    mantissa_bits: 16,
    exponent_bits: 7,
};

impl FloatFormat {
    /// The exponent bias.
    pub fn bias(&self) -> i32 {
        (1 << (self.exponent_bits - 1)) - 1
    }

    /// Rounds `x` to this format (round to nearest even; overflow to ±inf; below the smallest
    /// normal to ±0). NaN and infinities pass through.
    pub fn round(&self, x: f32) -> f32 {
        let u = x.to_bits();
        if (u >> 23) & 0xff == 0xff || self.mantissa_bits >= 23 {
            return x;
        }
        let drop = 23 - self.mantissa_bits;
        let lsb = (u >> drop) & 1;
        let mut r = u.wrapping_add((1 << (drop - 1)) - 1 + lsb);
        r &= !((1u32 << drop) - 1);
        let sign = u & 0x8000_0000;
        let e = ((r >> 23) & 0xff) as i32 - 127;
        if e > self.bias() {
            return f32::from_bits(sign | 0x7f80_0000);
        }
        if e < 1 - self.bias() {
            return f32::from_bits(sign);
        }
        f32::from_bits(r)
    }

    /// The largest n such that every integer in 0..=n is exact in this format.
    pub fn max_exact_integer(&self) -> u64 {
        1 << (self.mantissa_bits + 1)
    }

    /// The `#define`s that make `glsl/common/precision.glsl` emulate this format.
    pub fn defines(&self) -> Vec<(String, String)> {
        vec![
            ("EMULATE_FLOAT".into(), "1".into()),
            ("FLOAT_MANTISSA".into(), self.mantissa_bits.to_string()),
            ("FLOAT_EXPONENT".into(), self.exponent_bits.to_string()),
        ]
    }
}

/// The paper's identifiers for particles `0..n`: 2^mantissa values per binade, binades from
/// [1, 2) upwards. Every value is exact in `format`, and the table ascends.
pub fn id_table(n: usize, format: &FloatFormat) -> Vec<f32> {
    let m = format.mantissa_bits;
    (0..n as u64)
        .map(|j| {
            let (s, t) = (j >> m, j & ((1 << m) - 1));
            (2f64.powi(s as i32) * (1.0 + t as f64 / 2f64.powi(m as i32))) as f32
        })
        .collect()
}

/// Inverts [`id_table`]: the particle index of identifier `value` (the paper's decode: subtract
/// the width of each binade until the rest falls inside one, then divide by its spacing).
pub fn decode_id(value: f32, format: &FloatFormat) -> u32 {
    let m = format.mantissa_bits;
    let mut rest = value - 1.0;
    let mut s = 0u32;
    let mut width = 1.0f32;
    while rest >= width && s < 126 {
        rest -= width;
        width *= 2.0;
        s += 1;
    }
    let spacing = width / (1u64 << m) as f32;
    (s << m) + (rest / spacing) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_matches_the_format() {
        let f = R300;
        // 16 stored bits: 1 + 2^-16 is exact, 1 + 2^-17 is a tie and rounds to even (1.0).
        assert_eq!(f.round(1.0 + 2f32.powi(-16)), 1.0 + 2f32.powi(-16));
        assert_eq!(f.round(1.0 + 2f32.powi(-17)), 1.0);
        assert_eq!(
            f.round(1.0 + 3.0 * 2f32.powi(-17)),
            1.0 + 2.0 * 2f32.powi(-16)
        );
        assert_eq!(f.round(-3.0), -3.0);
        // Exponent range: bias 63.
        assert_eq!(f.round(2f32.powi(64)), f32::INFINITY);
        assert_eq!(f.round(-(2f32.powi(64))), f32::NEG_INFINITY);
        assert_eq!(f.round(2f32.powi(-63)), 0.0);
        assert_eq!(f.round(2f32.powi(63)), 2f32.powi(63));
        assert!(f.round(f32::NAN).is_nan());
        // Integers are exact up to 2^17 and collide above.
        assert_eq!(f.max_exact_integer(), 1 << 17);
        assert_eq!(f.round(131071.0), 131071.0);
        assert_eq!(f.round(131073.0), 131072.0);
    }

    #[test]
    fn plain_ids_collide_beyond_the_mantissa_and_table_ids_do_not() {
        let f = R300;
        let n = 1usize << 20;
        let distinct = |v: Vec<f32>| {
            let mut b: Vec<u32> = v.into_iter().map(f32::to_bits).collect();
            b.sort_unstable();
            b.dedup();
            b.len()
        };
        let plain: Vec<f32> = (0..n).map(|i| f.round(i as f32)).collect();
        let plain_distinct = distinct(plain);
        assert!(plain_distinct < n, "plain ids should collide");
        // Exactly 2^17 + 1 integers (0..=2^17) survive, then one in 2^k per binade above.
        assert_eq!(
            distinct((0..=(1usize << 17)).map(|i| f.round(i as f32)).collect()),
            (1 << 17) + 1
        );
        let table = id_table(n, &f);
        assert!(
            table.iter().all(|&v| f.round(v) == v),
            "table values are exact in the format"
        );
        assert!(table.windows(2).all(|w| w[0] < w[1]));
        assert_eq!(distinct(table.clone()), n);
        for (j, &v) in table.iter().enumerate() {
            assert_eq!(decode_id(v, &f) as usize, j);
        }
    }
}
