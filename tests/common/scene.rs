//! Scenes written by the tests, the random states they start from, and their CPU references.

use texflow::scene::{self, SceneFile};
use texflow::Error;

/// Parses a scene the test wrote; a scene error fails the test with the message and the text.
pub fn parse(label: &str, src: &str) -> SceneFile {
    scene::parse(label, src).unwrap_or_else(|e| panic!("{e}\n{src}"))
}

/// A scene of `size` permanent particles at rest (the test sets the state), euler at 0.01 s,
/// with `extra` TOML after the emitter (a `[collisions]` section, forces).
pub fn collide_scene(size: [u32; 2], extra: &str) -> SceneFile {
    parse(
        "test",
        &format!(
            r#"
name = "collide"
integrator = "euler"
[particles]
size = [{}, {}]
[time]
dt = 0.01
[[emitters.initial]]
direction = [0.0, 1.0, 0.0]
speed = [0.0, 0.0]
{extra}
"#,
            size[0], size[1]
        ),
    )
}

/// `n` particles (position, velocity) uniform in the cube [0, extent)³, each velocity component
/// uniform in ±speed/2; the same for the same seed.
pub fn random_gas(n: usize, seed: u32, speed: f32, extent: f32) -> Vec<([f32; 3], [f32; 3])> {
    let mut rng = texflow::sim::emit::Rng::new(seed, 0, 11);
    (0..n)
        .map(|_| {
            let p = [rng.uniform(), rng.uniform(), rng.uniform()].map(|c| c * extent);
            let v = [0; 3].map(|_| (rng.uniform() - 0.5) * speed);
            (p, v)
        })
        .collect()
}

/// Brute force over all pairs: every live particle's number of live others closer than `reach`
/// (positions as read back, 4 floats per texel, life in w).
pub fn brute_counts(x: &[f32], reach: f32) -> Vec<usize> {
    let n = x.len() / 4;
    let live = |i: usize| x[i * 4 + 3] > 0.0 && x[i * 4].is_finite();
    let mut c = vec![0; n];
    for i in 0..n {
        for j in i + 1..n {
            if !(live(i) && live(j)) {
                continue;
            }
            let d2: f32 = (0..3).map(|k| (x[i * 4 + k] - x[j * 4 + k]).powi(2)).sum();
            if d2.sqrt() < reach {
                c[i] += 1;
                c[j] += 1;
            }
        }
    }
    c
}

/// The line, column and message of a scene error; anything else fails the test.
pub fn scene_error(r: texflow::Result<SceneFile>) -> (usize, usize, String) {
    match r {
        Err(Error::Scene {
            line,
            column,
            message,
            ..
        }) => (line, column, message),
        other => panic!("expected a scene error, got {other:?}"),
    }
}

/// splitmix64: deterministic test values.
pub struct Rng(pub u64);

impl Rng {
    /// The next 64 bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1), 24 bits.
    pub fn next(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in 0..n (0 when n is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.next()
    }

    /// Each component uniform in [lo, hi).
    pub fn vec(&mut self, lo: f32, hi: f32) -> glam::Vec3 {
        glam::Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
}
