//! How often the exact search hit its bound, or a path its bound on bounces at colliders: a count
//! kept on the GPU over a whole run and read back once, so that `render` can warn about
//! collisions the search could not see and bounces the colliders did not make.
//!
//! After each pass that flags particles (the exact count pass where a particle's search was
//! truncated, a run of cells holding more than [`EXACT_SCAN`](super::EXACT_SCAN) particles; the
//! integration in the velocity's w for the colliders; the fluid's density pass), a reduction in
//! fragment passes sums the flags: each fragment a block of [`TALLY_BLOCK`]² texels, pass after
//! pass, until the last adds its one sum into a 1×1 R32F target with additive blending
//! (`glsl/collide/tally.frag`). Exact up to 2^24 flagged particles over the run.

use crate::error::Result;
use crate::gl::{
    Blend, Context, DrawState, Framebuffer, FullscreenPass, Program, Texture, TextureDesc,
    TextureFormat, Uniform, FULLSCREEN_VERTEX,
};

/// Texels a side of the block each fragment of the reduction sums.
pub const TALLY_BLOCK: u32 = 4;

/// The sizes of the reduction's intermediate targets for a `width` × `height` source: each a
/// [`TALLY_BLOCK`]th of the last a side (rounded up), until one fits in a block; that one's sum
/// goes into the tally.
pub fn reduction_sizes(width: u32, height: u32) -> Vec<[u32; 2]> {
    let (mut w, mut h) = (width.max(1), height.max(1));
    let mut out = Vec::new();
    while w > TALLY_BLOCK || h > TALLY_BLOCK {
        w = w.div_ceil(TALLY_BLOCK);
        h = h.div_ceil(TALLY_BLOCK);
        out.push([w, h]);
    }
    out
}

/// A tally's line in the pass list: `what` it counts, then how (one wording for every tally,
/// its block the one [`TALLY_BLOCK`]).
pub(crate) fn pass_line(what: &str) -> String {
    format!(
        "{what}, summed by {TALLY_BLOCK}×{TALLY_BLOCK} blocks pass after pass into one texel \
         (read back once, at the end of a run)"
    )
}

/// The running count of flagged particles.
#[derive(Debug)]
pub(crate) struct TruncationTally {
    program: Program,
    target: Framebuffer,
    pass: FullscreenPass,
    /// The flags' texture size.
    size: [u32; 2],
    /// The reduction's intermediate targets ([`reduction_sizes`]).
    levels: Vec<Framebuffer>,
}

impl TruncationTally {
    /// The program each tally draws, for the pass list.
    pub(crate) fn program(&self) -> &Program {
        &self.program
    }

    /// The draws of one tally, for the pass list.
    pub(crate) fn draws(&self) -> u64 {
        self.levels.len() as u64 + 1
    }

    /// A tally at 0 of flags in textures of `size`.
    pub(crate) fn new(ctx: &Context, size: [u32; 2]) -> Result<Self> {
        let target = Framebuffer::new(ctx, "tally", vec![r32f(ctx, "tally", [1, 1])?])?;
        target.clear([0.0; 4]);
        let levels = (reduction_sizes(size[0], size[1]).into_iter())
            .map(|s| Framebuffer::new(ctx, "tally sums", vec![r32f(ctx, "tally sums", s)?]))
            .collect::<Result<Vec<_>>>()?;
        let defines = vec![("TALLY_BLOCK".into(), TALLY_BLOCK.to_string())];
        Ok(TruncationTally {
            program: Program::new(ctx, FULLSCREEN_VERTEX, "collide/tally.frag", &defines)?,
            target,
            pass: FullscreenPass::new(ctx)?,
            size,
            levels,
        })
    }

    /// Adds the particles that `counts` (the exact count pass's output, `n` texels) flags as
    /// truncated.
    pub(super) fn add(&self, counts: &Texture, n: usize) {
        self.add_flags(counts, 1, n);
    }

    /// Adds the first `n` texels of `flags` (a texture of the tally's size, in rows of its
    /// width) whose component `component` is above 1/2. Each level is drawn over the rows that
    /// sum the counted texels alone, and the next reads those rows alone (the rows above keep
    /// sums of an earlier, larger count): a sparse state's few live rows cost a few rows of each
    /// level, not the whole state (NVIDIA H100, `mesh` at 2048²: its integration's 866 live
    /// particles took 0.105 ms with the bounce tally's first level over all 4M texels).
    pub(crate) fn add_flags(&self, flags: &Texture, component: i32, n: usize) {
        let size = [flags.width(), flags.height()];
        debug_assert_eq!(size, self.size, "a tally counts flags of its own size");
        let (mut source, mut at, mut count, mut comp) = (flags, size, n as i32, component);
        // The source's rows holding counted texels (at least one: a level is never empty).
        let mut rows = (n as u32).div_ceil(size[0]).clamp(1, size[1]);
        let uniforms = |at: [u32; 2], count: i32, comp: i32| {
            [
                (
                    "u_size",
                    Uniform::IVec2(glam::IVec2::new(at[0] as i32, at[1] as i32)),
                ),
                ("u_count", Uniform::I32(count)),
                ("u_component", Uniform::I32(comp)),
            ]
        };
        for t in &self.levels {
            let u = uniforms(at, count, comp);
            rows = rows.div_ceil(TALLY_BLOCK).min(t.height());
            let textures = [("u_counts", source.into())];
            self.pass
                .draw_rows(&self.program, &textures, &u, t, 0, rows);
            source = t.only_texture();
            at = [t.width(), t.height()];
            (count, comp) = ((at[0] * rows) as i32, -1);
        }
        let state = DrawState {
            blend: Some(Blend::SUM),
            ..DrawState::REPLACE
        };
        let u = uniforms(at, count, comp);
        (self.pass).draw_with(
            &self.program,
            &[("u_counts", source.into())],
            &u,
            &self.target,
            &state,
        );
    }

    /// The count so far (one read-back of one texel).
    pub(crate) fn total(&self) -> Result<u64> {
        Ok(self.target.only_texture().read_f32()?[0].round() as u64)
    }
}

/// An R32F texture of `size`.
fn r32f(ctx: &Context, label: &'static str, size: [u32; 2]) -> Result<Texture> {
    Texture::new(
        ctx,
        TextureDesc {
            width: size[0],
            height: size[1],
            format: TextureFormat::R32F,
            label,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reduction counts what the CPU counts: random flags (some near the threshold) in
    /// sources of odd sizes, only the first `n` texels (after a tally of every texel), added over
    /// several tallies.
    #[test]
    fn the_reduction_counts_the_flags_of_the_first_texels() {
        let ctx = Context::new(0).expect("an EGL device (llvmpipe in CI)");
        let mut next = crate::test_rng::uniform(0x9e37_79b9_7f4a_7c15);
        for (w, h, n) in [
            (1, 1, 1),
            (9, 1, 9),
            (37, 23, 700),
            (64, 64, 4096),
            (130, 3, 390),
            // A few rows of a tall state: each level's first rows only.
            (64, 64, 100),
            (256, 300, 257),
            (16, 1024, 40),
            (64, 64, 0),
        ] {
            let flags = Texture::new(
                &ctx,
                TextureDesc {
                    width: w,
                    height: h,
                    format: TextureFormat::Rgba32F,
                    label: "flags",
                },
            )
            .unwrap();
            let data: Vec<f32> = (0..w * h * 4).map(|_| next() as f32).collect();
            flags.upload_f32(&data).unwrap();
            let tally = TruncationTally::new(&ctx, [w, h]).unwrap();
            assert_eq!(tally.draws(), reduction_sizes(w, h).len() as u64 + 1);
            let count = |n: u32| (0..n as usize).filter(|&i| data[i * 4 + 2] > 0.5).count();
            let (all, want) = (count(w * h) as u64, count(n) as u64);
            // Every texel first, so that each level's rows above the first n's hold sums that
            // the later tallies must not read.
            tally.add_flags(&flags, 2, (w * h) as usize);
            for _ in 0..3 {
                tally.add_flags(&flags, 2, n as usize);
            }
            assert_eq!(tally.total().unwrap(), all + 3 * want, "{w}×{h}, first {n}");
        }
    }

    #[test]
    fn every_level_shrinks_to_one_block() {
        assert_eq!(reduction_sizes(4, 4), Vec::<[u32; 2]>::new());
        assert_eq!(
            reduction_sizes(1024, 1024),
            vec![[256, 256], [64, 64], [16, 16], [4, 4]]
        );
        assert_eq!(reduction_sizes(37, 5), vec![[10, 2], [3, 1]]);
        assert_eq!(reduction_sizes(4096, 4096).len(), 5);
        for (w, h) in [(1, 1), (9, 1), (1, 4096), (24, 10), (4096, 4096)] {
            let last = reduction_sizes(w, h).last().copied().unwrap_or([w, h]);
            assert!(
                last[0] <= TALLY_BLOCK && last[1] <= TALLY_BLOCK,
                "{w}×{h}: {last:?}"
            );
        }
    }
}
