//! The constraints block: what the relaxation passes (`src/sim/particles/relax.rs`) and their
//! CPU twin (`src/sim/reference/constraints.rs`) read of `[constraints]`, built once.

use glam::Vec3;

use crate::scene::{ConstraintKind, Orbit, RelaxScheme, SceneFile};

/// The relaxation's numbers (the layout itself is `crate::sim::constraints::Layout`).
#[derive(Debug, Clone, PartialEq)]
pub struct Constraints {
    /// `cloth` or `hair`.
    pub kind: ConstraintKind,
    /// Relaxation passes per step.
    pub iterations: u32,
    /// Jacobi or Gauss-Seidel.
    pub scheme: RelaxScheme,
    /// The long-range attachments' pass runs after each iteration's edge passes.
    pub attachments: bool,
    /// Share of a pass's correction applied: `u_stiffness`.
    pub stiffness: f32,
    /// Relative stretch past which an edge counts as overstretched in the run's census.
    pub stretch_bound: f32,
    /// Hair on an orbiting sphere: the orbit its roots follow (`u_pin_offset`).
    pub pin: Option<Orbit>,
}

impl Constraints {
    /// The constraints block of `s` (`None` without `[constraints]`).
    pub fn of(s: &SceneFile) -> Option<Self> {
        let c = s.constraints.as_ref()?;
        let pin = match (c.kind, c.root_sphere) {
            (ConstraintKind::Hair, Some(k)) => s.colliders.sphere[k].orbit,
            (ConstraintKind::Hair, None) | (ConstraintKind::Cloth, _) => None,
        };
        Some(Constraints {
            kind: c.kind,
            iterations: c.iterations,
            scheme: c.scheme,
            attachments: c.attachments,
            stiffness: c.stiffness,
            stretch_bound: c.stretch_bound,
            pin,
        })
    }

    /// How far the pinned roots have moved at time `t` (zero unless they sit on an orbit).
    pub fn pin_offset(&self, t: f64) -> Vec3 {
        self.pin.map_or(Vec3::ZERO, |o| Vec3::from(o.offset(t)))
    }
}
