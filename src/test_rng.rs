//! The unit tests' random numbers: a xorshift generator, deterministic from its seed.

/// Numbers uniform in [0, 1) from `seed` (not 0), 53 bits each.
pub(crate) fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}
