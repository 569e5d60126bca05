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
    locations: RefCell<HashMap<String, Option<glow::UniformLocation>>>,
    /// Uniform names the resolved sources declare (active or dropped by the optimiser).
    declared: HashSet<String>,
    /// The active samplers, as GL names them.
    samplers: Vec<String>,
    /// What it was built from (boxed: programs are held by value in many passes).
    source: Box<SourceInfo>,
    /// The value each active uniform holds, by location name, as last uploaded: a draw that
    /// gives the same value again uploads nothing (see [`Context::set_uniform_cache`]).
    values: Box<RefCell<HashMap<String, Value>>>,
}

/// One uniform upload: the components per element and the data.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Int(u8, Vec<i32>),
    Uint(u32),
    Float(u8, Vec<f32>),
    Mat4(Box<[f32; 16]>),
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
    walks_some: bool,
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
    seen.walks_some |=
        (resolved.text.lines()).any(|l| l.trim_start().starts_with("#define WALKS_SOME"));
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

impl Program {
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
            locations: RefCell::new(HashMap::new()),
            declared: seen.declared,
            samplers,
            values: Box::default(),
            source: Box::new(SourceInfo {
                defines: defines.clone(),
                // A benchmark's own floor that walks is not a pass to floor.
                walks_every_live: seen.files.iter().any(|f| f == WALK_INCLUDE)
                    && !seen.walks_some
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
    /// (the exact neighbour search), and not marked `#define WALKS_SOME` (a pass that walks
    /// only some particles, as the exact response walks those with partners).
    pub fn walks_every_live(&self) -> bool {
        self.source.walks_every_live
    }

    /// The values its active integer uniforms (`int`, `ivec2` to `ivec4`, not arrays) hold now,
    /// by name: what a draw of it read, for a floor that repeats the draw's search.
    pub fn int_uniforms(&self) -> Vec<(String, Vec<i32>)> {
        let gl = self.ctx.gl();
        // SAFETY: queries of a linked program of this context.
        unsafe {
            (0..gl.get_active_uniforms(self.raw))
                .filter_map(|i| gl.get_active_uniform(self.raw, i))
                .filter_map(|u| {
                    let n = match u.utype {
                        glow::INT => 1,
                        glow::INT_VEC2 => 2,
                        glow::INT_VEC3 => 3,
                        glow::INT_VEC4 => 4,
                        _ => return None,
                    };
                    let at = gl.get_uniform_location(self.raw, &u.name)?;
                    let mut v = vec![0i32; 4];
                    gl.get_uniform_i32(self.raw, &at, &mut v);
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

    /// Makes it the current program; the setters below act on the current program.
    pub(super) fn bind(&self) {
        // SAFETY: the program is alive and linked.
        unsafe { self.ctx.gl().use_program(Some(self.raw)) }
    }

    fn location(&self, name: &str) -> Option<glow::UniformLocation> {
        if let Some(l) = self.locations.borrow().get(name) {
            return *l;
        }
        // SAFETY: the program is alive. An unused uniform (optimised away) gives None, which the
        // setters ignore as GL does for location -1.
        let l = unsafe { self.ctx.gl().get_uniform_location(self.raw, name) };
        // A name no source declares is a mistake, not an optimisation: refused in debug builds.
        if cfg!(debug_assertions) && l.is_none() && !self.declares(name) {
            panic!(
                "program {} declares no uniform `{name}` (misspelt, or the wrong program); \
                 wrap setters shared by several programs in Program::optional",
                self.name
            );
        }
        self.locations.borrow_mut().insert(name.to_owned(), l);
        l
    }

    /// Sets uniform `name` to `value`, of the type the variant names.
    pub(super) fn set(&self, name: &str, value: Uniform) {
        match value {
            Uniform::F32(v) => self.set_f32(name, v),
            Uniform::I32(v) => self.set_i32(name, v),
            Uniform::U32(v) => self.set_u32(name, v),
            Uniform::Vec2(v) => self.set_vec2(name, v),
            Uniform::Vec3(v) => self.set_vec3(name, v),
            Uniform::Vec4(v) => self.set_vec4(name, v),
            Uniform::IVec2(v) => self.set_ivec2(name, v.x, v.y),
            Uniform::IVec3(v) => self.set_ivec3(name, v.x, v.y, v.z),
            Uniform::IVec4(v) => self.set_ivec4(name, v.to_array()),
            Uniform::Mat4(m) => self.set_mat4(name, &m),
            Uniform::I32s(v) => self.set_i32_array(name, &v),
            Uniform::F32s(v) => self.set_f32_array(name, &v),
            Uniform::Vec2s(v) => self.set_vec2_array(name, &v),
            Uniform::Vec3s(v) => self.set_vec3_array(name, &v),
            Uniform::Vec4s(v) => self.set_vec4_array(name, &v),
            Uniform::IVec4s(v) => self.set_ivec4_array(name, &v),
        }
    }

    /// Sets an `int` uniform (samplers are set by [`Context::draw`] only).
    pub(super) fn set_i32(&self, name: &str, v: i32) {
        self.put(name, Value::Int(1, vec![v]));
    }
    /// Sets an `int[]` uniform array from its first element on (`name` without `[0]`); an
    /// empty `v` sets nothing.
    pub(super) fn set_i32_array(&self, name: &str, v: &[i32]) {
        self.put_array(name, Value::Int(1, v.to_vec()));
    }
    /// Sets a `float[]` uniform array from its first element on (`name` without `[0]`); an
    /// empty `v` sets nothing.
    pub(super) fn set_f32_array(&self, name: &str, v: &[f32]) {
        self.put_array(name, Value::Float(1, v.to_vec()));
    }
    /// Sets a `vec2[]` uniform array from its first element on (`name` without `[0]`); an
    /// empty `v` sets nothing.
    pub(super) fn set_vec2_array(&self, name: &str, v: &[glam::Vec2]) {
        let flat = v.iter().flat_map(|v| v.to_array()).collect();
        self.put_array(name, Value::Float(2, flat));
    }
    /// Sets a `vec3[]` uniform array from its first element on (`name` without `[0]`); an
    /// empty `v` sets nothing.
    pub(super) fn set_vec3_array(&self, name: &str, v: &[glam::Vec3]) {
        let flat = v.iter().flat_map(|v| v.to_array()).collect();
        self.put_array(name, Value::Float(3, flat));
    }
    /// Sets a `vec4[]` uniform array from its first element on (`name` without `[0]`); an
    /// empty `v` sets nothing.
    pub(super) fn set_vec4_array(&self, name: &str, v: &[glam::Vec4]) {
        let flat = v.iter().flat_map(|v| v.to_array()).collect();
        self.put_array(name, Value::Float(4, flat));
    }
    /// Sets an `ivec4[]` uniform array from its first element on (`name` without `[0]`); an
    /// empty `v` sets nothing.
    pub(super) fn set_ivec4_array(&self, name: &str, v: &[[i32; 4]]) {
        let flat = v.iter().flatten().copied().collect();
        self.put_array(name, Value::Int(4, flat));
    }
    /// Sets a `uint` uniform.
    pub(super) fn set_u32(&self, name: &str, v: u32) {
        self.put(name, Value::Uint(v));
    }
    /// Sets a `float` uniform.
    pub(super) fn set_f32(&self, name: &str, v: f32) {
        self.put(name, Value::Float(1, vec![v]));
    }
    /// Sets a `vec2` uniform.
    pub(super) fn set_vec2(&self, name: &str, v: glam::Vec2) {
        self.put(name, Value::Float(2, v.to_array().to_vec()));
    }
    /// Sets a `vec3` uniform.
    pub(super) fn set_vec3(&self, name: &str, v: glam::Vec3) {
        self.put(name, Value::Float(3, v.to_array().to_vec()));
    }
    /// Sets a `vec4` uniform.
    pub(super) fn set_vec4(&self, name: &str, v: glam::Vec4) {
        self.put(name, Value::Float(4, v.to_array().to_vec()));
    }
    /// Sets an `ivec2` uniform.
    pub(super) fn set_ivec2(&self, name: &str, x: i32, y: i32) {
        self.put(name, Value::Int(2, vec![x, y]));
    }
    /// Sets an `ivec3` uniform.
    pub(super) fn set_ivec3(&self, name: &str, x: i32, y: i32, z: i32) {
        self.put(name, Value::Int(3, vec![x, y, z]));
    }
    /// Sets an `ivec4` uniform.
    pub(super) fn set_ivec4(&self, name: &str, v: [i32; 4]) {
        self.put(name, Value::Int(4, v.to_vec()));
    }
    /// Sets a `mat4` uniform (column-major, as glam stores it).
    pub(super) fn set_mat4(&self, name: &str, m: &glam::Mat4) {
        self.put(name, Value::Mat4(Box::new(m.to_cols_array())));
    }

    /// An array's upload, at its first element's location; an empty one sets nothing.
    fn put_array(&self, name: &str, v: Value) {
        let empty = match &v {
            Value::Int(_, d) => d.is_empty(),
            Value::Float(_, d) => d.is_empty(),
            Value::Uint(_) | Value::Mat4(_) => false,
        };
        if !empty {
            self.put(&format!("{name}[0]"), v);
        }
    }

    /// Uploads `v` to the location of `name` (the program is current, see [`bind`](Self::bind))
    /// unless it holds that value already and the context's uniform cache is on. A uniform the
    /// optimiser dropped has no location: nothing to upload.
    fn put(&self, name: &str, v: Value) {
        let Some(l) = self.location(name) else {
            return;
        };
        let mut values = self.values.borrow_mut();
        if self.ctx.uniform_cache() && values.get(name) == Some(&v) {
            return;
        }
        self.upload(Some(&l), &v);
        values.insert(name.to_owned(), v);
    }

    fn upload(&self, l: Option<&glow::UniformLocation>, v: &Value) {
        self.ctx.count_upload();
        let gl = self.ctx.gl();
        // SAFETY: the program is current (see `bind`); a location of None is ignored by GL.
        unsafe {
            match v {
                Value::Int(1, d) => gl.uniform_1_i32_slice(l, d),
                Value::Int(2, d) => gl.uniform_2_i32_slice(l, d),
                Value::Int(3, d) => gl.uniform_3_i32_slice(l, d),
                Value::Int(_, d) => gl.uniform_4_i32_slice(l, d),
                Value::Uint(u) => gl.uniform_1_u32(l, *u),
                Value::Float(1, d) => gl.uniform_1_f32_slice(l, d),
                Value::Float(2, d) => gl.uniform_2_f32_slice(l, d),
                Value::Float(3, d) => gl.uniform_3_f32_slice(l, d),
                Value::Float(_, d) => gl.uniform_4_f32_slice(l, d),
                Value::Mat4(m) => gl.uniform_matrix_4_f32_slice(l, false, &m[..]),
            }
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
