//! Emitters that emit (the thesis §2): what the CPU learns of the child emitters, whose births
//! happen in the integration pass (`glsl/sim/child_birth.glsl`) with no read-back per step.

use super::ParticleSim;
use crate::error::Result;

impl ParticleSim {
    /// Births that child texels were asked for while their child still lived (or twice in one
    /// step), summed over every child texel: each keeps its count in velocity.w. One read-back
    /// of the velocity texture; call it once, at the end of a run. 0 without child emitters.
    pub fn dropped_child_births(&self) -> Result<u64> {
        if self.features.children == 0 {
            return Ok(0);
        }
        let Some(v) = self.velocities() else {
            return Ok(0);
        };
        let layout = &self.params.emitters.layout;
        let (start, end) = (layout.parent_slots as usize, layout.used() as usize);
        let data = v.read_f32()?;
        let sum: f64 = (data.chunks(4).take(end).skip(start))
            .map(|t| t[3] as f64)
            .sum();
        Ok(sum.round() as u64)
    }
}
