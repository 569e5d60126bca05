//! Scenes: what to simulate and how to look at it, read from TOML scene files ([`file`]).
//! Built-in scenes are the files in `examples/scenes/`, compiled into the binary.

pub mod file;

use std::path::Path;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::render::{Camera, PointStyle};
use crate::sim::FireParams;
pub use file::SceneFile;

macro_rules! builtin_scenes {
    ($($name:literal),* $(,)?) => {
        /// The built-in scenes: name and TOML source.
        pub static BUILTIN_SOURCES: &[(&str, &str)] = &[$(
            ($name, include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/", $name, ".toml"))),
        )*];
        /// The names of the built-in scenes.
        pub const BUILTIN: &[&str] = &[$($name),*];
    };
}

builtin_scenes!["fire", "snow", "fountain", "smoke", "e1", "e2", "e3", "collide"];

/// The scene rendered when none is named.
pub const DEFAULT_SCENE: &str = "fire";

/// The TOML source of a built-in scene.
pub fn builtin_source(name: &str) -> Option<&'static str> {
    BUILTIN_SOURCES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| *s)
}

/// Loads a scene by built-in name or from a `.toml` file (errors name file, line and column).
pub fn load(name_or_path: &str) -> Result<SceneFile> {
    let (label, src) = load_source(name_or_path)?;
    file::parse(&label, &src)
}

/// The label errors use for a scene and its TOML source, by built-in name or file path.
pub fn load_source(name_or_path: &str) -> Result<(String, String)> {
    if let Some(src) = builtin_source(name_or_path) {
        return Ok((format!("{name_or_path} (built-in)"), src.to_owned()));
    }
    let path = Path::new(name_or_path);
    let looks_like_file = path.extension().is_some_and(|e| e == "toml")
        || name_or_path.contains(std::path::MAIN_SEPARATOR);
    if !looks_like_file {
        return Err(Error::InvalidInput(format!(
            "unknown scene `{name_or_path}`: the built-in scenes are {}, or give a path to a \
             .toml scene file",
            BUILTIN.join(", ")
        )));
    }
    let src = std::fs::read_to_string(path).map_err(|e| {
        Error::InvalidInput(format!("cannot read scene file {}: {e}", path.display()))
    })?;
    Ok((path.display().to_string(), src))
}

/// A complete description of a run.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Scene {
    /// Scene name.
    pub name: String,
    /// State texture size (width, height): one particle per texel.
    pub particles: [u32; 2],
    /// Frame size in pixels.
    pub resolution: [u32; 2],
    /// Simulation time step in seconds, fixed whatever the frame rate.
    pub dt: f32,
    /// Simulation steps per rendered frame.
    pub substeps: u32,
    /// The camera at time 0.
    pub camera: Camera,
    /// Orbit speed of the camera around +y, degrees per simulated second.
    pub orbit: f32,
    /// Point size and brightness.
    pub style: PointStyle,
    /// The fire pass's parameters.
    pub fire: FireParams,
}

/// Looks up a built-in fire scene (the thesis model); other scenes run through
/// [`crate::engine::SceneEngine`].
pub fn builtin(name: &str) -> Result<Scene> {
    Scene::from_file(&load_builtin(name)?)
}

fn load_builtin(name: &str) -> Result<SceneFile> {
    match builtin_source(name) {
        Some(src) => file::parse(&format!("{name} (built-in)"), src),
        None => Err(Error::InvalidInput(format!(
            "unknown scene `{name}`: the built-in scenes are {}",
            BUILTIN.join(", ")
        ))),
    }
}

/// The fire of the thesis, at 256×256 particles rendered at 512×512 (`examples/scenes/fire.toml`).
pub fn fire() -> Scene {
    builtin("fire").expect("the built-in fire scene is valid")
}

/// The camera a scene file describes.
pub fn camera(c: &file::CameraSection) -> Camera {
    Camera {
        target: Vec3::from(c.target),
        distance: c.distance,
        azimuth: c.azimuth,
        elevation: c.elevation,
        fov_y: c.fov,
        ..Camera::default()
    }
}

impl Scene {
    /// The fire run a scene file with a `[fire]` section describes.
    pub fn from_file(f: &SceneFile) -> Result<Scene> {
        let Some(fire) = &f.fire else {
            return Err(Error::InvalidInput(format!(
                "scene `{}` has no [fire] section: it runs through the particle pipeline",
                f.name
            )));
        };
        let params = FireParams {
            emitter_center: Vec3::from(fire.emitter_center),
            emitter_radius: fire.emitter_radius,
            speed: fire.speed,
            spread: fire.spread,
            converge: fire.converge,
            buoyancy: Vec3::from(fire.buoyancy),
            turbulence: fire.turbulence,
            damping: fire.damping,
            life_min: fire.life[0],
            life_max: fire.life[1],
            max_age: fire.max_age,
        };
        Ok(Scene {
            name: f.name.clone(),
            particles: f.particles.size,
            resolution: f.render.resolution,
            dt: f.time.dt,
            substeps: f.time.substeps,
            camera: camera(&f.render.camera),
            orbit: f.render.camera.orbit,
            style: PointStyle {
                point_size: f.render.point_size,
                intensity: f.render.intensity,
                max_age: params.max_age,
            },
            fire: params,
        })
    }

    /// Rejects values no run can give a meaning to (limits of the device are checked later).
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidInput(m));
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return bad(format!(
                "time step dt = {} must be a finite number of seconds above 0",
                self.dt
            ));
        }
        if self.substeps == 0 {
            return bad("substeps must be at least 1".into());
        }
        for (what, [w, h]) in [
            ("particles", self.particles),
            ("resolution", self.resolution),
        ] {
            if w == 0 || h == 0 {
                return bad(format!(
                    "{what} {w}x{h} is empty: both sides must be at least 1"
                ));
            }
        }
        let s = &self.style;
        if !(s.point_size.is_finite() && s.point_size > 0.0 && s.intensity.is_finite()) {
            return bad("point size must be above 0 and intensity finite".into());
        }
        self.fire.validate()
    }

    /// Number of particles.
    pub fn particle_count(&self) -> u64 {
        self.particles[0] as u64 * self.particles[1] as u64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_are_valid_and_unknown_names_list_them() {
        for name in BUILTIN {
            let f = load(name).unwrap();
            f.validate().unwrap();
            if f.fire.is_some() {
                Scene::from_file(&f).unwrap().validate().unwrap();
            }
        }
        let msg = load("smok").unwrap_err().to_string();
        assert!(msg.contains("smok") && msg.contains("fire"), "{msg}");
    }

    #[test]
    fn meaningless_values_are_rejected() {
        let mut s = fire();
        s.dt = f32::NAN;
        assert!(s.validate().is_err());
        s.dt = -0.1;
        assert!(s.validate().is_err());
        let mut s = fire();
        s.substeps = 0;
        assert!(s.validate().is_err());
        let mut s = fire();
        s.fire.life_max = s.fire.max_age * 2.0;
        assert!(s.validate().is_err());
        let mut s = fire();
        s.fire.buoyancy.y = f32::INFINITY;
        assert!(s.validate().is_err());
    }
}
