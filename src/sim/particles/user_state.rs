//! Per-particle state of the user's own (`[[state]]`; three.js's
//! `GPUComputationRenderer.addVariable`, Latta §3.4.2: "other operations can be applied in
//! separate passes"): one RGBA ping-pong texture per state, one full-screen pass per state and
//! step after the integration (`glsl/sim/user_state.frag`), or with `pass = "integrate"` its
//! update written by the integration pass itself (`user_state_mrt.rs`).
//!
//! Each pass is compiled from a root added at run time: `common/rng.glsl`, the expressions'
//! inputs (`sim/user_state_inputs.glsl`), a sampler and a macro per state (the state's name reads
//! its previous value at the pass's own texel), the states' helper files, the state's `init` and
//! `update` expressions as functions, then `sim/user_state.frag`. Each user text is its own source,
//! so a compile error names the user's file (or the state's key) and line.
//!
//! Semantics: every pass reads the previous step's values of every state and swaps only once all
//! have been drawn, so the states' order does not matter and they cannot form cycles. The
//! integration pass reads the same values through the same macros (custom forces, `custom.rs`).

#[path = "user_state_mrt.rs"]
mod mrt;

use super::{draw_textures, ParticleSim, State};
use crate::error::{Error, Result};
use crate::gl::source::add_runtime_source;
use crate::gl::{
    Context, Defines, PingPong, Program, Sampled, Texture, Uniform, FULLSCREEN_VERTEX,
};
use crate::scene::{SceneFile, StateFormat};
use crate::sim::state::{POSITION, STATIC, VELOCITY};
use crate::sim::user_glsl::{source_key, user_compile_error, Renamed};
pub(super) use mrt::{integrate_tail, integrated};

/// The scene's user states: a ping-pong texture and a pass each.
pub(super) struct UserStates {
    states: Vec<PingPong>,
    programs: Vec<Program>,
    /// The dump's names, `state_NAME` (made once: a dump names its textures by `&'static str`).
    dump_names: Vec<&'static str>,
    /// The states updated in the integration pass (`pass = "integrate"`, `user_state_mrt.rs`):
    /// their own passes draw only the values at the start.
    integrated: Vec<usize>,
    /// The integration pass's targets made so far, by the framebuffers they view
    /// (`user_state_mrt.rs`): made once per combination of ping-pong sides, not every step.
    views: mrt::Views,
}

/// The sampler state `i` is read from in every pass that reads it.
fn sampler(i: usize) -> String {
    format!("u_user_state_{i}")
}

/// GLSL declaring each state's sampler, and the macros that read its previous value by name at
/// the fragment's own texel (any pass over the particle texture: the state pass, integration).
/// The macros are defined around the user's texts alone (`#undef` after them), so that a state's
/// name never replaces a word of texflow's own shaders.
pub(super) fn declarations(scene: &SceneFile) -> (String, String, String) {
    let (mut uniforms, mut define, mut undef) = (String::new(), String::new(), String::new());
    for (i, s) in scene.state.iter().enumerate() {
        uniforms += &format!("uniform sampler2D {};\n", sampler(i));
        define += &format!("#define {} {}\n", s.name, fetch(i));
        undef += &format!("#undef {}\n", s.name);
    }
    (uniforms, define, undef)
}

/// State `i`'s previous value at the fragment's texel.
fn fetch(i: usize) -> String {
    format!("texelFetch({}, ivec2(gl_FragCoord.xy), 0)", sampler(i))
}

/// The helper files' text: read and checked when the scene was loaded, or read now.
fn helper_texts(scene: &SceneFile) -> Result<Vec<Option<(String, String)>>> {
    (scene.state.iter().enumerate())
        .map(|(i, s)| {
            let Some(path) = &s.glsl else { return Ok(None) };
            let text = match &s.source {
                Some(t) => t.clone(),
                None => crate::scene::read_state_glsl(path).map_err(|m| {
                    Error::InvalidInput(format!(
                        "state[{i}].glsl: {m}; the path is relative to the scene file"
                    ))
                })?,
            };
            Ok(Some((path.clone(), text)))
        })
        .collect()
}

/// The user sources of the states' passes, as `(source key, name in messages, text)`: the
/// helper files, then each state's `init` and `update`.
fn user_sources(scene: &SceneFile) -> Result<Vec<(String, String, String)>> {
    let mut out = Vec::new();
    for (i, h) in helper_texts(scene)?.into_iter().enumerate() {
        if let Some((path, text)) = h {
            out.push((source_key("state-glsl", i, &path, &text), path, text));
        }
    }
    for (i, s) in scene.state.iter().enumerate() {
        let update = s.update.clone().unwrap_or_else(|| s.name.clone());
        for (key, text) in [("init", s.init.clone()), ("update", update)] {
            let label = format!("state.{}.{key}", s.name);
            out.push((
                source_key(&format!("state-{key}"), i, &label, &text),
                label,
                text,
            ));
        }
    }
    Ok(out)
}

/// How many of `sources` are helper files: they come first, two expressions per state after.
fn helper_count(scene: &SceneFile, sources: &[(String, String, String)]) -> usize {
    sources.len() - 2 * scene.state.len()
}

/// The root of state `i`'s pass, added as a runtime source; returns its name.
fn root(scene: &SceneFile, i: usize, sources: &[(String, String, String)]) -> String {
    let mut root = String::from(
        "// A user state's pass (src/sim/particles/user_state.rs).\n\
         #include \"common/rng.glsl\"\n#include \"sim/user_state_inputs.glsl\"\n",
    );
    let (uniforms, define, undef) = declarations(scene);
    root += &uniforms;
    root += &define;
    for (key, _, text) in sources {
        add_runtime_source(key, text);
    }
    let helpers = helper_count(scene, sources);
    for (key, _, _) in &sources[..helpers] {
        root += &format!("#include \"{key}\"\n");
    }
    let init = &sources[helpers + 2 * i].0;
    let update = &sources[helpers + 2 * i + 1].0;
    root += &format!(
        "vec4 user_init() {{\n    return vec4(\n#include \"{init}\"\n    );\n}}\n\
         vec4 user_update() {{\n    return vec4(\n#include \"{update}\"\n    );\n}}\n\
         {undef}#define USER_SELF {}\n#include \"sim/user_state.frag\"\n",
        fetch(i)
    );
    let name = format!("user-state:{init}+{update}");
    add_runtime_source(&name, &root);
    name
}

/// A compile error in a helper file becomes an input error naming the file and line (as a
/// custom force's does); one in state `i`'s expressions (which drivers place at the pass's
/// root) names the state, its expressions' places in the scene file and the driver's words.
fn user_error(
    scene: &SceneFile,
    i: usize,
    sources: &[(String, String, String)],
    helpers: usize,
    e: Error,
) -> Error {
    let files: Vec<(String, String)> = (sources[..helpers].iter())
        .map(|(k, label, _)| (k.clone(), label.clone()))
        .collect();
    let inputs = crate::scene::STATE_INPUTS.join(", ");
    match e {
        // Mesa may place an error in a helper at the root: the log names the helper.
        Error::ShaderCompile { ref log, .. } if files.iter().any(|(k, _)| log.contains(k)) => {
            user_compile_error(
                e,
                &files,
                "user state file",
                "the functions (of any names) that `init` and `update` call",
                Renamed {
                    name: "user_update",
                    prefix: "user_update_",
                },
            )
        }
        // Any error of the user's program, wherever the driver places it.
        Error::ShaderCompile { log, .. } => {
            let mut log = log;
            for (k, label, _) in sources {
                log = log.replace(k.as_str(), label);
            }
            // The driver's places are texflow's root: its words are what the user fixes.
            let log: Vec<&str> = (log.lines())
                .filter(|l| !l.contains(": warning: "))
                .map(|l| l.find("): ").map_or(l, |k| &l[k + 3..]))
                .collect();
            let at = crate::scene::state_places(scene).unwrap_or_default();
            Error::InvalidInput(format!(
                "user state `{}`: the GLSL does not compile; `init`, `update` and `pair` are GLSL \
                 vec4 expressions of {inputs}, the states' names (in `pair` also the \
                 neighbour's, `other.x`, `other.NAME`, ..., and the distance `r`) and the \
                 `glsl` file's functions:\n{}\n({at})",
                scene.state[i].name,
                log.join("\n")
            ))
        }
        e => e,
    }
}

/// A compile error of the integration pass in the expressions of the states it updates
/// (`pass = "integrate"`) named as one in their own pass is; other errors pass through.
pub(super) fn integrate_error(scene: &SceneFile, e: Error) -> Error {
    let (Some(&i), Ok(sources)) = (integrated(scene).first(), user_sources(scene)) else {
        return e;
    };
    let helpers = helper_count(scene, &sources);
    user_error(scene, i, &sources, helpers, e)
}

/// The root of state `i`'s exchange pass (`pair`, `glsl/collide/exchange.frag`), added as a
/// runtime source: the states' names read globals there, loaded at the particle's texel and
/// the neighbour's into `other`, whose members are named by the same macros, so that
/// `other.temperature` reads the neighbour's value. Returns its name and the `pair` source.
fn exchange_root(
    scene: &SceneFile,
    i: usize,
    sources: &[(String, String, String)],
) -> (String, (String, String, String)) {
    let value = |k: usize| format!("user_value_{k}");
    let mut root = String::from(
        "// A user state's exchange pass (src/sim/particles/user_state.rs).\n\
         #include \"common/rng.glsl\"\n#include \"sim/user_state_inputs.glsl\"\n",
    );
    let mut members = String::new();
    let (mut define, mut undef, mut own, mut other) =
        (String::new(), String::new(), String::new(), String::new());
    for (k, st) in scene.state.iter().enumerate() {
        root += &format!("uniform sampler2D {};\nvec4 {};\n", sampler(k), value(k));
        members += &format!(" vec4 {};", value(k));
        define += &format!("#define {} {}\n", st.name, value(k));
        undef += &format!("#undef {}\n", st.name);
        own += &format!("    {} = texelFetch({}, t, 0);\n", value(k), sampler(k));
        other += &format!(
            "    other.{} = texelFetch({}, t, 0);\n",
            value(k),
            sampler(k)
        );
    }
    root += &format!(
        "struct UserOther {{ vec3 x; vec3 v; float life; float age; int type; float random; \
         int index;{members} }};\nUserOther other;\nfloat r;\n{define}"
    );
    for (key, _, _) in &sources[..helper_count(scene, sources)] {
        root += &format!("#include \"{key}\"\n");
    }
    let st = &scene.state[i];
    let text = st.pair.clone().unwrap_or_else(|| "vec4(0.0)".into());
    let label = format!("state.{}.pair", st.name);
    let key = source_key("state-pair", i, &label, &text);
    add_runtime_source(&key, &text);
    root += &format!(
        "vec4 user_pair() {{\n    return vec4(\n#include \"{key}\"\n    );\n}}\n{undef}\
         void user_load_self(ivec2 t) {{\n{own}}}\nvoid user_load_other(ivec2 t) {{\n{other}}}\n\
         #define USER_SELF {}\n#include \"collide/exchange.frag\"\n",
        value(i)
    );
    let name = format!("user-exchange:{key}");
    add_runtime_source(&name, &root);
    (name, (key, label, text))
}

/// State `i`'s exchange pass (`pair`), compiled with the collision stage's `defines` (the
/// sorted keys' layout); a compile error names the state and its keys' places.
fn exchange_program(
    ctx: &Context,
    scene: &SceneFile,
    i: usize,
    defines: &Defines,
) -> Result<Program> {
    let mut sources = user_sources(scene)?;
    for (key, _, text) in &sources {
        add_runtime_source(key, text);
    }
    let helpers = helper_count(scene, &sources);
    let (root, pair) = exchange_root(scene, i, &sources);
    sources.push(pair);
    Program::new(ctx, FULLSCREEN_VERTEX, &root, defines)
        .map_err(|e| user_error(scene, i, &sources, helpers, e))
}

impl UserStates {
    /// The scene's states and their passes, none without `[[state]]`.
    pub(super) fn new(
        ctx: &Context,
        scene: &SceneFile,
        defines: &Defines,
        size: [u32; 2],
    ) -> Result<Option<Self>> {
        if scene.state.is_empty() {
            return Ok(None);
        }
        let sources = user_sources(scene)?;
        let helpers = helper_count(scene, &sources);
        let mut states = Vec::new();
        let mut programs = Vec::new();
        for (i, s) in scene.state.iter().enumerate() {
            let format = match s.format {
                StateFormat::Rgba32f => crate::gl::TextureFormat::Rgba32F,
                StateFormat::Rgba16f => crate::gl::TextureFormat::Rgba16F,
            };
            let label = format!("state:{}", s.name);
            let attachment = [crate::gl::Attachment::named("user state")];
            states.push(PingPong::new(
                ctx,
                &label,
                &attachment,
                &[format],
                size[0],
                size[1],
            )?);
            let root = root(scene, i, &sources);
            programs.push(
                Program::new(ctx, FULLSCREEN_VERTEX, &root, defines)
                    .map_err(|e| user_error(scene, i, &sources, helpers, e))?,
            );
        }
        let dump_names = (scene.state.iter())
            .map(|s| &*Box::leak(format!("state_{}", s.name).into_boxed_str()))
            .collect();
        Ok(Some(UserStates {
            states,
            programs,
            dump_names,
            integrated: integrated(scene),
            views: mrt::Views::default(),
        }))
    }

    /// The states' draws of one step, one pass each but for those the integration updates, for
    /// the lines of [`passes`].
    pub(super) fn pass_draws(&self) -> Vec<crate::gl::PassDraw> {
        (self.dump_names.iter().zip(&self.programs).enumerate())
            .filter(|(i, _)| !self.integrated.contains(i))
            .map(|(_, (n, p))| {
                let name = n.strip_prefix("state_").unwrap_or(n);
                crate::gl::PassDraw::of(format!("state {name} ("), p, 1)
            })
            .collect()
    }

    /// The states' textures, for the collision stage and the fluid to carry along their sorts.
    pub(super) fn states_mut(&mut self) -> &mut Vec<PingPong> {
        &mut self.states
    }

    /// State `i`'s next value: the target of a pass that writes it.
    pub(super) fn back(&self, i: usize) -> &crate::gl::Framebuffer {
        self.states[i].back()
    }

    /// Makes state `i`'s next value its current one.
    pub(super) fn swap(&mut self, i: usize) {
        self.states[i].swap();
    }

    /// The states' current values, with the samplers passes read them by.
    pub(super) fn samplers(&self) -> Vec<(String, &Texture)> {
        (self.states.iter().enumerate())
            .map(|(i, pp)| (sampler(i), pp.front().only_texture()))
            .collect()
    }
}

/// The states' own passes as `texflow scene passes` lists them (after the integration), of
/// the states not updated in the integration pass.
pub(super) fn passes(states: &[(String, StateFormat)]) -> Vec<String> {
    (states.iter())
        .map(|(name, format)| {
            let format = match format {
                StateFormat::Rgba32f => "rgba32f",
                StateFormat::Rgba16f => "rgba16f",
            };
            format!(
                "state {name} (Latta §3.4.2, a separate pass): `init` at birth, else `update` \
                 from the previous step's states and this step's position and velocity [{name} \
                 ({format}) ping-pong; every state swapped after all are drawn]"
            )
        })
        .collect()
}

/// The entries of `samplers` that `p` declares, to bind.
pub(super) fn declared<'a>(
    p: &Program,
    samplers: &'a [(String, &'a Texture)],
) -> Vec<(&'a str, Sampled<'a>)> {
    (samplers.iter().filter(|(n, _)| p.declares(n)))
        .map(|(n, t)| (n.as_str(), (*t).into()))
        .collect()
}

/// Compiles the states' passes of `scene`, so that `scene check` refuses what `render` would.
pub fn check_user_states(ctx: &Context, scene: &SceneFile) -> Result<()> {
    let defines = super::Features::of(scene).defines();
    UserStates::new(ctx, scene, &defines, [1, 1])?;
    exchange_programs(ctx, scene, &defines).map(drop)
}

/// The exchange passes of `scene` (`pair`) with each state's index, compiled with the
/// simulation's `defines` as the collision stage's passes are.
pub(super) fn exchange_programs(
    ctx: &Context,
    scene: &SceneFile,
    defines: &Defines,
) -> Result<Vec<(usize, Program)>> {
    // The fluid's search walks runs of up to its own bound (src/sim/fluid/).
    let d = match &scene.fluid {
        Some(_) => {
            // The fluid's search (with its cell-start table where it has one).
            let lattice = crate::sim::fluid::lattice_of(scene);
            let size = scene.particles.size;
            let mut d = crate::sim::collide::cells::search_defines(defines, &lattice, size);
            d.push((
                "EXACT_SCAN".into(),
                crate::sim::fluid::FLUID_SCAN.to_string(),
            ));
            d
        }
        None => crate::sim::collide::exchange_defines(scene, defines),
    };
    (scene.state.iter().enumerate())
        .filter(|(_, s)| s.pair.is_some())
        .map(|(i, _)| Ok((i, exchange_program(ctx, scene, i, &d)?)))
        .collect()
}

impl ParticleSim {
    /// The user states' passes (after the integration, or at the start with `start`: every
    /// texel takes its value at birth), then one swap of them all.
    pub(super) fn user_state_passes(&mut self, start: bool) {
        // The live rows under the min-heap allocator, as the integration: the rows after them
        // hold dead texels, whose values are not read before their next birth sets them.
        let rows = if start {
            self.height
        } else {
            self.active_rows()
        };
        let Some(user) = &mut self.user else {
            return;
        };
        let (position, old, velocity) = match &self.state {
            State::Explicit(pp) => (
                pp.front().texture(POSITION),
                if start { pp.front() } else { pp.back() }.texture(POSITION),
                Some(pp.front().texture(VELOCITY)),
            ),
            State::Verlet(ring) => (
                ring.current().texture(POSITION),
                ring.previous().texture(POSITION),
                None,
            ),
        };
        let samplers = user.samplers();
        let mut own: Vec<(&str, Sampled<'_>)> = vec![
            ("u_position", position.into()),
            ("u_old_position", old.into()),
            ("u_static", self.statics.texture(STATIC).into()),
        ];
        own.extend(velocity.map(|v| ("u_velocity", v.into())));
        own.extend(samplers.iter().map(|(n, t)| (n.as_str(), (*t).into())));
        for (i, (p, pp)) in user.programs.iter().zip(&user.states).enumerate() {
            // The integration pass drew these (user_state_mrt.rs); they swap with the rest.
            if !start && user.integrated.contains(&i) {
                continue;
            }
            let now = [
                ("u_time", Uniform::F32(self.time as f32)),
                ("u_start", Uniform::I32(start as i32)),
            ];
            let now = self.constants.for_draw(p, now);
            let list: Vec<_> = own.iter().copied().filter(|(n, _)| p.declares(n)).collect();
            let t = draw_textures(p, &list, &self.fields);
            self.pass.draw_rows(p, &t, &now, pp.back(), 0, rows);
        }
        for pp in &mut user.states {
            pp.swap();
        }
    }

    /// The user states' current values (`[[state]]`), by name.
    pub fn user_state(&self, name: &str) -> Option<&Texture> {
        let i = self.state_names.iter().position(|s| s == name)?;
        Some(self.user.as_ref()?.states[i].front().only_texture())
    }

    /// Reads user state `name` back, 4 floats per texel.
    pub fn read_user_state(&self, name: &str) -> Result<Vec<f32>> {
        self.user_state(name)
            .ok_or_else(|| {
                Error::InvalidInput(format!("the scene has no [[state]] named `{name}`"))
            })?
            .read_f32()
    }

    /// The user states read back for a dump, named `state_NAME`.
    pub(super) fn read_user_states(&self) -> Result<Vec<(&'static str, Vec<f32>)>> {
        let Some(user) = &self.user else {
            return Ok(Vec::new());
        };
        (user.dump_names.iter().zip(&user.states))
            .map(|(n, pp)| Ok((*n, pp.front().only_texture().read_f32()?)))
            .collect()
    }
}
