//! The programs the sorter draws, read from the passes it built (the schedule of
//! [`crate::sort::schedule::network`]), for the scene's pass list.

use super::{group_shape, Pass, ProgramKey, Sorter, Step};
use crate::gl::FULLSCREEN_VERTEX;

/// The key pass's fragment file (`write_keys`, `refresh_keys`).
pub(super) const KEYS: &str = "sort/keys.frag";
/// The gather's fragment file (`rearrange`, `gather`).
pub(super) const REARRANGE: &str = "sort/rearrange.frag";

impl Sorter {
    /// The programs of one full sort, in the order of their first pass, each with how many of
    /// the sort's passes draw it: the network's passes one for one.
    pub fn network_draws(&self) -> Vec<(String, u64)> {
        let mut out: Vec<(String, u64)> = Vec::new();
        for &i in &self.cycle {
            let name = self.pass_program(&self.passes[i]);
            match out.iter_mut().find(|(n, _)| *n == name) {
                Some((_, t)) => *t += 1,
                None => out.push((name, 1)),
            }
        }
        out
    }

    /// The program of the key pass (`vertex+fragment`).
    pub fn keys_program() -> String {
        format!("{FULLSCREEN_VERTEX}+{KEYS}")
    }

    /// The program of a gather in sorted order (`vertex+fragment`).
    pub fn gather_program() -> String {
        format!("{FULLSCREEN_VERTEX}+{REARRANGE}")
    }

    fn pass_program(&self, pass: &Pass) -> String {
        let key = match pass {
            Pass::Fragment(Step::Bitonic { .. }) => ProgramKey::Fp,
            Pass::Fragment(Step::OddEvenRecursion { .. }) => ProgramKey::OddEvenRecursion,
            Pass::Fragment(Step::OddEvenEnd { .. }) => ProgramKey::OddEvenEnd,
            Pass::Group(steps) => {
                let (levels, steps) = group_shape(steps);
                ProgramKey::Multistep { levels, steps }
            }
            Pass::Geometry { program, .. } => ProgramKey::Geometry(*program),
            Pass::Blocked(i) => {
                let b = self
                    .blocked
                    .as_ref()
                    .expect("blocked passes have a network");
                return b.pass_program(*i).to_owned();
            }
            Pass::Unpack => {
                let b = self.blocked.as_ref().expect("the unpack has a network");
                return b.unpack_program().to_owned();
            }
        };
        self.programs[&key].name().to_owned()
    }
}
