//! `texflow scene`: check scene files, list their passes, list the built-in scenes.

use super::overrides::Overrides;
use clap::Subcommand;
use texflow::gl::Context;
use texflow::scene;
use texflow::EngineKind;

use super::bad;

#[derive(Subcommand)]
pub enum SceneCommand {
    /// Validate a scene file (syntax, types, keys, values) without rendering.
    #[command(allow_negative_numbers = true)]
    Check {
        /// Scene file (.toml) or built-in name.
        scene: String,
        /// EGL device whose size limits to check against.
        #[arg(long, default_value_t = 0)]
        device: usize,
        #[command(flatten)]
        set: super::set::SetArgs,
    },
    /// Print the passes a scene runs per frame: those of the engine built for it (on a GL
    /// context, so that the list is what runs).
    #[command(allow_negative_numbers = true)]
    Passes {
        /// Scene file (.toml) or built-in name.
        scene: String,
        /// EGL device to build the engine on.
        #[arg(long, default_value_t = 0)]
        device: usize,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        set: super::set::SetArgs,
    },
    /// List the built-in scenes, or print one's TOML source.
    #[command(allow_negative_numbers = true)]
    List {
        /// Print the source of this built-in scene.
        name: Option<String>,
    },
}

pub fn scene_command(c: SceneCommand) -> texflow::Result<()> {
    match c {
        SceneCommand::Check {
            scene: name,
            device,
            set,
        } => {
            // The same validation path as render and every other command.
            let overrides = Overrides {
                device,
                set: set.set,
                ..Overrides::default()
            };
            let prepared = overrides.prepare(&name)?;
            let s = &prepared.scene;
            // Sizes against the device's limits, where there is a device to ask; a device
            // index that does not exist is the user's mistake, not a missing driver.
            let limits = match Context::new(device) {
                Ok(ctx) => {
                    overrides.check_device(&ctx, &prepared)?;
                    format!("sizes fit {}", ctx.limits().renderer)
                }
                Err(e @ texflow::Error::DeviceIndex { .. }) => return Err(e),
                Err(e) => format!("sizes not checked against a device: {e}"),
            };
            println!(
                "{name}: ok (scene `{}`, {} particles; {limits})",
                s.name,
                s.particle_count()
            );
            // Valid, but the run will drop births: said now, predicted from rate × life.
            if let Some(w) = s.capacity_check() {
                println!("{name}: warning: {w}");
            }
            for w in s.child_capacity_check() {
                println!("{name}: warning: {w}");
            }
        }
        SceneCommand::Passes {
            scene: name,
            device,
            json,
            set,
        } => {
            let overrides = Overrides {
                set: set.set,
                ..Overrides::default()
            };
            // The passes the engine holds once built for the scene, on the default device.
            let prepared = overrides.prepare(&name)?;
            let ctx = Context::new(device)?;
            let engine = texflow::engine::build(&ctx, &prepared.scene, 1, EngineKind::Gpu)?;
            let plan = engine.plan();
            if json {
                super::print_json("texflow.scene.passes/1", None, &plan);
            } else {
                print!("{plan}");
            }
        }
        SceneCommand::List { name: None } => {
            let width = scene::BUILTIN.iter().map(|n| n.len()).max().unwrap_or(0);
            for n in scene::BUILTIN {
                let what = scene::summary(n).unwrap_or_default();
                println!("{n:<width$}  {what}");
            }
        }
        SceneCommand::List { name: Some(n) } => match scene::builtin_source(&n) {
            Some(src) => print!("{src}"),
            None => {
                return Err(bad(format!(
                    "unknown scene `{n}`: the built-in scenes are {}{}",
                    scene::BUILTIN.join(", "),
                    scene::did_you_mean(&n, scene::BUILTIN.iter().copied()),
                )))
            }
        },
    }
    Ok(())
}
