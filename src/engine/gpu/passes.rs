//! The passes of one frame as the engine runs them: its simulation's step passes, its sort's
//! key, network and gather passes, and its renderer's, each with the programs it draws.

use super::GpuEngine;
use crate::gl::{attach_draws, PassDraw, PassInfo};
use crate::sim::Simulation;
use crate::sort::Sorter;

impl<S: Simulation> GpuEngine<S> {
    /// Every pass of a frame, in order: the step's (run `substeps` times), then the frame's.
    pub(super) fn frame_passes(&self) -> Vec<PassInfo> {
        let mut out = self.sim.pass_list();
        if let Some(s) = &self.sort {
            let mut lines = self.sort_passes.clone();
            let mut draws = vec![PassDraw::new("sort keys", Sorter::keys_program(), 1)];
            for (program, n) in s.sorter.network_draws() {
                // Spread over frames, a frame runs part of the network: at most all of it.
                let d = PassDraw::new("sort:", program, n);
                draws.push(if s.spread { d.varying() } else { d });
            }
            if !s.lookup {
                let names: Vec<&str> = (s.sorted.names().iter())
                    .flatten()
                    .map(|a| a.name())
                    .collect();
                lines.push(format!(
                    "gather {} textures in sorted order",
                    and_list(&names)
                ));
                draws.push(PassDraw::new("gather", Sorter::gather_program(), 1));
            }
            out.extend(attach_draws("sort", lines, draws));
        }
        out.extend(match &self.lit {
            Some(l) => l.passes(),
            None => self.renderer.passes(),
        });
        out
    }
}

/// `a`, `a and b`, `a, b and c`.
fn and_list(items: &[&str]) -> String {
    match items {
        [] => String::new(),
        [one] => (*one).to_owned(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}
