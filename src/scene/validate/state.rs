//! `[[state]]`: the user's per-particle state. Names must be GLSL identifiers of their own, the
//! expressions single GLSL expressions; the collision stage and the fluid carry the states along
//! their sorts. A `pair` exchange needs a neighbour search, the exact detection's or the
//! fluid's, within its cell.
//!
//! Every update reads the previous step's values of every state, so the order of the states'
//! passes does not matter and no update can depend on another's result of the same step: there
//! are no cycles to refuse.

use super::{bounded, fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{
    Blending, Detection, DrawMode, DrawPrimitive, Integrator, RenderPath, SceneFile, StateModel,
    StatePassKind, UpdatePasses, UserState, MAX_STATE_EXPRESSION, MAX_USER_STATES,
};

use Key::{Index as I, Name as N};

/// The names the expressions read besides the states (src/sim/particles/user_state.rs).
pub const STATE_INPUTS: [&str; 9] = [
    "x", "v", "life", "age", "type", "random", "index", "time", "dt",
];

/// GLSL's words a state may not be named after: keywords, types and the built-in functions
/// an expression is likely to call.
const GLSL_WORDS: &[&str] = &[
    "attribute",
    "const",
    "uniform",
    "varying",
    "layout",
    "centroid",
    "flat",
    "smooth",
    "break",
    "continue",
    "do",
    "for",
    "while",
    "switch",
    "case",
    "default",
    "if",
    "else",
    "in",
    "out",
    "inout",
    "float",
    "int",
    "uint",
    "void",
    "bool",
    "true",
    "false",
    "invariant",
    "discard",
    "return",
    "struct",
    "precision",
    "highp",
    "mediump",
    "lowp",
    "sampler2d",
    "vec2",
    "vec3",
    "vec4",
    "ivec2",
    "ivec3",
    "ivec4",
    "uvec2",
    "uvec3",
    "uvec4",
    "bvec2",
    "bvec3",
    "bvec4",
    "mat2",
    "mat3",
    "mat4",
    "abs",
    "sign",
    "floor",
    "ceil",
    "fract",
    "mod",
    "min",
    "max",
    "clamp",
    "mix",
    "step",
    "smoothstep",
    "length",
    "distance",
    "dot",
    "cross",
    "normalize",
    "reflect",
    "sqrt",
    "exp",
    "exp2",
    "log",
    "log2",
    "pow",
    "sin",
    "cos",
    "tan",
    "asin",
    "acos",
    "atan",
    "radians",
    "degrees",
    "main",
    "texture",
    "texelfetch",
    "common",
    "input",
    "output",
    "filter",
    "sizeof",
    "cast",
    "namespace",
    "using",
    "static",
    "inline",
    "external",
    "interface",
    "long",
    "short",
    "double",
    "half",
    "fixed",
    "unsigned",
    "goto",
    "class",
    "union",
    "enum",
    "typedef",
    "template",
    "this",
    "packed",
    "volatile",
    "public",
    "noinline",
    "asm",
    "active",
    "superp",
    "patch",
    "sample",
    "subroutine",
    "isnan",
    "isinf",
];

/// `[[state]]`, and `render.color`, which reads the states.
pub(super) fn state(s: &SceneFile) -> Check {
    if let Some(c) = &s.render.color {
        render_color(s, "color", c)?;
    }
    if let Some(c) = &s.render.size {
        render_color(s, "size", c)?;
    }
    if let Some(c) = &s.render.rotation {
        render_color(s, "rotation", c)?;
    }
    if s.state.is_empty() {
        return Ok(());
    }
    if s.state.len() > MAX_USER_STATES {
        return fail(
            path(&[N("state"), I(MAX_USER_STATES)]),
            format!(
                "{} [[state]] tables: at most {MAX_USER_STATES} (each is a texture the passes \
                 sample); pack values into the four channels of one",
                s.state.len()
            ),
        );
    }
    let at0 = path(&[N("state"), I(0)]);
    if s.fire.is_some() {
        return fail(
            at0,
            "[[state]] is for the particle system; the thesis's fire has no user state: remove \
             [[state]] or [fire]",
        );
    }
    if s.simulation == StateModel::Stateless {
        return fail(
            at0,
            "[[state]] is updated step by step, a stateless scene has no steps to carry it: \
             remove [[state]] or simulation = \"stateless\"",
        );
    }
    for (i, st) in s.state.iter().enumerate() {
        let at = |k| path(&[N("state"), I(i), N(k)]);
        name(at("name"), &st.name)?;
        if let Some(j) = s.state[..i].iter().position(|o| o.name == st.name) {
            return fail(
                at("name"),
                format!(
                    "state `{}` is named twice (also [[state]] {j}): give each its own name",
                    st.name
                ),
            );
        }
        expression(at("init"), "init", &st.init)?;
        if let Some(u) = &st.update {
            expression(at("update"), "update", u)?;
        }
        exchange(s, i, st)?;
    }
    integrated(s)
}

/// Render targets every OpenGL ES 3.0 context has (`GL_MAX_DRAW_BUFFERS` is at least 4).
pub const PORTABLE_DRAW_BUFFERS: usize = 4;

/// `pass = "integrate"`: an explicit integrator's single MRT pass, with a target to spare per
/// state.
fn integrated(s: &SceneFile) -> Check {
    let on: Vec<usize> = (0..s.state.len())
        .filter(|&i| s.state[i].pass == StatePassKind::Integrate)
        .collect();
    let Some(&first) = on.first() else {
        return Ok(());
    };
    let at = |i: usize| path(&[N("state"), I(i), N("pass")]);
    let why = if s.integrator == Integrator::Verlet {
        Some("Verlet's pass writes the next positions alone (the velocity is implied)")
    } else if s.passes == UpdatePasses::Separate {
        Some("passes = \"separate\" draws the integration without multiple render targets")
    } else {
        None
    };
    if let Some(why) = why {
        return fail(
            at(first),
            format!(
                "pass = \"integrate\" writes the state as one more render target of the \
                 integration pass, and {why}: use pass = \"own\" (a pass of its own)"
            ),
        );
    }
    let spin = s.collisions.as_ref().is_some_and(|c| c.spin);
    let own = 2 + spin as usize;
    if own + on.len() > PORTABLE_DRAW_BUFFERS {
        let last = on[PORTABLE_DRAW_BUFFERS - own];
        return fail(
            at(last),
            format!(
                "the integration pass writes {own} targets (position, velocity{}) and one per \
                 state with pass = \"integrate\": {} in all, above the {PORTABLE_DRAW_BUFFERS} \
                 every OpenGL ES 3.0 context can draw at once (GL_MAX_DRAW_BUFFERS); use \
                 pass = \"own\" for this state",
                if spin { ", spin" } else { "" },
                own + on.len()
            ),
        );
    }
    Ok(())
}

/// The names a `pair` expression reads besides the inputs and the states, taken for states
/// of a scene with one.
pub const PAIR_INPUTS: [&str; 2] = ["other", "r"];

/// State `i`'s `pair` and `radius`: an expression, a reach within the exact search's cell.
fn exchange(s: &SceneFile, i: usize, st: &UserState) -> Check {
    let at = |k| path(&[N("state"), I(i), N(k)]);
    let Some(pair) = &st.pair else {
        return match st.radius {
            Some(_) => fail(
                at("radius"),
                "radius is the reach of `pair`: add pair (a GLSL vec4 expression summed over \
                 the neighbours closer than radius), or remove radius",
            ),
            None => Ok(()),
        };
    };
    expression(at("pair"), "pair", pair)?;
    if let Some(j) = s
        .state
        .iter()
        .position(|o| PAIR_INPUTS.contains(&o.name.as_str()))
    {
        return fail(
            path(&[N("state"), I(j), N("name")]),
            format!(
                "state name `{}` is taken in a scene with `pair`: the pair expressions read \
                 the neighbour as `other` and the distance as `r`; choose another name",
                s.state[j].name
            ),
        );
    }
    let Some(r) = st.radius else {
        return fail(
            at("pair"),
            "pair needs radius: the distance (m) below which a neighbour is summed, at most \
             the neighbour search's reach (the exact collision detection's cell, or the fluid's \
             2h)",
        );
    };
    bounded(at("radius"), "radius", &[r])?;
    let exact = (s.collisions.as_ref()).filter(|c| c.detection == Detection::Exact);
    let (cell, what, fix) =
        match (exact, &s.fluid) {
            (Some(c), _) => (
                c.cell.unwrap_or(2.0 * c.radius),
                "the collision cell",
                "the reach of the search of the 27 cells around a particle; raise collisions.cell",
            ),
            (None, Some(f)) => (
                2.0 * f.h(),
                "the fluid's reach 2h",
                "the kernel's support, within which its search's runs are bounded; raise \
                 fluid.smoothing",
            ),
            (None, None) => return fail(
                at("pair"),
                "pair sums over the neighbours a search finds, the exact collision detection's \
                 or the fluid's: add [collisions] with detection = \"exact\" (its cell bounds \
                 radius), or [fluid]",
            ),
        };
    if !(r > 0.0 && r <= cell) {
        return fail(
            at("radius"),
            format!("radius {r} m must be above 0 and at most {what} {cell} m ({fix})"),
        );
    }
    Ok(())
}

/// `render.color`, `render.size` or `render.rotation` (`key`): an expression the particle renderer can evaluate
/// at the particle's texel.
fn render_color(s: &SceneFile, key: &'static str, c: &str) -> Check {
    let at = path(&[N("render"), N(key)]);
    expression(at.clone(), &format!("render.{key}"), c)?;
    let why = if s.fire.is_some() {
        Some("the thesis's fire is coloured by its own ramp")
    } else if s.render.mode == DrawMode::Surface {
        Some("mode = \"surface\" draws the connected surface, not the particles")
    } else if key == "rotation" && s.render.mode != DrawMode::Sprites {
        Some("it turns the sprites' atlas tiles; use mode = \"sprites\"")
    } else if key == "rotation" && s.render.primitive == DrawPrimitive::Stretched {
        Some("stretched quads lay the sprite along the motion, unturned")
    } else if s.render.path == RenderPath::VertexBuffer {
        Some(
            "path = \"vertex_buffer\" hands the vertex stage a buffer without the user states; \
             use path = \"texture_fetch\"",
        )
    } else if s.render.blending == Blending::Alpha {
        Some(
            "blending = \"alpha\" sorts the particles by depth and gathers position and static \
             only, so the user states would no longer match; use \"additive\" or \
             \"multiplicative\"",
        )
    } else {
        None
    };
    match why {
        Some(why) => fail(at, format!("render.{key} cannot be used here: {why}")),
        None => Ok(()),
    }
}

/// A state's name: a lower-case GLSL identifier of its own.
fn name(at: Vec<Key>, n: &str) -> Check {
    let ok = n.len() <= 32
        && n.starts_with(|c: char| c.is_ascii_lowercase())
        && n.chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')
        && !n.contains("__");
    if !ok {
        return fail(
            at,
            format!(
                "state name `{n}` is not a name GLSL can read: use 1 to 32 lower-case letters, \
                 digits and single `_`, starting with a letter (e.g. \"temperature\")"
            ),
        );
    }
    let taken = STATE_INPUTS.contains(&n)
        || GLSL_WORDS.contains(&n)
        || ["gl_", "u_", "o_", "a_", "v_"]
            .iter()
            .any(|p| n.starts_with(p));
    if taken {
        return fail(
            at,
            format!(
                "state name `{n}` is taken: the expressions read {} by those names, and GLSL \
                 reserves its keywords, types and built-in functions; choose another name",
                STATE_INPUTS.join(", ")
            ),
        );
    }
    Ok(())
}

/// One GLSL expression: not empty, no statements, blocks or directives.
fn expression(at: Vec<Key>, key: &str, e: &str) -> Check {
    if e.trim().is_empty() {
        return fail(
            at,
            format!("{key} is empty: give a GLSL vec4 expression, e.g. \"vec4(0.0)\""),
        );
    }
    if e.len() > MAX_STATE_EXPRESSION {
        return fail(
            at,
            format!(
                "{key} is {} bytes, above {MAX_STATE_EXPRESSION}: move the code into a function \
                 of the state's `glsl` file",
                e.len()
            ),
        );
    }
    if let Some(c) = e
        .chars()
        .find(|c| matches!(c, ';' | '{' | '}' | '#' | '\\') || (c.is_control() && *c != '\n'))
    {
        return fail(
            at,
            format!(
                "{key} holds {c:?}: it is one GLSL vec4 expression, not statements, blocks or \
                 directives; put those in a function of the state's `glsl` file"
            ),
        );
    }
    Ok(())
}
