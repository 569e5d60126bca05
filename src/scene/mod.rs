//! Scenes: what to simulate and how to look at it, read from TOML scene files. Data only: the
//! simulation and the renderers take their sections by value or through `From`.
//!
//! Every error names the file, line and column: syntax errors and wrong types from the TOML
//! parser, unknown keys (`deny_unknown_fields`), non-finite numbers (TOML accepts `nan` and `inf`;
//! scenes do not), and meaningless values (a negative time step, friction outside [0, 1], ...),
//! located through the spans of a second, untyped parse.
//!
//! - `schema/`: the file format ([`SceneFile`]), every section's type and default;
//! - `validate/`: one function per section, called by [`SceneFile::validate`];
//! - `locate`: an error's path into the document ([`Key`], [`Invalid`]) to line and column;
//! - `parse`: [`parse`] and the device-size check [`check_limits`];
//! - `sources`: the built-in scenes' TOML and meshes, compiled in ([`BUILTIN`]);
//! - `builtin`: loading a scene by built-in name or path ([`load`]);
//! - `mesh`: the OBJ meshes of distance fields, read while parsing ([`read_obj`]);
//! - `custom`: the custom forces' GLSL files, read and checked before compiling ([`load_custom`]).
//! - `set`: `--set KEY=VALUE`, keys changed from the command line ([`parse_with`]);
//! - `suggest`: "did you mean" for mistyped scene names and keys ([`closest`]).

mod builtin;
mod custom;
mod field_files;
mod locate;
mod mesh;
mod parse;
mod schema;
mod set;
mod sources;
mod suggest;
mod validate;

pub use builtin::{builtin, fire, load, load_source, DEFAULT_SCENE, THESIS_SCENE};
pub use custom::{
    check_glsl, check_pair_glsl, load_custom, read_glsl, read_pair_glsl, PAIR_SIGNATURE,
};
pub use field_files::{grey_image, npy_field, MAX_FIELD_FILE};
pub use locate::{Invalid, Key};
pub use mesh::{read_obj, Triangle, MAX_TRIANGLES};
pub use parse::{check_limits, check_point_size, parse, SizeLimits};
pub use schema::*;
pub use set::{parse_with, Setting};
pub use sources::{builtin_source, BUILTIN, BUILTIN_MESHES, BUILTIN_SOURCES};
pub use suggest::{closest, did_you_mean, edit_distance};
pub use validate::{
    largest_exact_cell, run_capacity, CapacityWarning, ChildCapacityWarning, ChildLayout,
    ChildRange, EXACT_SCAN, MAX_DEM_OMEGA_DT, MAX_LATTICE_CELLS,
};

use crate::error::{Error, Result};

/// Point size and brightness of the fire's points: `[render]`'s, with the fire's cycle length,
/// from which the renderer derives each particle's age.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PointStyleSection {
    /// Point diameter in pixels (`render.point_size`).
    pub point_size: f32,
    /// Opacity of a newborn particle (`render.intensity`).
    pub intensity: f32,
    /// The fire cycle length (`fire.max_age`).
    pub max_age: f32,
    /// Soft round sprites (`render.mode = "sprites"`) instead of the thesis's square points.
    pub soft: bool,
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
    /// The camera at time 0, and its orbit speed around +y (degrees per simulated second).
    pub camera: CameraSection,
    /// Point size and brightness.
    pub style: PointStyleSection,
    /// Background colour the frame is cleared to (`render.background`).
    pub background: [f32; 3],
    /// The fire pass's parameters.
    pub fire: Fire,
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
        Ok(Scene {
            name: f.name.clone(),
            particles: f.particles.size,
            resolution: f.render.resolution,
            dt: f.time.dt,
            substeps: f.time.substeps,
            camera: f.render.camera.clone(),
            style: PointStyleSection {
                point_size: f.render.point_size,
                intensity: f.render.intensity,
                max_age: fire.max_age,
                soft: f.render.mode == DrawMode::Sprites,
            },
            background: f.render.background,
            fire: fire.clone(),
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
        self.fire.check()
    }

    /// Number of particles.
    pub fn particle_count(&self) -> u64 {
        self.particles[0] as u64 * self.particles[1] as u64
    }
}

impl Fire {
    /// Rejects values the fire pass cannot give a meaning to; the same rules as the file's
    /// `[fire]` validation, for a section changed after parsing.
    pub fn check(&self) -> Result<()> {
        let finite = [
            self.emitter_radius,
            self.speed,
            self.spread,
            self.converge,
            self.turbulence,
            self.damping,
            self.life[0],
            self.life[1],
            self.max_age,
        ]
        .iter()
        .chain(&self.emitter_center)
        .chain(&self.buoyancy)
        .all(|v| v.is_finite());
        let bad = |m: &str| Err(Error::InvalidInput(format!("fire parameters: {m}")));
        if !finite {
            return bad("every value must be finite");
        }
        let [life_min, life_max] = self.life;
        if !(life_min > 0.0 && life_min <= life_max && life_max <= self.max_age) {
            return bad("lives must satisfy 0 < life_min <= life_max <= max_age");
        }
        if self.emitter_radius < 0.0 || self.damping < 0.0 || self.turbulence < 0.0 {
            return bad("emitter_radius, damping and turbulence must not be negative");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        s.fire.life[1] = s.fire.max_age * 2.0;
        assert!(s.validate().is_err());
        let mut s = fire();
        s.fire.buoyancy[1] = f32::INFINITY;
        assert!(s.validate().is_err());
    }
}
