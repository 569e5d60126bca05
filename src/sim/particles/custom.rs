//! User forces (`[[forces.custom]] glsl = "wind.glsl"`): GLSL files defining
//! `vec3 force(vec3 x, vec3 v, float age, int type)`, compiled into the integration pass with
//! the same includes as the built-in forces (random numbers, fields).
//!
//! The pass of such a scene is compiled from a root source added at run time
//! ([`crate::gl::source::add_runtime_source`]): it splices `common/rng.glsl` and
//! `sim/fields.glsl`, then each user file with `force` renamed `custom_force_<i>`, defines
//! `N_CUSTOM`, and includes `sim/integrate.frag`, whose `acceleration` (glsl/sim/forces.glsl)
//! adds each user force, divided by the particle's mass (Latta eq. 2). Each user file is its own
//! source number in the `#line` directives, so a compile error names the user's file and line.
//!
//! Only the integration pass has the user forces: the Verlet start of a newborn particle and
//! the collision stage use the built-in forces alone.

use crate::error::{Error, Result};
use crate::gl::source::{add_runtime_source, is_runtime_source};
use crate::scene::SceneFile;

/// The fragment shader of the integration pass: `sim/integrate.frag`, or for a scene with
/// custom forces, the root that splices them in front of it (read from the files now).
pub(super) fn integrate_root(scene: &SceneFile) -> Result<String> {
    if scene.forces.custom.is_empty() {
        return Ok("sim/integrate.frag".to_owned());
    }
    let mut root = String::from(
        "// The integration pass with the scene's custom forces (src/sim/particles/custom.rs).\n\
         #include \"common/rng.glsl\"\n#include \"sim/fields.glsl\"\n",
    );
    for (i, c) in scene.forces.custom.iter().enumerate() {
        let text = std::fs::read_to_string(&c.glsl).map_err(|e| {
            Error::InvalidInput(format!(
                "forces.custom[{i}].glsl: cannot read `{}`: {e}; the path is relative to the \
                 scene file",
                c.glsl
            ))
        })?;
        add_runtime_source(&c.glsl, &text);
        root += &format!(
            "#define force custom_force_{i}\n#include \"{}\"\n#undef force\n",
            c.glsl
        );
    }
    root += &format!(
        "#define N_CUSTOM {}\n#include \"sim/integrate.frag\"\n",
        scene.forces.custom.len()
    );
    let name = format!(
        "custom-integrate:{}",
        scene
            .forces
            .custom
            .iter()
            .map(|c| c.glsl.as_str())
            .collect::<Vec<_>>()
            .join("+")
    );
    add_runtime_source(&name, &root);
    Ok(name)
}

/// A compile error in a user's file becomes an input error that names the file and line (not
/// under `glsl/`); other errors pass through. The location is the first line of the driver's
/// log that points into a user's file (Mesa may place an error in an expression of the user's
/// file at the root's source number, so the log's first location is not always the one).
pub(super) fn user_error(scene: &SceneFile, e: Error) -> Error {
    match e {
        Error::ShaderCompile { file, line, log } if is_runtime_source(&file) => {
            let at = log.lines().find_map(|l| {
                scene.forces.custom.iter().find_map(|c| {
                    let rest = l.strip_prefix(c.glsl.as_str())?.strip_prefix(':')?;
                    let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
                    Some(format!("{}:{digits}", c.glsl))
                })
            });
            let at = at.unwrap_or(format!("{file}:{line}"));
            Error::InvalidInput(format!(
                "custom force {at}: the GLSL does not compile; it must define \
                 `vec3 force(vec3 x, vec3 v, float age, int type)`:\n{log}"
            ))
        }
        e => e,
    }
}
