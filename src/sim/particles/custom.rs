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

/// The name a custom force's text is added under: unique to its index, path and text, and
/// never the name of one of texflow's files, so that a user's `common/rng.glsl` is not shadowed
/// by the built-in one, and one file named twice is spliced twice (as two forces).
fn source_key(i: usize, path: &str, text: &str) -> String {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (path, text).hash(&mut h);
    format!("custom-force-{i}-{:016x}", h.finish())
}

/// The text of each custom force: read and checked when the scene was loaded, or read now.
fn sources(scene: &SceneFile) -> Result<Vec<String>> {
    scene
        .forces
        .custom
        .iter()
        .enumerate()
        .map(|(i, c)| match &c.source {
            Some(t) => Ok(t.clone()),
            None => crate::scene::read_glsl(&c.glsl).map_err(|m| {
                Error::InvalidInput(format!(
                    "forces.custom[{i}].glsl: {m}; the path is relative to the scene file"
                ))
            }),
        })
        .collect()
}

/// The fragment shader of the integration pass: `sim/integrate.frag`, or for a scene with
/// custom forces, the root that splices them in front of it.
pub(super) fn integrate_root(scene: &SceneFile) -> Result<String> {
    if scene.forces.custom.is_empty() {
        return Ok("sim/integrate.frag".to_owned());
    }
    let mut root = String::from(
        "// The integration pass with the scene's custom forces (src/sim/particles/custom.rs).\n\
         #include \"common/rng.glsl\"\n#include \"sim/fields.glsl\"\n",
    );
    let mut keys = Vec::new();
    for (i, (c, text)) in scene.forces.custom.iter().zip(sources(scene)?).enumerate() {
        let key = source_key(i, &c.glsl, &text);
        add_runtime_source(&key, &text);
        root += &format!("#define force custom_force_{i}\n#include \"{key}\"\n#undef force\n");
        keys.push(key);
    }
    root += &format!(
        "#define N_CUSTOM {}\n#include \"sim/integrate.frag\"\n",
        scene.forces.custom.len()
    );
    let name = format!("custom-integrate:{}", keys.join("+"));
    add_runtime_source(&name, &root);
    Ok(name)
}

/// Compiles the integration pass of `scene` on `ctx`, as [`super::ParticleSim::new`] does, so
/// that `scene check` refuses what `render` would (scenes without custom forces compile only
/// texflow's own shaders, which the tests compile).
pub fn check_custom_forces(ctx: &crate::gl::Context, scene: &SceneFile) -> Result<()> {
    if scene.forces.custom.is_empty() {
        return Ok(());
    }
    let defines = super::Features::of(scene).defines();
    crate::gl::Program::new(
        ctx,
        crate::gl::FULLSCREEN_VERTEX,
        &integrate_root(scene)?,
        &defines,
    )
    .map(drop)
    .map_err(|e| user_error(scene, e))
}

/// A compile error in a user's file becomes an input error that names the file and line (not
/// under `glsl/`); other errors pass through. The location is the first line of the driver's
/// log that points into a user's file (Mesa may place an error in an expression of the user's
/// file at the root's source number, so the log's first location is not always the one).
pub(super) fn user_error(scene: &SceneFile, e: Error) -> Error {
    match e {
        Error::ShaderCompile { file, line, log } if is_runtime_source(&file) => {
            // The log names the sources by key: name the user's files instead.
            let mut log = log;
            let mut file = file;
            for (i, c) in scene.forces.custom.iter().enumerate() {
                let text = sources(scene).ok().and_then(|t| t.into_iter().nth(i));
                if let Some(text) = text {
                    let key = source_key(i, &c.glsl, &text);
                    log = log.replace(&key, &c.glsl);
                    if file == key {
                        file.clone_from(&c.glsl);
                    }
                }
            }
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
