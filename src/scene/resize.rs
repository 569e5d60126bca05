//! `--particles` below a scene's own count, with its look kept: fewer particles drawn at the
//! scene's point size cover a fraction of the frame they used to (`e3` at 64×64 instead of
//! 256×256 drew a nearly black frame), so the point size grows with the square root of the
//! ratio of counts, which keeps the area the particles cover.

use super::schema::{DrawMode, SceneFile};

/// The largest point size the scaling reaches, in pixels (well inside every driver's point size
/// range, which GL guarantees only up to 1 but llvmpipe and desktop GPUs give ≥ 64).
pub const MAX_SCALED_POINT_SIZE: f32 = 64.0;

impl SceneFile {
    /// Sets the state size (`--particles`). When that holds fewer particles than the scene's
    /// own size, `render.point_size` is multiplied by √(own count / new count), up to
    /// [`MAX_SCALED_POINT_SIZE`] (never below the scene's own): the frame stays about as
    /// covered. Not where the drawn size is the physical one (`[collisions]`: the particle's
    /// radius; `[fluid]`: the lattice spacing) or no point is drawn (`mode = "surface"`). At
    /// the scene's own size or above, nothing but the size changes.
    pub fn resize_particles(&mut self, size: [u32; 2]) {
        let count = |s: [u32; 2]| s[0] as f64 * s[1] as f64;
        let (own, new) = (count(self.particles.size), count(size));
        self.particles.size = size;
        let physical = self.collisions.is_some()
            || self.fluid.is_some()
            || self.render.mode == DrawMode::Surface;
        if new < own && new > 0.0 && !physical {
            let p = self.render.point_size;
            let scaled = p * (own / new).sqrt() as f32;
            self.render.point_size = scaled.min(MAX_SCALED_POINT_SIZE.max(p));
        }
    }
}
