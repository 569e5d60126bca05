//! A window with an OpenGL 3.3 core context (winit + glutin, X11 or Wayland), wrapped as a
//! [`Context`] the engine draws with (`texflow view`). Context creation through glutin is the
//! GL layer's business, so the `unsafe` calls it takes live here.

use std::num::NonZeroU32;
use std::rc::Rc;

use glutin::config::{Config, ConfigTemplateBuilder, GlConfig};
use glutin::context::{
    ContextApi, ContextAttributesBuilder, GlProfile, NotCurrentGlContext, PossiblyCurrentContext,
    PossiblyCurrentGlContext, Version,
};
use glutin::display::{GetGlDisplay, GlDisplay};
use glutin::surface::{GlSurface, Surface, SwapInterval, WindowSurface};
use glutin_winit::{DisplayBuilder, GlWindow as _};
use winit::event_loop::ActiveEventLoop;
use winit::raw_window_handle::HasWindowHandle;
use winit::window::Window;

use super::Context;
use crate::error::{Error, Result};

type Shared = Rc<(PossiblyCurrentContext, Surface<WindowSurface>)>;

fn context_err(reason: impl std::fmt::Display) -> Error {
    Error::Context {
        device: 0,
        reason: format!("window: {reason}"),
    }
}

/// A window, its GL context and surface, and the [`Context`] that wraps them.
#[derive(Debug)]
pub struct GlWindow {
    // Field order is drop order: the wrapped context's objects go before the surface.
    ctx: Context,
    gl: Shared,
    window: Window,
}

impl GlWindow {
    /// Opens a window of `size` pixels titled `title`, with an OpenGL 3.3 core context made
    /// current on it (no multisampling, so the engine's frame can be blitted 1:1).
    pub fn open(event_loop: &ActiveEventLoop, title: &str, size: [u32; 2]) -> Result<Self> {
        let attributes = Window::default_attributes()
            .with_title(title)
            .with_inner_size(winit::dpi::PhysicalSize::new(size[0], size[1]));
        let template = ConfigTemplateBuilder::new();
        let (window, config) = DisplayBuilder::new()
            .with_window_attributes(Some(attributes))
            .build(event_loop, template, |configs| {
                // The first config without multisampling: a blit into a multisampled buffer of
                // another size is not allowed.
                let all: Vec<Config> = configs.collect();
                let first = all[0].clone();
                all.into_iter()
                    .find(|c| c.num_samples() == 0)
                    .unwrap_or(first)
            })
            .map_err(context_err)?;
        let window = window.ok_or_else(|| context_err("no window was created"))?;
        let raw = window.window_handle().map_err(context_err)?.as_raw();
        let display = config.display();
        let attributes = ContextAttributesBuilder::new()
            .with_context_api(ContextApi::OpenGl(Some(Version::new(3, 3))))
            .with_profile(GlProfile::Core)
            .build(Some(raw));
        // SAFETY: the config comes from this display, the handle from a live window.
        let not_current = unsafe { display.create_context(&config, &attributes) }
            .map_err(|e| context_err(format!("creating an OpenGL 3.3 core context: {e}")))?;
        let surface_attributes = window
            .build_surface_attributes(Default::default())
            .map_err(context_err)?;
        // SAFETY: as above.
        let surface = unsafe { display.create_window_surface(&config, &surface_attributes) }
            .map_err(context_err)?;
        let current = not_current.make_current(&surface).map_err(context_err)?;
        // The frame rate is the engine's; no wait for the display's refresh.
        let _ = surface.set_swap_interval(&current, SwapInterval::DontWait);
        let gl: Shared = Rc::new((current, surface));
        let again = Rc::clone(&gl);
        // SAFETY: the context was made current just now; `again` keeps it and its surface alive
        // as long as the wrapped context, which every GL object of the engine holds.
        let ctx = unsafe {
            Context::from_current(
                |name| display.get_proc_address(name),
                Some(Box::new(move || {
                    again.0.make_current(&again.1).map_err(|e| e.to_string())
                })),
            )
        }?;
        Ok(GlWindow { ctx, gl, window })
    }

    /// The wrapped context: everything the engine creates on it draws into this window's GL.
    pub fn context(&self) -> &Context {
        &self.ctx
    }

    /// The window.
    pub fn window(&self) -> &Window {
        &self.window
    }

    /// Shows the frame drawn into the default framebuffer.
    pub fn swap_buffers(&self) -> Result<()> {
        self.gl.1.swap_buffers(&self.gl.0).map_err(context_err)
    }

    /// Resizes the surface to the window's new size (sides of at least 1 pixel).
    pub fn resize(&self, width: u32, height: u32) {
        let w = NonZeroU32::new(width.max(1)).expect("at least 1");
        let h = NonZeroU32::new(height.max(1)).expect("at least 1");
        self.gl.1.resize(&self.gl.0, w, h);
    }
}
