//! A thin safe layer over glow: one owning type per GL object, freed on drop, none able to
//! outlive the [`Context`] it was made in.
//!
//! The only code of the crate that calls GL. The layers above describe what to draw as data
//! ([`Draw`], [`DrawState`], [`Blend`]) and [`Context::draw`] sets all of that state on every
//! draw, so no pass depends on what the one before it left bound or enabled.

mod attachment;
mod bindings;
mod buffer;
mod context;
mod draw;
mod framebuffer;
mod pack;
mod pass;
mod pingpong;
mod program;
mod query;
pub mod source;
mod stats;
mod texture;
mod texture3d;
mod timer;
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
pub use program::{Defines, Program};
pub use query::TimerQuery;
pub use stats::DrawStats;
pub use texture::{check_size, Texture, TextureDesc, TextureFormat};
pub use texture3d::{check_size_3d, Texture3D};
pub use timer::{Clock, PassTimer};
#[cfg(feature = "window")]
pub use window::GlWindow;
