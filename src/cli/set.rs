//! `--set KEY=VALUE`, shared by every command that takes a scene (the work is
//! `texflow::scene::parse_with`).

use clap::Args;

#[derive(Args, Clone, Default)]
pub struct SetArgs {
    /// Set a scene key, as KEY=VALUE (repeatable), validated like the file: e.g.
    /// `--set render.point_size=4`, `--set render.mode=points`, `--set
    /// emitters.allocator.0.rate=500` (array entries by index). See docs/scenes.md.
    #[arg(long = "set", value_name = "KEY=VALUE", allow_hyphen_values = true)]
    pub set: Vec<String>,
}
