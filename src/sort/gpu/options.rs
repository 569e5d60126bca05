//! What a [`Sorter`](super::Sorter) sorts and how: the variant, the key, the options.

use glam::{UVec3, Vec3};

pub use super::blocked::BlockedShape;
use crate::sort::precision::FloatFormat;

pub use crate::scene::Variant;

// The variant is defined with the scene file format that names it; the layout it sorts in is
// the sorter's business.
impl Variant {
    /// Whether entries are packed two per texel.
    pub fn packed(self) -> bool {
        matches!(self, Variant::Packed | Variant::Multistep)
    }
}

/// What the key pass computes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KeyMode {
    /// Distance to the eye; ascending (front to back) or negated (back to front).
    ViewerDistance {
        /// The eye position.
        eye: Vec3,
        /// Sort the farthest first (for alpha blending).
        back_to_front: bool,
    },
    /// The particle's age (total life from the static texture minus the remaining life), for
    /// drawing the youngest or the oldest on top; needs the static texture
    /// ([`Sorter::write_keys_with_statics`](super::Sorter::write_keys_with_statics)).
    Age {
        /// The youngest drawn on top (else the oldest).
        youngest_on_top: bool,
        /// Drawn first to last with the over operator (else with the under operator, where the
        /// first drawn is on top).
        back_to_front: bool,
    },
    /// The position along an axis, `dot(x, direction)`, ascending: half-angle slicing sorts
    /// along the vector halfway between the light and the view (Kniss et al. 2003), nearest
    /// the light first.
    Axis {
        /// The axis (any length: the keys scale with it).
        direction: Vec3,
    },
    /// Index of the cell of a lattice, enumerated z, y, x (UberFlow §4.3).
    GridCell {
        /// Corner of cell (0, 0, 0).
        origin: Vec3,
        /// Mesh size g0.
        spacing: f32,
        /// Cells per axis.
        dims: UVec3,
    },
}

/// Options of a [`Sorter`](super::Sorter).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SortOptions {
    /// `None`: sort the whole texture; `Some(k)`: sort within each set of k consecutive rows
    /// (k a power of two; 1 = rows only, UberFlow §4.4).
    pub rows: Option<u32>,
    /// Emulate a narrower float format in what the sort passes write (UberFlow §4.3.1).
    pub precision: Option<FloatFormat>,
    /// With `precision`, identifiers from the paper's enumeration instead of plain indices.
    pub id_table: bool,
    /// Steps of distance 2 or more per pass of the multistep variant (1 to 3; distance-1 steps
    /// come free).
    pub steps_per_pass: usize,
    /// Passes [`Sorter::sort_frame`](super::Sorter::sort_frame) runs per frame; `None`: the whole sort every frame. Latta
    /// spreads one odd-even sort over 20-50 frames (§3.4.4); the sequence restarts when done.
    pub passes_per_frame: Option<usize>,
    /// The order of passes the spread runs ([`Spread`](crate::sort::spread::Spread)): `Even`
    /// (the network in order) or `Local` (the first merge stages re-run between later ones).
    pub spread: crate::sort::spread::Spread,
    /// Entries per fragment and lane pinning of the blocked variant.
    pub blocked: BlockedShape,
    /// `Some(cells)`: the keys are whole cell indices below `cells` (or ±inf, NaN) and every
    /// identifier is its entry's own texel index, as the key pass writes them for a lattice.
    /// A blocked sort within rows then takes 4-byte exact entries where they fit
    /// ([`SortOptions::row_cells`]).
    pub cell_keys: Option<u64>,
    /// The blocked sort leaves its entries where its last pass wrote them and the gather reads
    /// them there: no unpack pass. The row-major texture is written only when something asks
    /// for it ([`Sorter::keys`](super::Sorter::keys), [`Sorter::read`](super::Sorter::read)).
    /// Taken where the last pass leaves exact entries row-major within the blocks (it merges);
    /// any other blocked sort unpacks as before, and the other variants, which have no unpack,
    /// ignore it ([`Sorter::keeps_blocked_layout`](super::Sorter::keeps_blocked_layout) says
    /// which). For sorts that only the gather reads (UberFlow's detection).
    pub keep_blocked: bool,
}

impl SortOptions {
    /// Whether a blocked sort of `variant` over rows `width` entries wide takes rows-only
    /// compact exact entries: (cell level, position in the sorted rows) in one uint
    /// ([`row_cells_fit`](super::blocked::row_cells_fit)). Decided from the options alone, so
    /// the pass lists say it without GL.
    pub fn row_cells(&self, variant: Variant, width: u32) -> bool {
        match (variant, self.rows, self.cell_keys) {
            (Variant::Blocked, Some(k), Some(cells)) => {
                super::blocked::row_cells_fit(cells, (width * k).trailing_zeros())
            }
            _ => false,
        }
    }

    /// The blocked network's shape as the sorter runs it: with rows-only compact exact entries
    /// (see [`row_cells`](Self::row_cells)), 4-byte entries and, for exact shapes, one group
    /// bit more (twice the entries of the same render targets); else the options' shape.
    pub fn blocked_shape(&self, variant: Variant, width: u32) -> BlockedShape {
        let s = self.blocked;
        match self.row_cells(variant, width) {
            true if s.compact => s,
            true => BlockedShape {
                bits: (s.bits + 1).min(5),
                pinned: false,
                compact: true,
                merge: s.merge,
            },
            false => s,
        }
    }
}

impl Default for SortOptions {
    fn default() -> Self {
        SortOptions {
            rows: None,
            precision: None,
            id_table: false,
            steps_per_pass: 2,
            passes_per_frame: None,
            spread: crate::sort::spread::Spread::Even,
            blocked: BlockedShape::default(),
            cell_keys: None,
            keep_blocked: false,
        }
    }
}
