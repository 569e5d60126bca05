//! The forces and constraint passes of [`Features`], named for the scene's pass list.

use super::Features;
use crate::scene::{self, ForceKind};

impl Features {
    /// The forces the integration applies, in the order the shader adds them.
    pub(in crate::sim::particles) fn force_names(&self) -> Vec<String> {
        let mut forces = Vec::new();
        for kind in ForceKind::ALL {
            match kind {
                ForceKind::Gravity if self.gravity => forces.push("gravity".to_owned()),
                ForceKind::Damping => {
                    if self.damping {
                        forces.push("damping".to_owned());
                    }
                    if self.emitter_forces {
                        forces.push("forces per emitter (by the particle's type)".to_owned());
                    }
                }
                ForceKind::Wind if self.wind => forces.push(
                    match self.wind_form {
                        scene::WindForm::Drag => "wind (flow-field texture, Stokes drag)",
                        scene::WindForm::Latta => {
                            "wind (flow-field texture, Latta eq. 1-2: drag / mass)"
                        }
                        scene::WindForm::Uberflow => {
                            "wind (flow-field texture, UberFlow eq. 1: v += v_ext)"
                        }
                    }
                    .to_owned(),
                ),
                ForceKind::Gravity | ForceKind::Wind => {}
                ForceKind::Attractor if self.attractors > 0 => {
                    forces.push(format!("{} attractor(s)", self.attractors))
                }
                ForceKind::Spring if self.springs > 0 => {
                    forces.push(format!("{} spring(s)", self.springs))
                }
                ForceKind::Vortex if self.vortices > 0 => {
                    forces.push(format!("{} vortex(es)", self.vortices))
                }
                ForceKind::Attractor | ForceKind::Spring | ForceKind::Vortex => {}
                ForceKind::Custom => {
                    for file in &self.custom_forces {
                        forces.push(format!("user force {file}"));
                    }
                }
                // Not in the integration pass: named with the collision stage's passes.
                ForceKind::Pair => {}
            }
        }
        forces
    }

    /// The constraint relaxation passes of cloth and hair, `iterations` times per step.
    pub(super) fn constrain_passes(&self) -> Vec<String> {
        let Some((kind, n, scheme, attachments)) = self.constraints else {
            return Vec::new();
        };
        let io = "[current position and rest texture in, the ring's free side out, then swapped]";
        let project = if self.colliders() {
            "; colliders' projection"
        } else {
            ""
        };
        let mut out = Vec::new();
        match (scheme, kind) {
            (scene::RelaxScheme::Jacobi, scene::ConstraintKind::Cloth) => out.push(format!(
                "{n} × constrain: Jacobi relaxation of the cloth's distance constraints (4 grid \
                 neighbours, 4 diagonals; each texel by the mean of its corrections) {io}{project}"
            )),
            (scene::RelaxScheme::Jacobi, scene::ConstraintKind::Hair) => out.push(format!(
                "{n} × constrain: Jacobi relaxation of the hair's distance constraints (chains \
                 along rows; each texel by the mean of its corrections) {io}{project}"
            )),
            (scene::RelaxScheme::GaussSeidel, kind) => {
                let sets: &[&str] = match kind {
                    scene::ConstraintKind::Cloth => &[
                        "(1, 0) from even x",
                        "(1, 0) from odd x",
                        "(0, 1) from even y",
                        "(0, 1) from odd y",
                        "(1, 1) from even x",
                        "(1, 1) from odd x",
                        "(1, -1) from even x",
                        "(1, -1) from odd x",
                    ],
                    scene::ConstraintKind::Hair => &["(1, 0) from even x", "(1, 0) from odd x"],
                };
                let order = match attachments {
                    true => "sets in order, then attach",
                    false => "sets in order",
                };
                for (i, set) in sets.iter().enumerate() {
                    out.push(format!(
                        "{n} × constrain set {i} (each of {n} iterations runs the {order}): \
                         Gauss-Seidel relaxation of the edges {set}, which share no particle, \
                         both ends moving {io}{project}"
                    ));
                }
            }
        }
        if attachments {
            out.push(format!(
                "{n} × attach: long-range attachments, each free particle back within its rest \
                 distance of {} {io}{project}",
                match kind {
                    scene::ConstraintKind::Cloth => "every pin [pins texture in]",
                    scene::ConstraintKind::Hair => "its strand's root",
                }
            ));
        }
        out
    }
}
