//! Counts non-finite particle state on the GPU, so that garbage is reported instead of rendered
//! silently (docs/numerics.md).
//!
//! A reduction by fragment passes (`glsl/sim/nonfinite.frag`): the first pass marks, for every
//! 4×4 tile of the state, how many live particles (life `w > 0`) have a NaN or infinite component
//! in their position (xyzw) or velocity (xyz), how many are live, how many have a non-finite
//! position, and how many texels hold a NaN life; each further pass sums 4×4 tiles of the previous
//! level into an RGBA32F target a sixteenth of its size, down to 1×1, and one texel is read back.
//! Dead particles (`w ≤ 0`, parked at `+inf` by design) are not counted. Every test is on the bits
//! (`floatBitsToUint`): drivers may fold comparisons with NaN.
//!
//! Counts are floats on the GPU, exact up to 2^24 per texel: for states of more than 2^24
//! particles the reduction stops at the last level whose texels cover at most 2^24 particles and
//! the CPU adds up those few texels in `u64`.
//!
//! ```no_run
//! # use texflow::{gl::Context, scene, sim::{ParticleSim, nonfinite::NonFiniteCounter}};
//! # let ctx = Context::new(0)?;
//! let sim = ParticleSim::new(&ctx, &scene::load("fountain")?, 1)?;
//! let counter = NonFiniteCounter::for_sim(&ctx, &sim)?;
//! let c = counter.count_sim(&sim)?;
//! if c.non_finite > 0 {
//!     eprintln!("{} of {} live particles are NaN or infinite", c.non_finite, c.live);
//! }
//! # Ok::<(), texflow::Error>(())
//! ```

use glam::IVec2;

use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, Program, Sampled, Texture, TextureDesc,
    TextureFormat, Uniform, FULLSCREEN_VERTEX,
};

use super::ParticleSim;

/// Side of the tile each reduction pass sums.
pub const BLOCK: u32 = 4;

/// Largest count a float texel holds exactly.
const EXACT: u64 = 1 << 24;

/// What one count found.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct NonFiniteCount {
    /// Live particles with a NaN or infinite component in position (xyzw) or velocity (xyz).
    pub non_finite: u64,
    /// Live particles (life `w > 0`, `+inf` included).
    pub live: u64,
    /// Of `non_finite`, those whose position (xyzw) is non-finite.
    pub non_finite_position: u64,
    /// Texels whose life is NaN: neither alive nor dead (not in `live`).
    pub nan_life: u64,
}

impl NonFiniteCount {
    /// Of `non_finite`, those whose position is finite but whose velocity is not.
    pub fn velocity_only(&self) -> u64 {
        self.non_finite - self.non_finite_position
    }

    /// Nothing non-finite and no NaN life.
    pub fn is_clean(&self) -> bool {
        self.non_finite == 0 && self.nan_life == 0
    }

    /// The same count made on the CPU from read-back state (4 floats per texel each;
    /// `velocities` may be empty): the twin of the GPU passes, for tests and for callers that
    /// read the state back anyway.
    pub fn of_slices(positions: &[f32], velocities: &[f32]) -> Self {
        let non_finite = |x: f32| x.to_bits() & 0x7f80_0000 == 0x7f80_0000;
        let mut c = NonFiniteCount::default();
        for (i, p) in positions.chunks_exact(4).enumerate() {
            let w = p[3].to_bits();
            if w != 0 && w <= 0x7f80_0000 {
                c.live += 1;
                let bad_p = p.iter().any(|&x| non_finite(x));
                let bad_v = velocities
                    .get(i * 4..i * 4 + 3)
                    .is_some_and(|v| v.iter().any(|&x| non_finite(x)));
                c.non_finite += (bad_p || bad_v) as u64;
                c.non_finite_position += bad_p as u64;
            } else if p[3].is_nan() {
                c.nan_life += 1;
            }
        }
        c
    }
}

/// The reduction passes and their targets for one state size.
#[derive(Debug)]
pub struct NonFiniteCounter {
    width: u32,
    height: u32,
    levels: Vec<Framebuffer>,
    mark: Program,
    mark_velocity: Program,
    /// Marking programs with user states (`[[state]]`), by their count, built when first used.
    mark_extra: std::cell::RefCell<Vec<(usize, Program)>>,
    sum: Program,
    pass: FullscreenPass,
    ctx: Context,
}

fn reduced(n: u32) -> u32 {
    n.div_ceil(BLOCK)
}

/// Sizes of the reduction targets for a `width`×`height` state: each a `BLOCK`-th of the one
/// before on each side, down to 1×1, or to the last level whose texels cover at most 2^24 state
/// texels (float counts stay exact).
pub fn level_sizes(width: u32, height: u32) -> Vec<(u32, u32)> {
    let mut sizes = vec![(reduced(width), reduced(height))];
    // State texels one texel of the last level covers.
    let mut cover = (BLOCK * BLOCK) as u64;
    while sizes.last() != Some(&(1, 1)) && cover * (BLOCK * BLOCK) as u64 <= EXACT {
        let (w, h) = sizes[sizes.len() - 1];
        sizes.push((reduced(w), reduced(h)));
        cover *= (BLOCK * BLOCK) as u64;
    }
    sizes
}

impl NonFiniteCounter {
    /// Builds the passes and the targets of the reduction for `width`×`height` state textures.
    pub fn new(ctx: &Context, width: u32, height: u32) -> Result<Self> {
        crate::gl::check_size(ctx, "non-finite counter state", width, height)?;
        let levels = level_sizes(width, height)
            .iter()
            .enumerate()
            .map(|(i, &(w, h))| {
                let label = format!("nonfinite:{i}");
                let t = Texture::new(
                    ctx,
                    TextureDesc {
                        width: w,
                        height: h,
                        format: TextureFormat::Rgba32F,
                        label: &label,
                    },
                )?;
                Framebuffer::new(ctx, &label, vec![t])
            })
            .collect::<Result<Vec<_>>>()?;
        let program = |extra: &[&str]| -> Result<Program> {
            let mut d: Defines = vec![
                ("BLOCK".into(), BLOCK.to_string()),
                ("N_EXTRA".into(), "0".into()),
            ];
            d.extend(extra.iter().map(|k| ((*k).to_owned(), "1".to_owned())));
            Program::new(ctx, FULLSCREEN_VERTEX, "sim/nonfinite.frag", &d)
        };
        let counter = NonFiniteCounter {
            width,
            height,
            levels,
            mark: program(&["MARK"])?,
            mark_velocity: program(&["MARK", "VELOCITY"])?,
            mark_extra: Default::default(),
            sum: program(&[])?,
            pass: FullscreenPass::new(ctx)?,
            ctx: ctx.clone(),
        };
        ctx.check_error("building the non-finite counter")?;
        Ok(counter)
    }

    /// A counter sized for `sim`'s state.
    pub fn for_sim(ctx: &Context, sim: &ParticleSim) -> Result<Self> {
        let s = sim.size();
        Self::new(ctx, s.x, s.y)
    }

    /// The state size this counter is built for.
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Reduction passes one count runs (the marking pass included).
    pub fn passes(&self) -> usize {
        self.levels.len()
    }

    /// Counts the live particles of `positions` (xyz, life) with a non-finite component there or
    /// in `velocities` (xyz; Verlet's previous positions serve as well). Runs the reduction
    /// passes and reads back one texel (a few for states beyond 2^24 particles).
    pub fn count(
        &self,
        positions: &Texture,
        velocities: Option<&Texture>,
    ) -> Result<NonFiniteCount> {
        self.count_with(positions, velocities, &[])
    }

    /// [`count`](Self::count) with up to 4 more textures of the state, the user's states
    /// (`[[state]]`), all four components of which must be finite too (and, in a half-float
    /// texture, below 65504, where llvmpipe clamps an overflow): a live particle counts once in
    /// `non_finite` whichever of its textures is not finite.
    pub fn count_with(
        &self,
        positions: &Texture,
        velocities: Option<&Texture>,
        extra: &[&Texture],
    ) -> Result<NonFiniteCount> {
        if extra.len() > 4 {
            return Err(Error::InvalidInput(
                "the non-finite counter reads at most 4 more state textures".into(),
            ));
        }
        let extras = extra.iter().map(|t| ("a user state", *t));
        for (what, t) in std::iter::once(("positions", positions))
            .chain(velocities.map(|v| ("velocities", v)))
            .chain(extras)
        {
            if (t.width(), t.height()) != (self.width, self.height) {
                return Err(Error::InvalidInput(format!(
                    "non-finite counter built for {}x{} state, {what} are {}x{}",
                    self.width,
                    self.height,
                    t.width(),
                    t.height()
                )));
            }
        }
        let key = self.build_mark(velocities.is_some(), extra)?;
        let built = self.mark_extra.borrow();
        let mark = match key {
            None if velocities.is_some() => &self.mark_velocity,
            None => &self.mark,
            Some(key) => &built.iter().find(|(k, _)| *k == key).expect("built").1,
        };
        let mut textures: Vec<(&str, Sampled)> = vec![("u_src", positions.into())];
        textures.extend(velocities.map(|v| ("u_velocity", v.into())));
        let names = ["u_extra0", "u_extra1", "u_extra2", "u_extra3"];
        textures.extend(names.iter().zip(extra).map(|(n, t)| (*n, (*t).into())));
        let size =
            |w: u32, h: u32| [("u_src_size", Uniform::IVec2(IVec2::new(w as i32, h as i32)))];
        let first = &self.levels[0];
        self.pass
            .draw(mark, &textures, &size(self.width, self.height), first);
        for pair in self.levels.windows(2) {
            let (src, dst) = (&pair[0], &pair[1]);
            let from = [("u_src", src.only_texture().into())];
            self.pass
                .draw(&self.sum, &from, &size(src.width(), src.height()), dst);
        }
        let last = self.levels[self.levels.len() - 1].only_texture();
        let texels = last.read_f32()?;
        let mut c = NonFiniteCount::default();
        for t in texels.chunks_exact(4) {
            c.non_finite += t[0] as u64;
            c.live += t[1] as u64;
            c.non_finite_position += t[2] as u64;
            c.nan_life += t[3] as u64;
        }
        Ok(c)
    }

    /// Builds the marking program for `extra` user states (none for no extras: the fixed
    /// ones serve) and returns its key in `mark_extra`.
    fn build_mark(&self, velocity: bool, extra: &[&Texture]) -> Result<Option<usize>> {
        let n = extra.len();
        if n == 0 {
            return Ok(None);
        }
        let half: Vec<bool> = (extra.iter())
            .map(|t| t.format() == TextureFormat::Rgba16F)
            .collect();
        let mask: usize = (half.iter().enumerate())
            .map(|(k, h)| (*h as usize) << k)
            .sum();
        let key = n + 8 * velocity as usize + 16 * mask;
        let mut built = self.mark_extra.borrow_mut();
        if !built.iter().any(|(k, _)| *k == key) {
            let mut d: Defines = vec![
                ("BLOCK".into(), BLOCK.to_string()),
                ("MARK".into(), "1".into()),
                ("N_EXTRA".into(), n.to_string()),
            ];
            if velocity {
                d.push(("VELOCITY".into(), "1".into()));
            }
            for k in (0..n).filter(|k| half[*k]) {
                d.push((format!("HALF_{k}"), "1".into()));
            }
            let p = Program::new(&self.ctx, FULLSCREEN_VERTEX, "sim/nonfinite.frag", &d)?;
            built.push((key, p));
        }
        Ok(Some(key))
    }

    /// Counts the current state of `sim`: positions with velocities, or with the previous
    /// positions under Verlet, and the user's states.
    pub fn count_sim(&self, sim: &ParticleSim) -> Result<NonFiniteCount> {
        crate::sim::Simulation::non_finite(sim, self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_shrink_to_one_texel_or_stop_at_the_exact_limit() {
        assert_eq!(level_sizes(1, 1), vec![(1, 1)]);
        assert_eq!(level_sizes(37, 23), vec![(10, 6), (3, 2), (1, 1)]);
        assert_eq!(level_sizes(1, 100), vec![(1, 25), (1, 7), (1, 2), (1, 1)]);
        // 4096^2 = 2^24 particles: down to 1x1, one texel holding at most 2^24.
        assert_eq!(level_sizes(4096, 4096).last(), Some(&(1, 1)));
        // 16384^2 = 2^28: six levels, each last texel covering 4^6 x 4^6 = 2^24 particles.
        let l = level_sizes(16384, 16384);
        assert_eq!(l.len(), 6);
        assert_eq!(l.last(), Some(&(4, 4)));
    }

    #[test]
    fn cpu_twin_counts_live_non_finite_only() {
        let inf = f32::INFINITY;
        let nan = f32::NAN;
        #[rustfmt::skip]
        let pos = [
            0.0, 0.0, 0.0, 1.0,    // live, finite
            inf, inf, inf, 0.0,    // dead at infinity: not counted
            nan, 0.0, 0.0, 1.0,    // live, NaN position
            0.0, 0.0, 0.0, inf,    // live, infinite life: non-finite position
            0.0, 0.0, 0.0, 1.0,    // live, infinite velocity
            1.0, 2.0, 3.0, nan,    // NaN life: lost
            0.0, 0.0, 0.0, -0.0,   // dead
        ];
        let mut vel = vec![0.0f32; pos.len()];
        vel[4 * 4 + 1] = -inf;
        vel[4] = nan; // the dead particle's velocity: ignored
        let c = NonFiniteCount::of_slices(&pos, &vel);
        assert_eq!(
            c,
            NonFiniteCount {
                non_finite: 3,
                live: 4,
                non_finite_position: 2,
                nan_life: 1
            }
        );
        assert_eq!(c.velocity_only(), 1);
        assert!(!c.is_clean());
    }
}
