//! The lookup fields that colliders and forces sample (UberFlow §4.6, Latta eq. 1): a height
//! field (2D), a signed distance field (3D) and a wind flow field (3D). Each is built on the CPU
//! from its scene description and uploaded once to a float texture (except a distance field of
//! a triangle mesh, which is scan-converted on the GPU, one fragment pass per slice: `scan`, with
//! its CPU twin in `mesh`), and sampled in GLSL by
//! `glsl/sim/fields.glsl` with `texelFetch` only: the interpolation is done by hand (no hardware
//! filtering, whose 8-bit interpolation weights would make the GPU disagree with the CPU). Every
//! field has a CPU sampler that is the twin of its GLSL function, with the same arithmetic in the
//! same order, so the two agree up to float rounding (tests/fields.rs).
//!
//! # Conventions (identical for the three fields)
//!
//! - **Nodes.** An axis from `min` to `max` with `n >= 2` nodes has its nodes at
//!   `x_i = min + i (max - min) / (n - 1)`, `i = 0 .. n-1`: the first node lies on `min`, the last
//!   on `max` (node-centred, not cell-centred). Texel `i` of that axis holds the value at `x_i`.
//!   Texel `(i, j)` of the height field is `i` along x and `j` along z; texel `(i, j, k)` of a 3D
//!   field is `(x, y, z)`. Uploads are x-fastest: value `c` of texel `(i, j, k)` is at
//!   `((k ny + j) nx + i) channels + c`.
//! - **Sampling.** A position maps to the continuous grid coordinate
//!   `u = (x - min) / (max - min) * (n - 1)`, clamped to `[0, n - 1]`; it lies between the nodes
//!   `i0 = floor(u)` and `i1 = min(i0 + 1, n - 1)` with the weight `t = u - i0` in `[0, 1)`.
//!   Linear interpolation is `a + t (b - a)`: a sample at a node's grid coordinate (`t = 0`)
//!   returns the node's value bit for bit, and between equal texels it returns that value
//!   exactly (so a region where the field is constant has a gradient of exactly zero, with or
//!   without fused multiply-adds). Bilinear interpolates along x first, then z; trilinear along
//!   x, then y, then z.
//! - **Outside the bounds** the coordinate is clamped per axis: the field continues constant
//!   along each axis from its boundary values (a landscape that goes on flat from its edge
//!   heights; a distance field that stops growing; a wind that keeps its boundary velocity).
//! - Positions must be finite.

mod distance;
mod flow;
mod grid;
mod height;
mod mesh;
mod scan;

pub use distance::DistanceField;
pub use flow::FlowField;
pub use height::HeightField;

/// What the fields' unit tests share.
#[cfg(test)]
mod test_util {
    use glam::Vec3;

    /// splitmix64: deterministic test points.
    pub(super) struct Rng(pub(super) u64);
    impl Rng {
        pub(super) fn next(&mut self) -> f32 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            (z >> 40) as f32 / (1u64 << 24) as f32
        }
        pub(super) fn range(&mut self, lo: f32, hi: f32) -> f32 {
            lo + (hi - lo) * self.next()
        }
        pub(super) fn point(&mut self, lo: Vec3, hi: Vec3) -> Vec3 {
            Vec3::new(
                self.range(lo.x, hi.x),
                self.range(lo.y, hi.y),
                self.range(lo.z, hi.z),
            )
        }
    }
}
