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
//! - `curve`: emitter values that change over time ([`curve::Animated`]);
//! - `builtin`: loading a scene by built-in name or path ([`load`]);
//! - `mesh`: the OBJ meshes of distance fields, read while parsing ([`read_obj`]);
//! - `custom`: the custom forces' GLSL files, read and checked before compiling ([`load_custom`]).
//! - `set`: `--set KEY=VALUE`, keys changed from the command line ([`parse_with`]);
//! - `suggest`: "did you mean" for mistyped scene names and keys ([`closest`]).

mod builtin;
pub mod curve;
mod custom;
mod field_files;
mod locate;
mod mesh;
mod parse;
mod resize;
mod schema;
mod set;
mod sources;
mod suggest;
mod validate;

pub use builtin::{builtin, fire, load, load_source, summary, DEFAULT_SCENE, THESIS_SCENE};
pub use custom::{
    check_glsl, check_pair_glsl, key_place, load_custom, read_glsl, read_pair_glsl,
    read_state_glsl, state_places, PAIR_SIGNATURE,
};
pub use field_files::{grey_image, npy_field, MAX_FIELD_FILE};
pub use locate::{Invalid, Key};
pub use mesh::{read_obj, Triangle, MAX_TRIANGLES};
pub use parse::{check_limits, check_point_size, parse, SizeLimits};
pub use resize::MAX_SCALED_POINT_SIZE;
pub use schema::*;
pub use set::{parse_with, Setting};
pub use sources::{builtin_source, BUILTIN, BUILTIN_MESHES, BUILTIN_SOURCES};
pub use suggest::{closest, did_you_mean, edit_distance};
pub use validate::{
    fire_section, has_curves, largest_exact_cell, run_capacity, CapacityWarning,
    ChildCapacityWarning, ChildLayout, ChildRange, EXACT_SCAN, MAX_DEM_OMEGA_DT, MAX_LATTICE_CELLS,
    MAX_LIGHT_RESOLUTION, MAX_NEIGHBOURS, MAX_SLICES, STATE_INPUTS,
};
pub use validate::{fluid_cells, FLUID_CFL, FLUID_FORCE, FLUID_VISCOUS, MAX_SMOOTHING_RATIO};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn meaningless_values_are_rejected() {
        let mut s = fire();
        s.time.dt = f32::NAN;
        assert!(s.check().is_err());
        s.time.dt = -0.1;
        assert!(s.check().is_err());
        let mut s = fire();
        s.time.substeps = 0;
        assert!(s.check().is_err());
        let f = |s: &mut SceneFile| s.fire.as_mut().unwrap().clone();
        let mut s = fire();
        let mut section = f(&mut s);
        section.life[1] = section.max_age * 2.0;
        s.fire = Some(section);
        // Changed after parsing, still reported at the file's line and column.
        let e = s.check().unwrap_err().to_string();
        assert!(
            e.contains("fire-points (built-in):24:") && e.contains("max_age"),
            "{e}"
        );
        let mut s = fire();
        let mut section = f(&mut s);
        section.buoyancy[1] = f32::INFINITY;
        s.fire = Some(section);
        assert!(s.check().is_err());
    }
}
