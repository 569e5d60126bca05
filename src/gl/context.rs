//! The headless context: an EGL device (EGL_EXT_device_enumeration), a surfaceless OpenGL 3.3
//! core context on it, and glow loaded from it; or, for an application that draws the particles
//! into its own frame, a GL context the caller made current ([`Context::from_current`]).
//!
//! Every GL object of this crate holds a [`Context`] (a reference-counted handle), so no object
//! can outlive the context it was made in. GL contexts are bound to the thread that made them
//! current: a [`Context`] is neither `Send` nor `Sync`.
//!
//! One thread can hold several contexts ([`Context::new`] twice), and EGL has one current context
//! per thread, so every GL call of this layer, and every `Drop` of a GL object, goes through
//! [`Context::make_current`] first: an object is always used and deleted in its own context,
//! whichever was made current last. When only one context exists that is one thread-local compare.

use std::cell::Cell;
use std::ffi::CStr;
use std::rc::Rc;
use std::sync::atomic::{AtomicU64, Ordering};

use glow::HasContext;

use super::stats::DrawStats;
use glutin::api::egl::{
    context::PossiblyCurrentContext, device::Device as EglDevice, display::Display,
};
use glutin::config::{ConfigSurfaceTypes, ConfigTemplateBuilder};
use glutin::context::{ContextApi, ContextAttributesBuilder, GlProfile, Version};
use glutin::prelude::*;

use crate::error::{Error, Result};

/// One EGL device as enumerated by EGL_EXT_device_enumeration.
#[derive(Debug, Clone)]
pub struct DeviceInfo {
    /// Position in the enumeration, the value of `--device`.
    pub index: usize,
    /// The device name EGL reports, if any.
    pub name: Option<String>,
    /// The vendor EGL reports, if any.
    pub vendor: Option<String>,
    /// Whether Mesa marks it as a software device (llvmpipe).
    pub software: bool,
    /// The DRM node, for hardware devices.
    pub drm_node: Option<String>,
}

fn query_devices() -> Result<Vec<EglDevice>> {
    let devices = EglDevice::query_devices()
        .map_err(|e| Error::NoEglDevice {
            reason: e.to_string(),
        })?
        .collect::<Vec<_>>();
    if devices.is_empty() {
        return Err(Error::NoEglDevice {
            reason: "EGL enumerated no devices".into(),
        });
    }
    Ok(devices)
}

/// Lists the EGL devices of this machine.
pub fn list_devices() -> Result<Vec<DeviceInfo>> {
    Ok(query_devices()?
        .iter()
        .enumerate()
        .map(|(index, d)| DeviceInfo {
            index,
            name: d.name().map(str::to_owned),
            vendor: d.vendor().map(str::to_owned),
            software: d.extensions().contains("EGL_MESA_device_software"),
            drm_node: d.drm_device_node_path().map(|p| p.display().to_string()),
        })
        .collect())
}

/// What the context can do, queried once at creation.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Limits {
    /// `GL_RENDERER`.
    pub renderer: String,
    /// `GL_VENDOR`.
    pub vendor: String,
    /// `GL_VERSION`.
    pub version: String,
    /// `GL_SHADING_LANGUAGE_VERSION`.
    pub glsl_version: String,
    /// `GL_MAX_TEXTURE_SIZE`: the largest state texture side.
    pub max_texture_size: u32,
    /// `GL_MAX_DRAW_BUFFERS`: how many render targets one pass can write.
    pub max_draw_buffers: u32,
    /// `GL_MAX_COLOR_ATTACHMENTS`.
    pub max_color_attachments: u32,
    /// `GL_MAX_VERTEX_TEXTURE_IMAGE_UNITS`: vertex texture fetch.
    pub max_vertex_texture_image_units: u32,
    /// `GL_MAX_VIEWPORT_DIMS`.
    pub max_viewport: [u32; 2],
    /// `GL_MAX_3D_TEXTURE_SIZE`: flow and distance fields.
    pub max_3d_texture_size: u32,
    /// Whether an RGBA32F texture can be a colour attachment.
    pub float32_color_buffer: bool,
    /// Whether an RGBA16F texture can be a colour attachment.
    pub float16_color_buffer: bool,
    /// Whether `GL_KHR_debug` is available.
    pub khr_debug: bool,
    /// `GL_ALIASED_POINT_SIZE_RANGE` (where a core profile rejects that enum,
    /// `GL_POINT_SIZE_RANGE`): the smallest and largest point sprite, in pixels.
    pub point_size_range: [f32; 2],
}

thread_local! {
    /// The id of the context of this crate that is current on this thread (0: none).
    static CURRENT: Cell<u64> = const { Cell::new(0) };
}

/// Ids of contexts, unique in the process (0 is never given out).
static NEXT_ID: AtomicU64 = AtomicU64::new(1);

/// How a context is made current again when another took its place on the thread.
type Reactivate = Box<dyn Fn() -> std::result::Result<(), String>>;

/// Who made the GL context.
enum Owner {
    /// This crate: a surfaceless context on an EGL device. Fields drop in order: the context,
    /// then the display.
    Egl {
        context: PossiblyCurrentContext,
        _display: Display,
    },
    /// The caller ([`Context::from_current`]): it owns the context; `reactivate`, if given, makes
    /// it current again (and keeps whatever it captured alive as long as this crate's objects).
    Caller { reactivate: Option<Reactivate> },
}

/// Owner of the GL context and the glow function table.
///
/// Fields drop in declaration order: glow first, then the owner of the context.
struct Inner {
    gl: glow::Context,
    limits: Limits,
    device: usize,
    id: u64,
    owner: Owner,
    /// What the draws since the last [`Context::take_draw_stats`] did (for floors and the cost
    /// model: passes and bytes written).
    stats: Cell<DrawStats>,
    /// What the draws counted since the last [`Context::take_draw_stats`] drew into and read
    /// (see [`DrawStats::follow_ons`] and [`DrawStats::concurrent`]).
    hazards: std::cell::RefCell<super::stats::Hazards>,
    /// Whether uploads of a value a program's uniform already holds are skipped (see
    /// [`Context::set_uniform_cache`]).
    uniform_cache: Cell<bool>,
}

impl Drop for Inner {
    fn drop(&mut self) {
        // The EGL context is destroyed with the fields; no later call may take it for current.
        if CURRENT.with(Cell::get) == self.id {
            CURRENT.with(|c| c.set(0));
        }
    }
}

/// A current, surfaceless OpenGL 3.3 core context on one EGL device. Cheap to clone.
///
/// ```
/// let ctx = texflow::gl::Context::new(0)?;          // the first EGL device (llvmpipe in CI)
/// let limits = ctx.limits();
/// assert!(limits.max_texture_size >= 1024 && limits.max_draw_buffers >= 4);
/// assert!(limits.float32_color_buffer, "float render targets are needed");
/// ctx.check_error("nothing yet")?;
/// # Ok::<(), texflow::Error>(())
/// ```
#[derive(Clone)]
pub struct Context {
    inner: Rc<Inner>,
}

impl std::fmt::Debug for Context {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Context")
            .field("device", &self.inner.device)
            .field("renderer", &self.inner.limits.renderer)
            .finish()
    }
}

impl Context {
    /// Creates a context on EGL device `index` (see [`list_devices`]) and makes it current on this
    /// thread.
    pub fn new(index: usize) -> Result<Self> {
        let devices = query_devices()?;
        let count = devices.len();
        let device = devices
            .get(index)
            .ok_or(Error::DeviceIndex { index, count })?;
        let ctx_err = |reason: String| Error::Context {
            device: index,
            reason,
        };
        // SAFETY: the device comes from EGL's own enumeration; no native display is involved.
        let display = unsafe { Display::with_device(device, None) }
            .map_err(|e| ctx_err(format!("eglGetPlatformDisplay: {e}")))?;
        let template = ConfigTemplateBuilder::new()
            .with_surface_type(ConfigSurfaceTypes::empty())
            .build();
        // SAFETY: the display is valid for the whole call.
        let config = unsafe { display.find_configs(template) }
            .map_err(|e| ctx_err(format!("eglChooseConfig: {e}")))?
            .next()
            .ok_or_else(|| ctx_err("no EGL config without surfaces".into()))?;
        let attributes = ContextAttributesBuilder::new()
            .with_context_api(ContextApi::OpenGl(Some(Version::new(3, 3))))
            .with_profile(GlProfile::Core)
            .build(None);
        // SAFETY: config belongs to display.
        let not_current = unsafe { display.create_context(&config, &attributes) }
            .map_err(|e| ctx_err(format!("eglCreateContext (OpenGL 3.3 core): {e}")))?;
        let context = not_current
            .make_current_surfaceless()
            .map_err(|e| ctx_err(format!("eglMakeCurrent without surface: {e}")))?;
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        CURRENT.with(|c| c.set(id));
        // SAFETY: the context is current on this thread; glow only stores the pointers.
        #[allow(unused_mut)]
        let mut gl = unsafe {
            glow::Context::from_loader_function_cstr(|name: &CStr| display.get_proc_address(name))
        };
        let limits = query_limits(&gl);
        #[cfg(debug_assertions)]
        if limits.khr_debug {
            install_debug_callback(&mut gl);
        }
        let ctx = Context {
            inner: Rc::new(Inner {
                gl,
                limits,
                device: index,
                id,
                stats: Cell::new(DrawStats::default()),
                hazards: Default::default(),
                uniform_cache: Cell::new(true),
                owner: Owner::Egl {
                    context,
                    _display: display,
                },
            }),
        };
        ctx.require_capabilities()?;
        Ok(ctx)
    }

    /// Wraps the OpenGL context that the caller made current on this thread (a window's, made
    /// with glutin, SDL or any other library), so that the engines draw into the caller's
    /// frame: render into their [`FrameTarget`](crate::render::FrameTarget) as usual, then
    /// [`Framebuffer::blit_to_default`](super::Framebuffer::blit_to_default) copies the frame
    /// into the window's back buffer (or sample its texture in a pass of your own), and the
    /// caller swaps buffers.
    ///
    /// `loader` returns the address of a GL function of that context (glutin's
    /// `Display::get_proc_address`). `reactivate`, if given, makes the caller's context current
    /// again: it is called only when a context made with [`Context::new`] on the same thread, or
    /// an object of one, was used since. Without it such a switch back is an error.
    ///
    /// The context must be OpenGL 3.3 core or later with the capabilities [`Context::new`]
    /// requires (RGBA32F colour buffers, two draw buffers, vertex texture fetch). The engines set
    /// all the state of each of their draws and leave framebuffer 0 bound after a blit, but
    /// change other state (programs, textures, blending, viewport): an application that draws
    /// too sets its own state after them.
    ///
    /// # Safety
    /// The caller's context must be current on this thread now, and `loader` must return its
    /// functions. It must outlive the returned context and every object made with it (capture
    /// it in `reactivate` to tie the two), and be current whenever they are used or dropped.
    pub unsafe fn from_current(
        mut loader: impl FnMut(&CStr) -> *const std::ffi::c_void,
        reactivate: Option<Reactivate>,
    ) -> Result<Self> {
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        CURRENT.with(|c| c.set(id));
        // SAFETY: the caller's context is current (this function's contract).
        let gl = unsafe { glow::Context::from_loader_function_cstr(|name| loader(name)) };
        let limits = query_limits(&gl);
        if limits.version.is_empty() {
            return Err(Error::Context {
                device: 0,
                reason: "no current OpenGL context: make the caller's context current before \
                         Context::from_current"
                    .into(),
            });
        }
        let ctx = Context {
            inner: Rc::new(Inner {
                gl,
                limits,
                device: 0,
                id,
                stats: Cell::new(DrawStats::default()),
                hazards: Default::default(),
                uniform_cache: Cell::new(true),
                owner: Owner::Caller { reactivate },
            }),
        };
        ctx.require_capabilities()?;
        Ok(ctx)
    }

    /// Every draw carries all of its uniforms, the run's constants among them; with the cache on
    /// (the default) a program uploads only the values that differ from what it holds, as
    /// three.js's uniform cache does. Off, every value given is uploaded: for profiling what
    /// the cache saves. Results are the same either way.
    pub fn set_uniform_cache(&self, on: bool) {
        self.inner.uniform_cache.set(on);
    }

    /// Whether the uniform cache is on (see [`set_uniform_cache`](Self::set_uniform_cache)).
    pub fn uniform_cache(&self) -> bool {
        self.inner.uniform_cache.get()
    }

    /// The draw counts and what the counted draws touched (the counting lives in `stats.rs`).
    pub(super) fn counts(&self) -> (&Cell<DrawStats>, &std::cell::RefCell<super::stats::Hazards>) {
        (&self.inner.stats, &self.inner.hazards)
    }

    /// What the draws since the last call did, and starts counting again (the next draw waits
    /// on whatever came before: no follow-on, none concurrent).
    pub fn take_draw_stats(&self) -> DrawStats {
        self.inner.hazards.take();
        self.inner.stats.take()
    }

    /// Whether the context is the caller's ([`Context::from_current`]) rather than this crate's.
    pub fn is_wrapped(&self) -> bool {
        matches!(self.inner.owner, Owner::Caller { .. })
    }

    /// What the context can do.
    pub fn limits(&self) -> &Limits {
        &self.inner.limits
    }

    /// The EGL device index the context lives on (0 for a wrapped context).
    pub fn device_index(&self) -> usize {
        self.inner.device
    }

    /// Makes this context current on the calling thread if it is not (another context made on
    /// this thread since, or an object of another context used or dropped since, took its place).
    /// Cheap when it already is: a thread-local compare, no EGL call.
    pub fn make_current(&self) -> Result<()> {
        if CURRENT.with(Cell::get) == self.inner.id {
            return Ok(());
        }
        match &self.inner.owner {
            Owner::Egl { context, .. } => {
                context
                    .make_current_surfaceless()
                    .map_err(|e| Error::Context {
                        device: self.inner.device,
                        reason: format!("eglMakeCurrent without surface: {e}"),
                    })?
            }
            Owner::Caller {
                reactivate: Some(f),
            } => f().map_err(|reason| Error::Context {
                device: self.inner.device,
                reason: format!("making the caller's context current again: {reason}"),
            })?,
            Owner::Caller { reactivate: None } => {
                return Err(Error::Context {
                    device: self.inner.device,
                    reason: "another context was made current on this thread, and the caller's \
                             context was wrapped without a way to make it current again: pass \
                             `reactivate` to Context::from_current"
                        .into(),
                })
            }
        }
        CURRENT.with(|c| c.set(self.inner.id));
        Ok(())
    }

    /// Whether this context is the current one of the calling thread.
    pub fn is_current(&self) -> bool {
        CURRENT.with(Cell::get) == self.inner.id
    }

    /// The raw glow context, made current first: for the GL layer only, so that every GL call
    /// of the crate goes through a typed method of `src/gl/`.
    ///
    /// # Panics
    /// If EGL refuses to make the context current on its own thread again (a lost device):
    /// a GL call would otherwise land in whichever context is current.
    pub(in crate::gl) fn gl(&self) -> &glow::Context {
        if let Err(e) = self.make_current() {
            panic!("{e}");
        }
        &self.inner.gl
    }

    /// The raw glow context for a `Drop`: made current first; `None` if EGL refuses, in which case
    /// the object is leaked rather than a name of another context deleted.
    pub(in crate::gl) fn gl_for_drop(&self) -> Option<&glow::Context> {
        match self.make_current() {
            Ok(()) => Some(&self.inner.gl),
            Err(e) => {
                eprintln!("texflow: leaking a GL object: {e}");
                None
            }
        }
    }

    fn require_capabilities(&self) -> Result<()> {
        let l = self.limits();
        let missing = |what: &str, detail: String| {
            Err(Error::MissingCapability {
                what: what.into(),
                detail,
            })
        };
        if !l.float32_color_buffer {
            return missing(
                "RGBA32F colour buffers",
                "a framebuffer with an RGBA32F attachment is not complete".into(),
            );
        }
        if l.max_draw_buffers < 2 {
            return missing(
                "multiple render targets",
                format!("GL_MAX_DRAW_BUFFERS = {}", l.max_draw_buffers),
            );
        }
        if l.max_vertex_texture_image_units < 1 {
            return missing("vertex texture fetch", "0 vertex texture units".into());
        }
        Ok(())
    }

    /// Whether recorded texture `r` is still the texture that was read: not freed, and its
    /// name not made anew for another (each texture carries the serial number it was made
    /// with).
    pub fn is_live(&self, r: &super::RecordedTexture) -> bool {
        super::record::lives(r)
    }

    /// Returns the first pending GL error, if any, as an [`Error::Gl`] naming `what` was done.
    pub fn check_error(&self, what: &str) -> Result<()> {
        // SAFETY: glGetError has no preconditions.
        let code = unsafe { self.gl().get_error() };
        if code == glow::NO_ERROR {
            return Ok(());
        }
        // Drain the remaining flags so the next check starts clean.
        let mut more = Vec::new();
        for _ in 0..8 {
            // SAFETY: as above.
            let c = unsafe { self.gl().get_error() };
            if c == glow::NO_ERROR {
                break;
            }
            more.push(gl_error_name(c));
        }
        Err(Error::Gl(format!(
            "{} after {what}{}",
            gl_error_name(code),
            if more.is_empty() {
                String::new()
            } else {
                format!(" (then {})", more.join(", "))
            }
        )))
    }

    /// Waits for the GPU to finish all submitted work.
    pub fn finish(&self) {
        // SAFETY: glFinish has no preconditions.
        unsafe { self.gl().finish() }
    }

    /// Labels a GL object in debug builds, so that debug output and captures are readable.
    pub(crate) fn label(&self, identifier: u32, name: u32, label: &str) {
        if cfg!(debug_assertions) && self.limits().khr_debug {
            // SAFETY: `name` is a live object of type `identifier`, made by this context.
            unsafe { self.gl().object_label(identifier, name, Some(label)) }
        }
    }
}

/// The name of a GL error code.
pub fn gl_error_name(code: u32) -> String {
    match code {
        glow::INVALID_ENUM => "GL_INVALID_ENUM".into(),
        glow::INVALID_VALUE => "GL_INVALID_VALUE".into(),
        glow::INVALID_OPERATION => "GL_INVALID_OPERATION".into(),
        glow::INVALID_FRAMEBUFFER_OPERATION => "GL_INVALID_FRAMEBUFFER_OPERATION".into(),
        glow::OUT_OF_MEMORY => "GL_OUT_OF_MEMORY".into(),
        other => format!("GL error 0x{other:04x}"),
    }
}

fn query_limits(gl: &glow::Context) -> Limits {
    // SAFETY: plain queries on a current context.
    unsafe {
        let int = |p| gl.get_parameter_i32(p).max(0) as u32;
        let mut viewport = [0i32; 2];
        gl.get_parameter_i32_slice(glow::MAX_VIEWPORT_DIMS, &mut viewport);
        let exts = gl.supported_extensions();
        Limits {
            renderer: gl.get_parameter_string(glow::RENDERER),
            vendor: gl.get_parameter_string(glow::VENDOR),
            version: gl.get_parameter_string(glow::VERSION),
            glsl_version: gl.get_parameter_string(glow::SHADING_LANGUAGE_VERSION),
            max_texture_size: int(glow::MAX_TEXTURE_SIZE),
            max_draw_buffers: int(glow::MAX_DRAW_BUFFERS),
            max_color_attachments: int(glow::MAX_COLOR_ATTACHMENTS),
            max_vertex_texture_image_units: int(glow::MAX_VERTEX_TEXTURE_IMAGE_UNITS),
            max_viewport: [viewport[0].max(0) as u32, viewport[1].max(0) as u32],
            max_3d_texture_size: int(glow::MAX_3D_TEXTURE_SIZE),
            float32_color_buffer: color_renderable(gl, glow::RGBA32F),
            float16_color_buffer: color_renderable(gl, glow::RGBA16F),
            khr_debug: exts.contains("GL_KHR_debug"),
            point_size_range: point_size_range(gl),
        }
    }
}

/// `GL_ALIASED_POINT_SIZE_RANGE`, or `GL_POINT_SIZE_RANGE` where the context rejects the first
/// (it is not in every core profile); the error the query may raise is cleared.
fn point_size_range(gl: &glow::Context) -> [f32; 2] {
    // SAFETY: plain queries on a current context.
    unsafe {
        // Drains the pending errors; whether there were none.
        let clear = || {
            let none = gl.get_error() == glow::NO_ERROR;
            for _ in 0..8 {
                if gl.get_error() == glow::NO_ERROR {
                    break;
                }
            }
            none
        };
        clear();
        let mut range = [0f32; 2];
        gl.get_parameter_f32_slice(glow::ALIASED_POINT_SIZE_RANGE, &mut range);
        if !clear() || range[1] <= 0.0 {
            gl.get_parameter_f32_slice(glow::POINT_SIZE_RANGE, &mut range);
            clear();
        }
        range
    }
}

/// Whether a 4×4 texture of `internal` format makes a complete framebuffer.
fn color_renderable(gl: &glow::Context, internal: u32) -> bool {
    // SAFETY: objects are created and deleted inside this function on a current context.
    unsafe {
        let (Ok(tex), Ok(fbo)) = (gl.create_texture(), gl.create_framebuffer()) else {
            return false;
        };
        gl.bind_texture(glow::TEXTURE_2D, Some(tex));
        gl.tex_storage_2d(glow::TEXTURE_2D, 1, internal, 4, 4);
        gl.bind_framebuffer(glow::FRAMEBUFFER, Some(fbo));
        gl.framebuffer_texture_2d(
            glow::FRAMEBUFFER,
            glow::COLOR_ATTACHMENT0,
            glow::TEXTURE_2D,
            Some(tex),
            0,
        );
        let ok = gl.check_framebuffer_status(glow::FRAMEBUFFER) == glow::FRAMEBUFFER_COMPLETE;
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        gl.bind_texture(glow::TEXTURE_2D, None);
        gl.delete_framebuffer(fbo);
        gl.delete_texture(tex);
        ok
    }
}

#[cfg(debug_assertions)]
fn install_debug_callback(gl: &mut glow::Context) {
    // SAFETY: KHR_debug is present; the callback only prints.
    unsafe {
        gl.enable(glow::DEBUG_OUTPUT_SYNCHRONOUS);
        gl.debug_message_callback(|_source, kind, id, severity, message| {
            // Performance hints and notifications drown the real problems; keep errors and
            // high/medium severity messages.
            if kind == glow::DEBUG_TYPE_ERROR
                || severity == glow::DEBUG_SEVERITY_HIGH
                || severity == glow::DEBUG_SEVERITY_MEDIUM
            {
                eprintln!("[GL debug {id}] {message}");
            }
        });
    }
}
