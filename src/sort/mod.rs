//! GPU sorting as the papers do it: UberFlow's row-wise bitonic sort (FP, GP/FP, GP/FP packed),
//! Latta's odd-even merge sort, and a multistep variant of our own; sort keys, identifiers under
//! emulated 24-bit floats, and the rearrangement of particle state in sorted order.

pub mod blocked;
mod gpu;
pub mod network;
pub mod precision;
pub mod schedule;
pub mod spread;

pub use gpu::{
    row_cell_entry, row_cells_fit, BlockedShape, KeyMode, LookupBindings, Quantiser, SortOptions,
    Sorter, Variant,
};
pub use network::{entry_less, Entry, Step};
pub use schedule::{entry_pass_count, network as passes_of, pass_count, NetworkPass};
