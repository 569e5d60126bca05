//! A thin safe layer over glow: the only code of the crate that calls GL.
//!
//! ## Objects and ownership
//!
//! One owning type per GL object: [`Texture`], [`Texture3D`], [`Framebuffer`], [`Program`],
//! [`Buffer`], [`VertexArray`], [`PixelPack`], [`TimerQuery`]. Each holds a clone of the [`Context`] (an `Rc`)
//! and deletes its name on `Drop` after making its context current, or leaks it if EGL refuses
//! (never a name of another context), so no object outlives its context. Inside the context the
//! glow table drops before the EGL context. `Context` is neither `Send` nor `Sync`; it hands its
//! glow table only to this module (`Context::gl`, made current first), so code above names no GL
//! function or constant. A framebuffer made by [`Framebuffer::layer`] or
//! [`Framebuffer::attachment`] draws into textures it does not own: drop it before them.
//!
//! ## A draw as data
//!
//! A pass draws with [`Context::draw`] and a [`Draw`]: program, target framebuffer, viewport,
//! vertex array, primitive, count, a [`DrawState`], the textures it reads by sampler name
//! ([`Sampled`]) and the uniforms of this draw ([`Uniform`]); or with [`FullscreenPass`], which
//! makes that `Draw` for a full-screen triangle from the same lists. Every uniform a draw reads
//! travels in it, a scene's constants too ([`UniformList`], built once and given with each draw
//! of the programs that read it); nothing above this module sets a uniform on a program. Each
//! program remembers the value each of its uniforms holds and uploads only what differs (the
//! uniform cache, [`Context::set_uniform_cache`]), so constants in every draw cost no GL call
//! after the first.
//!
//! ## Texture units
//!
//! Units are assigned per draw, never by the caller (nothing outside this module binds one):
//! [`Context::draw`] binds the k-th listed texture to unit k and sets its sampler to k. A draw
//! whose list leaves out an active sampler of the program is refused with a panic (the sampler
//! would read what an earlier pass left bound), and in debug builds so is a listed name the
//! program does not declare.
//!
//! ## Attachments
//!
//! Colour attachment k of a framebuffer is output k of the fragment shader. Above this module it
//! is reached by name: the module owning a kind of state defines [`Attachment`] handles
//! (`Attachment::named("position")`), builds the state with them ([`Framebuffer::named`],
//! [`PingPong::new`], [`Ring3::new`]) and reads `fb.texture(POSITION)`, which looks the name up
//! among the framebuffer's own attachments and panics if it has none of that name: a handle of
//! another kind of state fails instead of reading whatever sits at the same index. A framebuffer
//! of one attachment gives it by [`Framebuffer::only_texture`]. Indices ([`AttachmentKey`] for
//! `usize`) remain for this layer's tests; `tests/layout.rs` refuses literal ones above it.
//!
//! ## Uniform names
//!
//! GL gives location −1 both to a misspelt name and to a declared uniform the optimiser dropped.
//! [`Program`] keeps the names its sources declare: both stages' resolved text (`#include`s
//! spliced, `#define`s prepended, not preprocessed, so a declaration inside an inactive `#if`
//! counts) is split into statements, `//` comments dropped, and the names after `uniform TYPE`
//! kept (`u_plane[4]` as `u_plane`). On a name's first use in a draw (locations are cached, the check
//! runs once per name) a name with no location is ignored if declared, as GL ignores −1, and in
//! debug builds panics if not; lists shared by several programs give each draw the names its
//! program declares ([`UniformList::for_draw`]). Release builds ignore both.
//!
//! ## State reset
//!
//! [`Context::draw`] sets, on every draw, the program, the target and its viewport, the vertex
//! array (unbound after the draw), the depth test, function and mask, program point size, and
//! blending with its equations and factors ([`Blend`]: `None` turns it off), so no pass depends
//! on the state the one before it left. Clears and blits set what they use (a depth clear turns
//! the depth mask on; a blit turns the scissor test off and leaves framebuffer 0 bound).

mod attachment;
mod bindings;
mod buffer;
mod context;
mod draw;
mod exchange;
mod framebuffer;
mod pack;
mod pass;
mod pingpong;
mod profile;
mod program;
mod query;
mod record;
pub mod source;
mod stats;
mod texture;
mod texture3d;
mod timer;
mod uniform_list;
#[cfg(feature = "window")]
mod window;

pub use attachment::{Attachment, AttachmentKey};
pub use bindings::Sampled;
pub use buffer::{Attribute, Buffer, BufferKind, BufferUsage, VertexArray};
pub use context::{gl_error_name, list_devices, Context, DeviceInfo, Limits};
pub use draw::{
    Blend, BlendComponent, BlendFactor, BlendOperation, Depth, Draw, DrawState, PointSize,
    Primitive, Rect,
};
pub use framebuffer::Framebuffer;
pub use pack::PixelPack;
pub use pass::{FullscreenPass, StatePass, Uniform, FULLSCREEN_VERTEX};
pub use pingpong::{PingPong, Ring3};
pub use profile::{DrawProfiler, DrawTime};
pub use program::{Defines, Program};
pub use query::{SamplesQuery, TimerQuery};
pub use record::{
    attach_draws, DrawRecorder, DrawShape, PassDraw, PassInfo, ReadShape, RecordedTexture,
    ShapeRecorder, WALK_INCLUDE,
};
pub use stats::DrawStats;
pub use texture::{check_size, Texture, TextureDesc, TextureFormat};
pub use texture3d::{check_size_3d, Texture3D};
pub use timer::{Clock, PassTimer};
pub use uniform_list::UniformList;
#[cfg(feature = "window")]
pub use window::GlWindow;
