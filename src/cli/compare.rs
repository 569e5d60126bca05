//! `render --compare`: the state at one frame against a dump saved earlier (a golden reference).

use std::path::PathBuf;

use clap::Args;
use texflow::engine::compare::{compare, describe, Comparison, Reference};
use texflow::engine::StateDump;
use texflow::Error;

use super::bad;

#[derive(Args)]
pub struct CompareArgs {
    /// Compare the state with a dump saved by --dump-state: `DIR/positions_NNNNN.npy` is
    /// compared with the positions at frame NNNNN, and `velocities_NNNNN.npy` beside it (if
    /// there) with the velocities; a file named otherwise, with the positions at the last frame.
    /// Beyond --tolerance the command exits with 4, naming the particle, the component and how
    /// far (the frames are written either way).
    #[arg(long, value_name = "FILE")]
    compare: Option<PathBuf>,
    /// Largest difference --compare accepts, in ULPs of float32 (units in the last place: 1 is
    /// one step between neighbouring floats, 2^-23 ≈ 1.2e-7 of the value's power of two). 0, the
    /// default, asks for the same bits, which the same scene, seed and device give.
    #[arg(long, value_name = "ULPS", default_value_t = 0, requires = "compare")]
    tolerance: u64,
}

/// A reference read before the run, and the state captured at its frame.
pub struct Golden {
    frame: u64,
    references: Vec<(Reference, Vec<[f32; 4]>)>,
    tolerance: u64,
    captured: Option<StateDump>,
}

impl CompareArgs {
    /// The files --compare reads: the reference and, where it exists, its other half.
    pub fn inputs(&self) -> super::targets::Inputs {
        let Some(path) = &self.compare else {
            return Vec::new();
        };
        let first = Reference::from_path(path);
        let mut v = vec![(path.clone(), "the --compare reference".to_owned())];
        if let Some(s) = first.sibling().filter(|s| s.path.is_file()) {
            v.push((s.path, "the --compare reference's other half".to_owned()));
        }
        v
    }

    /// Reads the reference (and its other half) before any GPU work; `frames` is the run's
    /// length, which must reach the reference's frame.
    pub fn prepare(&self, frames: u64) -> texflow::Result<Option<Golden>> {
        let Some(path) = &self.compare else {
            return Ok(None);
        };
        let first = Reference::from_path(path);
        let frame = first.frame.unwrap_or(frames - 1);
        if frame >= frames {
            return Err(bad(format!(
                "--compare {}: that dump is of frame {frame}, but --frames {frames} ends at \
                 frame {}: run at least {} frames",
                path.display(),
                frames - 1,
                frame + 1
            )));
        }
        let mut references = Vec::new();
        let data = first.read()?;
        let sibling = first.sibling().filter(|s| s.path.is_file());
        references.push((first, data));
        if let Some(s) = sibling {
            let data = s.read()?;
            references.push((s, data));
        }
        Ok(Some(Golden {
            frame,
            references,
            tolerance: self.tolerance,
            captured: None,
        }))
    }
}

impl Golden {
    /// The frame whose state is compared.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Keeps the dump of frame `index` if it is the reference's.
    pub fn offer(&mut self, index: u64, dump: &StateDump) {
        if index == self.frame {
            self.captured = Some(dump.clone());
        }
    }

    /// Compares the captured state with the reference: Ok with a line to print when it is
    /// within the tolerance, [`Error::Mismatch`] otherwise.
    pub fn verdict(&self) -> texflow::Result<String> {
        let Some(dump) = &self.captured else {
            return Err(Error::Mismatch(format!(
                "--compare: the run stopped before frame {}, so nothing was compared",
                self.frame
            )));
        };
        let mut lines = Vec::new();
        let mut failed = false;
        for (r, data) in &self.references {
            let name = r.path.display();
            let c: Comparison = compare(dump, r.what, data, self.tolerance).map_err(|e| {
                Error::Mismatch(format!("--compare {name}: frame {}: {e}", self.frame))
            })?;
            let worst = c
                .worst
                .as_ref()
                .map_or("every value has the same bits".to_owned(), describe);
            if c.beyond > 0 {
                failed = true;
                lines.push(format!(
                    "--compare {name}: frame {}: {} of {} values differ by more than {} ULP; the \
                     largest: {worst}",
                    self.frame, c.beyond, c.values, self.tolerance
                ));
            } else {
                lines.push(format!(
                    "--compare {name}: frame {} matches within {} ULP ({} values; {worst})",
                    self.frame, self.tolerance, c.values
                ));
            }
        }
        match failed {
            true => Err(Error::Mismatch(lines.join("\n"))),
            false => Ok(lines.join("\n")),
        }
    }
}
