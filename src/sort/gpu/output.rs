//! Where a sort's result lies: the row-major texture every variant leaves, or, for a blocked
//! sort that keeps its layout ([`SortOptions::keep_blocked`](super::SortOptions)), the blocked
//! network's own textures, read in place by the gather and unpacked only when asked for.

use super::Sorter;
use crate::error::Result;
use crate::gl::Texture;
use crate::sort::network::Entry;

impl Sorter {
    /// The texture holding the entries now, row-major (RG32F, or RGBA32F packed). After a sort
    /// that kept the blocked layout, the first call writes it (one unpack pass, the pass the
    /// sort left out).
    pub fn keys(&self) -> &Texture {
        if !self.row_major.get() {
            if let Some(b) = &self.blocked {
                // The key texture the sort started from is free: the sort is done with it.
                self.ctx.count_fetches(self.len() as u64);
                b.unpack(self.state.front(), &self.fullscreen);
            }
            self.row_major.set(true);
        }
        self.state.front().only_texture()
    }

    /// Reads the entries back, unpacked, row-major.
    pub fn read(&self) -> Result<Vec<Entry>> {
        // RG32F texels are entries; packed RGBA32F texels are two consecutive entries.
        let raw = self.keys().read_f32()?;
        Ok(raw.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    }

    /// Whether the sorted entries lie in the blocked layout only (the gather reads them there).
    pub(super) fn sorted_in_place(&self) -> bool {
        self.in_place && !self.row_major.get()
    }

    /// Whether the sort leaves its entries in the blocked layout, with no unpack pass
    /// ([`SortOptions::keep_blocked`](super::SortOptions) where it applies).
    pub fn keeps_blocked_layout(&self) -> bool {
        self.in_place
    }
}
