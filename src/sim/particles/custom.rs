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
use crate::sim::user_glsl::{source_key, user_compile_error, Renamed};

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
/// custom forces or states updated in the pass (`pass = "integrate"`, user_state_mrt.rs), the
/// root that splices them in front of it and after it.
pub(super) fn integrate_root(scene: &SceneFile) -> Result<String> {
    let integrated = !super::user_state::integrated(scene).is_empty();
    if scene.forces.custom.is_empty() && !integrated {
        return Ok("sim/integrate.frag".to_owned());
    }
    let mut root = String::from(
        "// The integration pass with the scene's custom forces (src/sim/particles/custom.rs).\n\
         #include \"common/rng.glsl\"\n#include \"sim/fields.glsl\"\n",
    );
    // The forces read the user states by name (`[[state]]`, user_state.rs).
    let (uniforms, define, undef) = super::user_state::declarations(scene);
    root += &uniforms;
    let mut keys = Vec::new();
    for (i, (c, text)) in scene.forces.custom.iter().zip(sources(scene)?).enumerate() {
        let key = source_key("custom-force", i, &c.glsl, &text);
        add_runtime_source(&key, &text);
        root += &format!(
            "{define}#define force custom_force_{i}\n#include \"{key}\"\n#undef force\n{undef}"
        );
        keys.push(key);
    }
    if !scene.forces.custom.is_empty() {
        root += &format!("#define N_CUSTOM {}\n", scene.forces.custom.len());
    }
    if integrated {
        root += "#define USER_STATE_OUTPUTS 1\n";
    }
    root += "#include \"sim/integrate.frag\"\n";
    if integrated {
        let (tail, states) = super::user_state::integrate_tail(scene)?;
        root += &tail;
        keys.push(states);
    }
    let name = format!("custom-integrate:{}", keys.join("+"));
    add_runtime_source(&name, &root);
    Ok(name)
}

/// Compiles the integration pass of `scene` on `ctx`, as [`super::ParticleSim::new`] does, and
/// its pair forces' pass, so that `scene check` refuses what `render` would (scenes without custom forces compile only
/// texflow's own shaders, which the tests compile).
pub fn check_custom_forces(ctx: &crate::gl::Context, scene: &SceneFile) -> Result<()> {
    let defines = super::Features::of(scene).defines();
    crate::sim::collide::check_pair_forces(ctx, scene, &defines)?;
    super::check_user_states(ctx, scene)?;
    let root = integrate_root(scene)?;
    if !is_runtime_source(&root) {
        return Ok(());
    }
    crate::gl::Program::new(ctx, crate::gl::FULLSCREEN_VERTEX, &root, &defines)
        .map(drop)
        .map_err(|e| user_error(scene, e))
}

/// A compile error in a user's file becomes an input error that names the file and line
/// ([`user_compile_error`]), one in a state's expressions names the state
/// (`pass = "integrate"`); other errors pass through.
pub(super) fn user_error(scene: &SceneFile, e: Error) -> Error {
    // An error in a state's expressions (`pass = "integrate"`) is the state's to name.
    let in_state = matches!(&e, Error::ShaderCompile { file, .. } if file.starts_with("state-"));
    if in_state || scene.forces.custom.is_empty() {
        return super::user_state::integrate_error(scene, e);
    }
    let texts = sources(scene).unwrap_or_default();
    let files: Vec<(String, String)> = (scene.forces.custom.iter().zip(texts).enumerate())
        .map(|(i, (c, text))| {
            (
                source_key("custom-force", i, &c.glsl, &text),
                c.glsl.clone(),
            )
        })
        .collect();
    user_compile_error(
        e,
        &files,
        "custom force",
        "vec3 force(vec3 x, vec3 v, float age, int type)",
        Renamed {
            name: "force",
            prefix: "custom_force_",
        },
    )
}
