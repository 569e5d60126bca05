//! `render.color`, `render.size` and `render.rotation`: the particles' colour, size and sprite
//! angle by the user's GLSL expressions of the user states (`[[state]]`), evaluated in the vertex
//! stage (`glsl/render/particle.vert`, `USER_COLOR`, `USER_SIZE`, `USER_ROTATION`) at the
//! particle's texel, so texture fetch only. The vertex shader is compiled from a root added at
//! run time: a sampler and a macro per state, the expressions as `user_color`, `user_size` and
//! `user_rotation`, then `render/particle.vert`.

use crate::error::Error;
use crate::gl::source::add_runtime_source;
use crate::scene::SceneFile;

/// The user's colour and size expressions and the states they may read, in the scene's order.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct UserColor {
    /// The GLSL `vec4` expression of the colour, if any.
    pub expression: Option<String>,
    /// The GLSL `float` expression of the size in pixels, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub size: Option<String>,
    /// The GLSL `float` expression of the sprite's angle in degrees, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotation: Option<String>,
    /// The user states' names (sampler `u_user_state_i` is state `i`).
    pub states: Vec<String>,
    /// Where the expressions are in the scene file, for compile errors.
    #[serde(skip)]
    pub place: Option<String>,
}

impl UserColor {
    /// The scene's `render.color`, `render.size` and `render.rotation`, if it has any.
    pub fn of(scene: &SceneFile) -> Option<Self> {
        let r = &scene.render;
        let (color, size, rotation) = (&r.color, &r.size, &r.rotation);
        if color.is_none() && size.is_none() && rotation.is_none() {
            return None;
        }
        let given = [
            ("color", color.is_some()),
            ("size", size.is_some()),
            ("rotation", rotation.is_some()),
        ];
        let places: Vec<String> = given
            .into_iter()
            .filter(|(_, on)| *on)
            .filter_map(|(k, _)| {
                let at = crate::scene::key_place(scene, &["render", k])?;
                Some(format!("render.{k} at {at}"))
            })
            .collect();
        Some(UserColor {
            expression: color.clone(),
            size: size.clone(),
            rotation: rotation.clone(),
            states: scene.state.iter().map(|s| s.name.clone()).collect(),
            place: (!places.is_empty()).then(|| places.join(", ")),
        })
    }

    /// The vertex shader's root, added as a runtime source; returns its name.
    pub(super) fn root(&self) -> String {
        // A name unique to the text, never one of texflow's files.
        let key = |what: &str, text: &str| {
            use std::hash::{Hash, Hasher};
            let mut h = std::collections::hash_map::DefaultHasher::new();
            text.hash(&mut h);
            let key = format!("render-{what}-{:016x}", h.finish());
            add_runtime_source(&key, text);
            key
        };
        let mut root = String::from(
            "// render.color, render.size, render.rotation (src/render/user_color.rs).\n",
        );
        let (mut define, mut undef) = (String::new(), String::new());
        for (i, name) in self.states.iter().enumerate() {
            root += &format!("uniform sampler2D u_user_state_{i};\n");
            define += &format!("#define {name} texelFetch(u_user_state_{i}, user_texel, 0)\n");
            undef += &format!("#undef {name}\n");
        }
        root += &define;
        // Each expression a function of the vertex stage's inputs, returning what it replaces
        // (colour, size, angle), with the define that turns its call on.
        let exprs = [
            (&self.expression, "color", "vec4", "color", "USER_COLOR"),
            (&self.size, "size", "float", "size", "USER_SIZE"),
            (
                &self.rotation,
                "rotation",
                "float",
                "angle",
                "USER_ROTATION",
            ),
        ];
        let mut keys = Vec::new();
        for (expr, what, ty, arg, _) in exprs {
            if let Some(e) = expr {
                let k = key(what, e);
                root += &format!(
                    "{ty} user_{what}(ivec2 user_texel, {ty} {arg}, vec3 x, float life, int type, \
                     float age) {{\n    return {ty}(\n#include \"{k}\"\n    );\n}}\n"
                );
                keys.push(k);
            }
        }
        root += &undef;
        for (expr, .., define) in exprs {
            if expr.is_some() {
                root += &format!("#define {define} 1\n");
            }
        }
        root += "#include \"render/particle.vert\"\n";
        let name = format!("user-render:{}", keys.join("+"));
        add_runtime_source(&name, &root);
        name
    }

    /// A compile error of the root becomes an input error naming `render.color` and its place.
    pub(super) fn error(&self, e: Error) -> Error {
        match e {
            // Any error of the user's program, wherever the driver places it.
            Error::ShaderCompile { log, .. } => {
                let log: Vec<&str> = (log.lines())
                    .filter(|l| !l.contains(": warning: "))
                    .map(|l| l.find("): ").map_or(l, |k| &l[k + 3..]))
                    .collect();
                Error::InvalidInput(format!(
                    "render.color, render.size or render.rotation{}: the GLSL does not compile; \
                     they are GLSL expressions (a vec4 colour, a float size in pixels, a float \
                     angle in degrees) of color, size or angle, x, life, age, type and the user \
                     states' names:\n{}",
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
