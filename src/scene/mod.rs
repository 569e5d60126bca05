//! Scenes: what to simulate and how to look at it. Built-in scenes are compiled into the binary.

pub mod file;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::render::{Camera, PointStyle};
use crate::sim::FireParams;

/// The names of the built-in scenes.
pub const BUILTIN: &[&str] = &["fire"];

/// The scene rendered when none is named.
pub const DEFAULT_SCENE: &str = "fire";

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
    /// The camera.
    pub camera: Camera,
    /// Point size and brightness.
    pub style: PointStyle,
    /// The fire pass's parameters.
    pub fire: FireParams,
}

/// Looks up a built-in scene; an unknown name lists the known ones.
pub fn builtin(name: &str) -> Result<Scene> {
    match name {
        "fire" => Ok(fire()),
        _ => Err(Error::InvalidInput(format!(
            "unknown scene `{name}`: the built-in scenes are {}",
            BUILTIN.join(", ")
        ))),
    }
}

/// The fire of the thesis, at 256×256 particles rendered at 512×512.
pub fn fire() -> Scene {
    let fire = FireParams::default();
    Scene {
        name: "fire".into(),
        particles: [256, 256],
        resolution: [512, 512],
        dt: 1.0 / 60.0,
        substeps: 1,
        camera: Camera {
            target: Vec3::new(0.0, 1.0, 0.0),
            distance: 3.0,
            azimuth: 0.0,
            elevation: 12.0,
            ..Camera::default()
        },
        style: PointStyle {
            point_size: 2.0,
            intensity: 0.15,
            max_age: fire.max_age,
        },
        fire,
    }
}

impl Scene {
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
            builtin(name).unwrap().validate().unwrap();
        }
        let msg = builtin("smok").unwrap_err().to_string();
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
