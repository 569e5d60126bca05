//! Golden references: a run's state at one frame against a dump saved earlier (`render
//! --compare`), component by component, in units in the last place of float32.
//!
//! A tolerance in ULPs is relative to the float format: 1 ULP is one step between neighbouring
//! float32 values, 2^-23 of the value's binary order of magnitude (about 1.2e-7 relative). The
//! same scene, seed and device give bit-identical state, so the default tolerance is 0.

use std::path::{Path, PathBuf};

use super::StateDump;
use crate::error::{Error, Result};

/// Distance between two floats counted in representable float32 values (0: the same bits, or
/// +0 and -0; 1: neighbours). Two NaNs are 0 apart; a NaN and a number are infinitely far.
pub fn ulp_distance(a: f32, b: f32) -> u64 {
    match (a.is_nan(), b.is_nan()) {
        (true, true) => return 0,
        (true, false) | (false, true) => return u64::MAX,
        _ => {}
    }
    // Maps the float's bits onto a line where consecutive floats are consecutive integers.
    let line = |x: f32| {
        let bits = x.to_bits();
        if bits & 0x8000_0000 != 0 {
            -((bits & 0x7fff_ffff) as i64)
        } else {
            bits as i64
        }
    };
    line(a).abs_diff(line(b))
}

/// One reference file: what it holds and the frame it was dumped at.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reference {
    /// The file.
    pub path: PathBuf,
    /// `positions` or `velocities`.
    pub what: &'static str,
    /// The frame, from the name `positions_NNNNN.npy` written by `--dump-state`; `None` for a
    /// file named otherwise (it is then compared with the last frame).
    pub frame: Option<u64>,
}

impl Reference {
    /// Reads what a reference's name says: `positions_00059.npy` is the positions at frame 59,
    /// `velocities_00059.npy` the velocities; any other name holds positions, frame unknown.
    pub fn from_path(path: &Path) -> Reference {
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        let (what, rest) = match name.strip_prefix("velocities_") {
            Some(rest) => ("velocities", Some(rest)),
            None => ("positions", name.strip_prefix("positions_")),
        };
        let frame = rest
            .and_then(|r| r.strip_suffix(".npy"))
            .filter(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit()))
            .and_then(|d| d.parse().ok());
        Reference {
            path: path.to_path_buf(),
            what,
            frame,
        }
    }

    /// The file of the other half of the same dump (velocities beside positions and back), if the
    /// name follows the dump's pattern.
    pub fn sibling(&self) -> Option<Reference> {
        let frame = self.frame?;
        let other = if self.what == "positions" {
            "velocities"
        } else {
            "positions"
        };
        let path = self.path.with_file_name(format!("{other}_{frame:05}.npy"));
        Some(Reference {
            path,
            what: other,
            frame: Some(frame),
        })
    }

    /// Reads the file: an N×4 float32 array, as `--dump-state` writes. Anything else is bad input.
    pub fn read(&self) -> Result<Vec<[f32; 4]>> {
        let (shape, data) = crate::npy::read_f32_shaped(&self.path)?;
        if shape.len() != 2 || shape[1] != 4 {
            return Err(Error::InvalidInput(format!(
                "{}: shape {shape:?} is not a state dump: --compare takes an N×4 float32 .npy \
                 written by --dump-state (positions_NNNNN.npy or velocities_NNNNN.npy)",
                self.path.display()
            )));
        }
        Ok(data
            .chunks_exact(4)
            .map(|c| [c[0], c[1], c[2], c[3]])
            .collect())
    }
}

/// The largest difference found between a run and a reference.
#[derive(Debug, Clone, PartialEq)]
pub struct Difference {
    /// `positions` or `velocities`.
    pub what: &'static str,
    /// Row of the dump (the live particles in texel order).
    pub particle: usize,
    /// Component 0-3 (x, y, z, w).
    pub component: usize,
    /// The run's value.
    pub value: f32,
    /// The reference's value.
    pub reference: f32,
    /// Distance in ULPs.
    pub ulps: u64,
}

impl Difference {
    /// The component's name: x, y, z, or `life` (positions) / `w` (velocities).
    pub fn component_name(&self) -> &'static str {
        match (self.component, self.what) {
            (0, _) => "x",
            (1, _) => "y",
            (2, _) => "z",
            (_, "positions") => "life",
            _ => "w",
        }
    }
}

/// What a comparison found.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// Values compared.
    pub values: usize,
    /// Values further apart than the tolerance.
    pub beyond: usize,
    /// The largest difference (`None` when every value has the same bits).
    pub worst: Option<Difference>,
}

/// Compares one half of `dump` (`what`: positions or velocities) with `reference`, value by
/// value. A different number of live particles is an error: the runs have diverged.
pub fn compare(
    dump: &StateDump,
    what: &'static str,
    reference: &[[f32; 4]],
    tolerance: u64,
) -> std::result::Result<Comparison, String> {
    let run = if what == "velocities" {
        &dump.velocities
    } else {
        &dump.positions
    };
    if run.len() != reference.len() {
        return Err(format!(
            "the run has {} live particles, the reference {}: the runs diverged, or ran with \
             another scene, --seed, --particles, --dt or --substeps",
            run.len(),
            reference.len()
        ));
    }
    let mut c = Comparison {
        values: run.len() * 4,
        beyond: 0,
        worst: None,
    };
    for (i, (a, b)) in run.iter().zip(reference).enumerate() {
        for k in 0..4 {
            let ulps = ulp_distance(a[k], b[k]);
            if ulps > tolerance {
                c.beyond += 1;
            }
            if ulps > 0 && c.worst.as_ref().is_none_or(|w| ulps > w.ulps) {
                c.worst = Some(Difference {
                    what,
                    particle: i,
                    component: k,
                    value: a[k],
                    reference: b[k],
                    ulps,
                });
            }
        }
    }
    Ok(c)
}

/// How far apart, in words: "3 ULP (|Δ| = 1.2e-7)", or "NaN against a number".
pub fn describe(d: &Difference) -> String {
    let far = if d.ulps == u64::MAX {
        "a NaN against a number".to_owned()
    } else {
        format!(
            "{} ULP apart (|Δ| = {:.3e})",
            d.ulps,
            (d.value as f64 - d.reference as f64).abs()
        )
    };
    format!(
        "particle {} (row of the dump: live particles in texel order), {} {}: {} against the \
         reference's {}, {far}",
        d.particle,
        d.what,
        d.component_name(),
        d.value,
        d.reference
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ulps_count_representable_floats() {
        assert_eq!(ulp_distance(1.0, 1.0), 0);
        assert_eq!(ulp_distance(0.0, -0.0), 0);
        assert_eq!(ulp_distance(1.0, f32::from_bits(1.0f32.to_bits() + 1)), 1);
        assert_eq!(ulp_distance(1.0, 1.0 + f32::EPSILON), 1);
        // Across zero: the smallest positive and negative subnormals are two steps apart.
        assert_eq!(ulp_distance(f32::from_bits(1), -f32::from_bits(1)), 2);
        assert_eq!(ulp_distance(f32::NAN, f32::NAN), 0);
        assert_eq!(ulp_distance(f32::NAN, 0.0), u64::MAX);
        // 2 and 4 are 2^23 floats apart (one binade).
        assert_eq!(ulp_distance(2.0, 4.0), 1 << 23);
    }

    #[test]
    fn names_give_frame_and_half() {
        let r = Reference::from_path(Path::new("ref/velocities_00012.npy"));
        assert_eq!((r.what, r.frame), ("velocities", Some(12)));
        let s = r.sibling().unwrap();
        assert_eq!(s.path, Path::new("ref/positions_00012.npy"));
        let o = Reference::from_path(Path::new("golden.npy"));
        assert_eq!((o.what, o.frame), ("positions", None));
        assert!(o.sibling().is_none());
    }

    #[test]
    fn the_worst_difference_is_named() {
        let dump = StateDump {
            positions: vec![[1.0, 2.0, 3.0, 4.0], [5.0, 6.0, 7.0, 8.0]],
            velocities: vec![[0.0; 4]; 2],
            more: Vec::new(),
            non_finite: 0,
        };
        let mut reference = dump.positions.clone();
        let same = compare(&dump, "positions", &reference, 0).unwrap();
        assert_eq!((same.beyond, same.worst), (0, None));
        reference[1][2] = f32::from_bits(7.0f32.to_bits() + 5);
        reference[0][0] = f32::from_bits(1.0f32.to_bits() + 1);
        let c = compare(&dump, "positions", &reference, 1).unwrap();
        assert_eq!(c.beyond, 1);
        let w = c.worst.unwrap();
        assert_eq!((w.particle, w.component, w.ulps), (1, 2, 5));
        assert!(describe(&w).contains("particle 1"));
        assert!(compare(&dump, "positions", &reference[..1], 0).is_err());
    }
}
