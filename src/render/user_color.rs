//! `render.color`: the particles' colour by the user's GLSL expression of the user states
//! (`[[state]]`), evaluated in the vertex stage (`glsl/render/particle.vert`, `USER_COLOR`) at
//! the particle's texel, so texture fetch only. The vertex shader is compiled from a root added
//! at run time: a sampler and a macro per state, the expression as `user_color`, then
//! `render/particle.vert`.

use crate::error::Error;
use crate::gl::source::{add_runtime_source, is_runtime_source};
use crate::scene::SceneFile;

/// The user's colour expression and the states it may read, in the scene's order.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct UserColor {
    /// The GLSL `vec4` expression.
    pub expression: String,
    /// The user states' names (sampler `u_user_state_i` is state `i`).
    pub states: Vec<String>,
    /// Where the expression is in the scene file, for compile errors.
    #[serde(skip)]
    pub place: Option<String>,
}

impl UserColor {
    /// The scene's `render.color`, if any.
    pub fn of(scene: &SceneFile) -> Option<Self> {
        Some(UserColor {
            expression: scene.render.color.clone()?,
            states: scene.state.iter().map(|s| s.name.clone()).collect(),
            place: crate::scene::key_place(scene, &["render", "color"]),
        })
    }

    /// The vertex shader's root, added as a runtime source; returns its name.
    pub(super) fn root(&self) -> String {
        // A name unique to the text, never one of texflow's files.
        let key = {
            use std::hash::{Hash, Hasher};
            let mut h = std::collections::hash_map::DefaultHasher::new();
            self.expression.hash(&mut h);
            format!("render-color-{:016x}", h.finish())
        };
        add_runtime_source(&key, &self.expression);
        let mut root = String::from("// render.color (src/render/user_color.rs).\n");
        let (mut define, mut undef) = (String::new(), String::new());
        for (i, name) in self.states.iter().enumerate() {
            root += &format!("uniform sampler2D u_user_state_{i};\n");
            define += &format!("#define {name} texelFetch(u_user_state_{i}, user_texel, 0)\n");
            undef += &format!("#undef {name}\n");
        }
        root += &format!(
            "{define}vec4 user_color(ivec2 user_texel, vec4 color, vec3 x, float life, int type, \
             float age) {{\n    return vec4(\n#include \"{key}\"\n    );\n}}\n{undef}\
             #define USER_COLOR 1\n#include \"render/particle.vert\"\n"
        );
        let name = format!("user-color:{key}");
        add_runtime_source(&name, &root);
        name
    }

    /// A compile error of the root becomes an input error naming `render.color` and its place.
    pub(super) fn error(&self, e: Error) -> Error {
        match e {
            Error::ShaderCompile { file, log, .. } if is_runtime_source(&file) => {
                let log: Vec<&str> = (log.lines())
                    .filter(|l| !l.contains(": warning: "))
                    .map(|l| l.find("): ").map_or(l, |k| &l[k + 3..]))
                    .collect();
                Error::InvalidInput(format!(
                    "render.color{}: the GLSL does not compile; it is a GLSL vec4 expression of \
                     color, x, life, age, type and the user states' names:\n{}",
                    self.place
                        .as_deref()
                        .map_or(String::new(), |p| format!(" ({p})")),
                    log.join("\n")
                ))
            }
            e => e,
        }
    }
}
