//! Benchmarks: time of passes, medians over many runs after warm-up, each pass next to its floor
//! measured in the same run (a write-only pass of the same size and formats: on a GPU whose
//! fragment path is bound by the bytes it writes, no pass that writes those targets can be
//! faster).

pub mod cost;
pub mod passes;
pub mod scene;
pub mod scenes;
pub mod sort;
mod sort_check;
pub mod stats;
pub mod step;

pub use passes::{bench_passes, passes_markdown, PassesOptions, PassesRecord};
pub use scene::{bench_scene, scene_markdown, SceneBenchOptions, SceneBenchRecord};
pub use sort::{bench_sort, paper_table1_fps, sort_markdown, SortBenchOptions, SortRecord};
pub use stats::{
    json_envelope, load_average, median, Clock, DeviceRecord, FixedCost, PassTimer,
    PlacedRenderFloor, RenderFloor, Spread, WriteFloor,
};
pub use step::{bench_step, step_markdown, StepOptions, StepRecord};
