//! `texflow trace`: the state textures drawn pass by pass, so that a reader can watch a frame or
//! a sort happen (UberFlow Fig. 1-3 and Latta Fig. 3-5 show the sorts this way).
//!
//! - [`trace_sort`]: random keys sorted pass by pass, a picture per pass and an animated GIF.
//! - [`trace_scene`]: a scene run to a frame, then that frame's passes one by one, each pass's
//!   output textures read back (through the `gl` layer's read-backs) and drawn, with an
//!   `index.md` naming each pass, its paper and section, its inputs and outputs.
//! - [`picture`]: the colour ramps and grids the pictures are made of.

pub mod picture;
mod scene;
mod sort;

use std::path::PathBuf;

pub use scene::{check_scene_trace, trace_scene, MAX_TRACE_FRAME, MAX_TRACE_SIDE};
pub use sort::{
    check_sort_size, describe_step, keys_from_picture, pass_descriptions, random_entries,
    trace_sort, MAX_SORT_SIDE,
};

/// What a trace wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Written {
    /// Every file, in the order written (`index.md` last).
    pub files: Vec<PathBuf>,
    /// Passes traced.
    pub passes: usize,
    /// For a sort: whether the last picture is sorted; for a scene: always true.
    pub ok: bool,
}
