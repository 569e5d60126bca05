//! Shader programs built from the embedded `glsl/` files.

use std::cell::RefCell;
use std::collections::{HashMap, HashSet};

use glow::HasContext;

use super::bindings::{base_name, declared_uniforms, is_sampler};
use super::source::{embedded, map_log, resolve};
use super::{Context, Uniform, WALK_INCLUDE};
use crate::error::{Error, Result};

/// `#define NAME VALUE` pairs prepended to both stages of a program.
pub type Defines = Vec<(String, String)>;

/// A linked vertex + fragment program, deleted on drop.
pub struct Program {
    pub(super) ctx: Context,
    raw: glow::Program,
    name: String,
    /// Each uniform named so far: its location (none for one the optimiser dropped) and the
    /// value it holds, as last uploaded (see [`Context::set_uniform_cache`]).
    uniforms: RefCell<HashMap<String, Slot>>,
    /// This program's number among all made in the process: a key for caches above.
    serial: u64,
    /// Uniform names the resolved sources declare (active or dropped by the optimiser).
    declared: HashSet<String>,
    /// The active samplers, as GL names them.
    samplers: Vec<String>,
    /// What it was built from (boxed: programs are held by value in many passes).
    source: Box<SourceInfo>,
}

/// A uniform's location and the value it holds (none yet).
#[derive(Debug)]
struct Slot {
    location: Option<glow::UniformLocation>,
    value: Option<Uniform>,
}

/// What a program was built from.
#[derive(Debug)]
struct SourceInfo {
    /// The defines it was compiled with.
    defines: Defines,
    /// The files of its sources, includes among them.
    files: Vec<String>,
    /// Whether it walks the cells around every live particle ([`Program::walks_every_live`]).
    walks_every_live: bool,
}

impl std::fmt::Debug for Program {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Program({})", self.name)
    }
}

/// What the sources of a program's shaders declare and include, gathered as they compile.
#[derive(Default)]
struct Seen {
    declared: HashSet<String>,
    files: Vec<String>,
}

fn compile<'a>(
    ctx: &Context,
    kind: u32,
    path: &str,
    defines: &Defines,
    lookup: &dyn Fn(&str) -> Option<&'a str>,
    seen: &mut Seen,
) -> Result<glow::Shader> {
    let resolved = resolve(path, defines, lookup)?;
    seen.declared.extend(declared_uniforms(&resolved.text));
    for f in &resolved.files {
        if !seen.files.contains(f) {
            seen.files.push(f.clone());
        }
    }
    // SAFETY: plain shader compilation on a current context.
    unsafe {
        let shader = ctx.gl().create_shader(kind).map_err(Error::Gl)?;
        ctx.gl().shader_source(shader, &resolved.text);
        ctx.gl().compile_shader(shader);
        if !ctx.gl().get_shader_compile_status(shader) {
            let raw_log = ctx.gl().get_shader_info_log(shader);
            ctx.gl().delete_shader(shader);
            let (log, first) = map_log(&raw_log, &resolved.files);
            let (file, line) = first.unwrap_or((path.to_owned(), 0));
            return Err(Error::ShaderCompile { file, line, log });
        }
        Ok(shader)
    }
}

/// Programs made so far in the process (a program's serial is its place in this count).
static MADE: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl Program {
    /// How many programs the process has built and linked so far, on every context: what a
    /// benchmark checks to show that it builds none within its timed repetitions (a first
    /// draw of a new program pays for its code, on llvmpipe a compile).
    pub fn made() -> u64 {
        MADE.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Compiles `vertex` and `fragment` (paths under `glsl/`) with `defines` and links them.
    pub fn new(ctx: &Context, vertex: &str, fragment: &str, defines: &Defines) -> Result<Self> {
        Self::build(ctx, vertex, fragment, defines, &embedded)
    }

    /// Compiles the embedded `vertex` with a fragment shader of the caller's, `source` (its
    /// `#include`s name embedded files, e.g. `"common/rng.glsl"`), named `name` in compile
    /// errors (`name:line`), and links them.
    pub fn with_fragment_source(
        ctx: &Context,
        vertex: &str,
        name: &str,
        source: &str,
        defines: &Defines,
    ) -> Result<Self> {
        let lookup = |p: &str| if p == name { Some(source) } else { embedded(p) };
        Self::build(ctx, vertex, name, defines, &lookup)
    }

    fn build<'a>(
        ctx: &Context,
        vertex: &str,
        fragment: &str,
        defines: &Defines,
        lookup: &dyn Fn(&str) -> Option<&'a str>,
    ) -> Result<Self> {
        let name = format!("{vertex}+{fragment}");
        let mut seen = Seen::default();
        let vs = compile(ctx, glow::VERTEX_SHADER, vertex, defines, lookup, &mut seen)?;
        let fs = match compile(
            ctx,
            glow::FRAGMENT_SHADER,
            fragment,
            defines,
            lookup,
            &mut seen,
        ) {
            Ok(fs) => fs,
            Err(e) => {
                // SAFETY: vs is a live shader of this context.
                unsafe { ctx.gl().delete_shader(vs) };
                return Err(e);
            }
        };
        // SAFETY: linking live shaders; they are detached and deleted right after.
        let raw = unsafe {
            let raw = ctx.gl().create_program().map_err(Error::Gl)?;
            ctx.gl().attach_shader(raw, vs);
            ctx.gl().attach_shader(raw, fs);
            ctx.gl().link_program(raw);
            ctx.gl().detach_shader(raw, vs);
            ctx.gl().detach_shader(raw, fs);
            ctx.gl().delete_shader(vs);
            ctx.gl().delete_shader(fs);
            if !ctx.gl().get_program_link_status(raw) {
                let log = ctx.gl().get_program_info_log(raw);
                ctx.gl().delete_program(raw);
                return Err(Error::ProgramLink { name, log });
            }
            raw
        };
        ctx.label(glow::PROGRAM, raw.0.get(), &name);
        // SAFETY: queries of a linked program.
        let samplers = unsafe {
            (0..ctx.gl().get_active_uniforms(raw))
                .filter_map(|i| ctx.gl().get_active_uniform(raw, i))
                .filter(|u| is_sampler(u.utype))
                .map(|u| u.name)
                .collect()
        };
        ctx.check_error(&format!("building program {name}"))?;
        Ok(Program {
            ctx: ctx.clone(),
            raw,
            name,
            uniforms: RefCell::new(HashMap::new()),
            serial: MADE.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
            declared: seen.declared,
            samplers,
            source: Box::new(SourceInfo {
                defines: defines.clone(),
                // A benchmark's own floor that walks is not a pass to floor.
                walks_every_live: seen.files.iter().any(|f| f == WALK_INCLUDE)
                    && !fragment.starts_with("bench/"),
                files: seen.files,
            }),
        })
    }

    /// The defines it was compiled with.
    pub fn defines(&self) -> &Defines {
        &self.source.defines
    }

    /// The files its two shaders were built from, includes among them (`glsl/` paths).
    pub fn files(&self) -> &[String] {
        &self.source.files
    }

    /// Whether it walks the cells around every live particle: built with [`WALK_INCLUDE`]
    /// (the exact neighbour search; every pass that includes it walks from each live particle).
    pub fn walks_every_live(&self) -> bool {
        self.source.walks_every_live
    }

    /// The values its active integer uniforms (`int`, `ivec2` to `ivec4`, not arrays) hold now,
    /// by name: what a draw of it read, for a floor that repeats the draw's search.
    pub fn int_uniforms(&self) -> Vec<(String, Vec<i32>)> {
        let types = [glow::INT, glow::INT_VEC2, glow::INT_VEC3, glow::INT_VEC4];
        // SAFETY: a query of a uniform of this program, into a buffer of four.
        self.active_values(types, |gl, p, at, v| unsafe {
            gl.get_uniform_i32(p, at, v)
        })
    }

    /// The values its active float uniforms (`float`, `vec2` to `vec4`, not arrays) hold now,
    /// by name: the geometry of a trimmed search, for a floor that repeats the draw's walk.
    pub fn float_uniforms(&self) -> Vec<(String, Vec<f32>)> {
        let types = [
            glow::FLOAT,
            glow::FLOAT_VEC2,
            glow::FLOAT_VEC3,
            glow::FLOAT_VEC4,
        ];
        // SAFETY: a query of a uniform of this program, into a buffer of four.
        self.active_values(types, |gl, p, at, v| unsafe {
            gl.get_uniform_f32(p, at, v)
        })
    }

    /// The active non-array uniforms of the GL types `types` (one to four components, in
    /// order), each read by `read` into four values and cut to its components.
    fn active_values<T: Copy + Default>(
        &self,
        types: [u32; 4],
        read: impl Fn(&glow::Context, glow::Program, &glow::UniformLocation, &mut [T]),
    ) -> Vec<(String, Vec<T>)> {
        let gl = self.ctx.gl();
        // SAFETY: queries of a linked program of this context.
        unsafe {
            (0..gl.get_active_uniforms(self.raw))
                .filter_map(|i| gl.get_active_uniform(self.raw, i))
                .filter_map(|u| {
                    let n = types.iter().position(|&t| t == u.utype)? + 1;
                    let at = gl.get_uniform_location(self.raw, &u.name)?;
                    let mut v = vec![T::default(); 4];
                    read(gl, self.raw, &at, &mut v);
                    v.truncate(n);
                    (u.size == 1).then_some((u.name, v))
                })
                .collect()
        }
    }

    /// Whether the program's sources declare uniform `name` (`u_plane[2]` counts as `u_plane`),
    /// whether or not the optimiser kept it.
    pub fn declares(&self, name: &str) -> bool {
        self.declared.contains(base_name(name))
    }

    /// The samplers the program reads (active sampler uniforms).
    pub fn samplers(&self) -> &[String] {
        &self.samplers
    }

    /// The program's name, `vertex+fragment`.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Makes it the current program, which [`set`](Self::set) acts on (a draw binds it first).
    pub(super) fn bind(&self) {
        // SAFETY: the program is alive and linked.
        unsafe { self.ctx.gl().use_program(Some(self.raw)) }
    }

    /// This program's number among all made in the process (never reused).
    pub fn serial(&self) -> u64 {
        self.serial
    }

    /// Sets uniform `name` to `value` (the program is current, see [`bind`](Self::bind)): an
    /// array from its first element on, an empty one not at all. Uploads nothing when the
    /// uniform holds `value` already and the context's uniform cache is on, or when the
    /// optimiser dropped it (GL's location −1). A name the sources do not declare is a mistake,
    /// not an optimisation: refused in debug builds.
    pub(super) fn set(&self, name: &str, value: &Uniform) {
        if value.is_empty_array() {
            return;
        }
        let mut uniforms = self.uniforms.borrow_mut();
        if !uniforms.contains_key(name) {
            let query = match value.is_array() {
                true => format!("{name}[0]"),
                false => name.to_owned(),
            };
            // SAFETY: the program is alive.
            let location = unsafe { self.ctx.gl().get_uniform_location(self.raw, &query) };
            if cfg!(debug_assertions) && location.is_none() && !self.declares(name) {
                panic!(
                    "program {} declares no uniform `{name}` (misspelt, or the wrong program); \
                     a list shared by several programs gives each the names it declares \
                     (UniformList::for_draw)",
                    self.name
                );
            }
            let slot = Slot {
                location,
                value: None,
            };
            uniforms.insert(name.to_owned(), slot);
        }
        let slot = uniforms.get_mut(name).expect("inserted above");
        let Some(l) = slot.location.as_ref() else {
            return;
        };
        if self.ctx.uniform_cache() && slot.value.as_ref().is_some_and(|v| v.same_as(value)) {
            return;
        }
        self.ctx.count_upload();
        upload(self.ctx.gl(), l, value);
        slot.value = Some(value.clone());
    }
}

/// One `glUniform*` call of `value` at `l` (the program current).
fn upload(gl: &glow::Context, l: &glow::UniformLocation, value: &Uniform) {
    let l = Some(l);
    fn flat<const N: usize>(v: impl Iterator<Item = [f32; N]>) -> Vec<f32> {
        v.flatten().collect()
    }
    // SAFETY: the program holding `l` is current; the data matches the uniform's type.
    unsafe {
        match value {
            Uniform::F32(v) => gl.uniform_1_f32(l, *v),
            Uniform::I32(v) => gl.uniform_1_i32(l, *v),
            Uniform::U32(v) => gl.uniform_1_u32(l, *v),
            Uniform::Vec2(v) => gl.uniform_2_f32(l, v.x, v.y),
            Uniform::Vec3(v) => gl.uniform_3_f32(l, v.x, v.y, v.z),
            Uniform::Vec4(v) => gl.uniform_4_f32(l, v.x, v.y, v.z, v.w),
            Uniform::IVec2(v) => gl.uniform_2_i32(l, v.x, v.y),
            Uniform::IVec3(v) => gl.uniform_3_i32(l, v.x, v.y, v.z),
            Uniform::IVec4(v) => gl.uniform_4_i32(l, v.x, v.y, v.z, v.w),
            Uniform::Mat4(m) => gl.uniform_matrix_4_f32_slice(l, false, &m.to_cols_array()),
            Uniform::I32s(v) => gl.uniform_1_i32_slice(l, v),
            Uniform::F32s(v) => gl.uniform_1_f32_slice(l, v),
            Uniform::Vec2s(v) => gl.uniform_2_f32_slice(l, &flat(v.iter().map(|x| x.to_array()))),
            Uniform::Vec3s(v) => gl.uniform_3_f32_slice(l, &flat(v.iter().map(|x| x.to_array()))),
            Uniform::Vec4s(v) => gl.uniform_4_f32_slice(l, &flat(v.iter().map(|x| x.to_array()))),
            Uniform::IVec4s(v) => gl.uniform_4_i32_slice(l, &v.concat()),
        }
    }
}

impl Drop for Program {
    fn drop(&mut self) {
        if let Some(gl) = self.ctx.gl_for_drop() {
            // SAFETY: the object belongs to this context, made current just now.
            unsafe { gl.delete_program(self.raw) }
        }
    }
}
