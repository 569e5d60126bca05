//! Command-line values that replace a scene's own, applied and validated in one place for every
//! command (render, collide-stats, the benchmarks, `scene check`). The library speaks in scene
//! keys; this is where an error about a key becomes one about the option a user typed.

use texflow::gl::Context;
use texflow::scene::{self, SceneFile};
use texflow::scene::{check_limits, Key, SizeLimits};
use texflow::{Error, Result};

/// Values given on the command line instead of the scene's.
#[derive(Debug, Clone, PartialEq)]
pub struct Overrides {
    /// State texture size (`--particles`).
    pub particles: Option<[u32; 2]>,
    /// Frame size (`--resolution`).
    pub resolution: Option<[u32; 2]>,
    /// Time step (`--dt`).
    pub dt: Option<f32>,
    /// Steps per frame (`--substeps`).
    pub substeps: Option<u32>,
    /// Drop the scene's collisions between particles (`--no-collisions`).
    pub no_collisions: bool,
    /// Random seed (`--seed`).
    pub seed: u64,
    /// EGL device (`--device`).
    pub device: usize,
    /// Scene keys set as `KEY=VALUE` (`--set`, repeatable), applied in order to the parsed
    /// file before the options above.
    pub set: Vec<String>,
}

impl Default for Overrides {
    fn default() -> Self {
        Overrides {
            particles: None,
            resolution: None,
            dt: None,
            substeps: None,
            no_collisions: false,
            seed: 1,
            device: 0,
            set: Vec::new(),
        }
    }
}

/// A scene loaded, overridden and validated: ready for a context.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The file's path or the built-in scene's name, for messages.
    pub label: String,
    /// The TOML source, for locating errors.
    pub source: String,
    /// The scene with the overrides applied.
    pub scene: SceneFile,
}

impl Overrides {
    /// The scene keys these overrides replace, with the option that replaced each.
    fn replaced(&self) -> Vec<(&'static str, &'static str)> {
        let mut v = Vec::new();
        if self.particles.is_some() {
            v.push(("particles.size", "--particles"));
        }
        if self.resolution.is_some() {
            v.push(("render.resolution", "--resolution"));
        }
        if self.dt.is_some() {
            v.push(("time.dt", "--dt"));
        }
        if self.substeps.is_some() {
            v.push(("time.substeps", "--substeps"));
        }
        v
    }

    /// The options given, as typed (`--dt 0.5`), for messages.
    fn given(&self) -> Vec<String> {
        let size = |s: [u32; 2]| format!("{}x{}", s[0], s[1]);
        let mut v = Vec::new();
        if let Some(p) = self.particles {
            v.push(format!("--particles {}", size(p)));
        }
        if let Some(r) = self.resolution {
            v.push(format!("--resolution {}", size(r)));
        }
        if let Some(dt) = self.dt {
            v.push(format!("--dt {dt}"));
        }
        if let Some(n) = self.substeps {
            v.push(format!("--substeps {n}"));
        }
        if self.no_collisions {
            v.push("--no-collisions".into());
        }
        v.extend(self.set.iter().map(|s| format!("--set {s}")));
        v
    }

    /// Sets the overridden values in `scene` and validates the result; an error names the option
    /// whose value it is about, or the scene key.
    pub fn apply(&self, scene: &mut SceneFile) -> Result<()> {
        self.apply_naming(scene, &[])
    }

    /// [`apply`](Self::apply) for a command that also set scene keys from its own options:
    /// `options` maps each such key (`collisions.iterations`) to the option typed
    /// (`--iterations`), so that an error about the key names the option.
    pub fn apply_naming(&self, scene: &mut SceneFile, options: &[(&str, &str)]) -> Result<()> {
        if let Some(p) = self.particles {
            // Below the scene's count the point size grows to keep the look (scene::resize).
            scene.resize_particles(p);
        }
        if let Some(r) = self.resolution {
            scene.render.resolution = r;
        }
        if let Some(dt) = self.dt {
            scene.time.dt = dt;
        }
        if let Some(n) = self.substeps {
            scene.time.substeps = n;
        }
        if self.no_collisions {
            scene.collisions = None;
        }
        if let Err(e) = scene.validate() {
            let key =
                e.at.iter()
                    .filter_map(|k| match k {
                        Key::Name(n) => Some(*n),
                        Key::Index(_) => None,
                    })
                    .collect::<Vec<_>>()
                    .join(".");
            let option = self
                .replaced()
                .into_iter()
                .chain(options.iter().copied())
                .find(|(k, _)| *k == key)
                .map(|(_, o)| o);
            let given = self.given();
            return Err(Error::InvalidInput(match (option, given.is_empty()) {
                (Some(o), _) => format!("{o}: {}", e.message),
                (None, true) => format!("scene `{}`: {} (at `{key}`)", scene.name, e.message),
                (None, false) => format!(
                    "scene `{}` with {}: {} (at `{key}`)",
                    scene.name,
                    given.join(" "),
                    e.message
                ),
            }));
        }
        Ok(())
    }

    /// Loads a built-in scene or a scene file, applies the overrides and validates it, all
    /// without a GPU.
    pub fn prepare(&self, name_or_path: &str) -> Result<Prepared> {
        let (label, source) = scene::load_source(name_or_path)?;
        let mut s = scene::parse_with(&label, &source, &self.set)?;
        scene::load_custom(&label, &source, &mut s)?;
        self.apply(&mut s)?;
        Ok(Prepared {
            label,
            source,
            scene: s,
        })
    }

    /// Checks the sizes the prepared scene asks of `ctx`'s device: keys from the file at their
    /// line and column, overridden ones by option.
    pub fn check_device(&self, ctx: &Context, p: &Prepared) -> Result<()> {
        let l = ctx.limits();
        let limits = SizeLimits {
            max_texture: l.max_texture_size,
            max_3d_texture: l.max_3d_texture_size,
        };
        let set: Vec<String> = (self.set.iter())
            .filter_map(|s| scene::Setting::parse(s).ok())
            .map(|s| s.key())
            .collect();
        let skip: Vec<&str> = (self.replaced().iter().map(|(k, _)| *k))
            .chain(set.iter().map(String::as_str))
            .collect();
        check_limits(&p.label, &p.source, &p.scene, limits, &skip)?;
        // Overridden sizes, by the option that gave them.
        let max = l.max_texture_size;
        let over = |flag: &str, what: &str, side: u32| {
            Err(Error::InvalidInput(format!(
                "{flag}: {what} {side} is over this device's limit of {max} \
                 (GL_MAX_TEXTURE_SIZE): give sides of at most {max}"
            )))
        };
        if let Some([w, h]) = self.particles {
            if w.max(h) > max {
                return over("--particles", "the state texture side", w.max(h));
            }
            let sort = w.next_power_of_two().max(h.next_power_of_two());
            if p.scene.render.blending == scene::Blending::Alpha && sort > max {
                return over(
                    "--particles",
                    "the sort texture side (the state's, rounded up to a power of two)",
                    sort,
                );
            }
        }
        if let Some([w, h]) = self.resolution {
            if w.max(h) > max {
                return over("--resolution", "the frame side", w.max(h));
            }
        }
        scene::check_point_size(&p.label, &p.source, &p.scene, l.point_size_range[1])?;
        // Custom forces compile here too, so that `scene check` refuses what `render` would.
        texflow::sim::particles::check_custom_forces(ctx, &p.scene)
    }
}
