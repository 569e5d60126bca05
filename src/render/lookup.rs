//! Latta §3.4.4's index lookup: the particle renderer draws sorted particles by reading the
//! sort's (key, id) texture in the vertex stage and fetching the state at `id`, instead of
//! drawing a copy of the state gathered into sorted order first (UberFlow §4.3.1).

use crate::gl::Defines;

/// The layout of the sort texture the vertex stage reads (that of the sorter which wrote it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SortLayout {
    /// Entries per row of the sort.
    pub width: u32,
    /// Two entries per RGBA texel (the packed and multistep variants).
    pub packed: bool,
    /// The paper's 24-bit-safe identifiers (UberFlow §4.3.1) of this many mantissa bits; `None`
    /// for plain indices.
    pub id_mantissa: Option<u32>,
}

impl SortLayout {
    /// The defines of the vertex stage's lookup (render/particle.vert, sort/sorted_id.glsl).
    pub(super) fn defines(&self) -> Defines {
        let mut d = Defines::new();
        d.push(("LOOKUP".into(), "1".into()));
        if self.packed {
            d.push(("PACKED".into(), "1".into()));
        }
        if let Some(m) = self.id_mantissa {
            d.push(("ID_TABLE".into(), "1".into()));
            d.push(("FLOAT_MANTISSA".into(), m.to_string()));
        }
        d
    }
}
