//! Embedding: an application opens its own window (winit + glutin, OpenGL 3.3 core), draws its own
//! frame, and lets texflow draw a scene's particles into part of it, through the application's
//! GL context wrapped with `gl::Context::from_current`. `texflow view` is built the same way.
//!
//!     cargo run --release --example embed -- [SCENE] [FRAMES]     (default: fountain, until closed)

use std::num::NonZeroU32;
use std::rc::Rc;

use glow::HasContext;
use glutin::config::ConfigTemplateBuilder;
use glutin::context::{
    ContextApi, ContextAttributesBuilder, GlProfile, NotCurrentGlContext, PossiblyCurrentContext,
    PossiblyCurrentGlContext, Version,
};
use glutin::display::{GetGlDisplay, GlDisplay};
use glutin::surface::{GlSurface, Surface, WindowSurface};
use glutin_winit::{DisplayBuilder, GlWindow};
use texflow::gl::Context;
use texflow::{Engine, EngineKind};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::raw_window_handle::HasWindowHandle;
use winit::window::{Window, WindowId};

type Gl = Rc<(PossiblyCurrentContext, Surface<WindowSurface>)>;

/// The application's state; fields drop in order (texflow's objects before the window's context).
struct Running {
    engine: Box<dyn Engine>,
    ctx: Context,
    /// The application's own GL functions (texflow keeps its raw GL to itself).
    app_gl: glow::Context,
    gl: Gl,
    window: Window,
    frame: u64,
}

struct App {
    scene: String,
    frames: Option<u64>,
    running: Option<Running>,
    error: Option<String>,
}

impl App {
    fn open(
        &mut self,
        event_loop: &ActiveEventLoop,
    ) -> Result<Running, Box<dyn std::error::Error>> {
        let attributes = Window::default_attributes()
            .with_title("texflow embedded")
            .with_inner_size(winit::dpi::PhysicalSize::new(480u32, 320u32));
        let (window, config) = DisplayBuilder::new()
            .with_window_attributes(Some(attributes))
            .build(event_loop, ConfigTemplateBuilder::new(), |mut c| {
                c.next().expect("a GL config")
            })?;
        let window = window.ok_or("no window")?;
        let display = config.display();
        let context = ContextAttributesBuilder::new()
            .with_context_api(ContextApi::OpenGl(Some(Version::new(3, 3))))
            .with_profile(GlProfile::Core)
            .build(Some(window.window_handle()?.as_raw()));
        // SAFETY: config and window belong to this display.
        let not_current = unsafe { display.create_context(&config, &context)? };
        let surface_attributes = window.build_surface_attributes(Default::default())?;
        // SAFETY: as above.
        let surface = unsafe { display.create_window_surface(&config, &surface_attributes)? };
        let current = not_current.make_current(&surface)?;
        let gl: Gl = Rc::new((current, surface));
        let again = Rc::clone(&gl);
        // SAFETY: the application's context is current; `again` keeps it alive as long as texflow
        // holds the wrapped context.
        let ctx = unsafe {
            Context::from_current(
                |name| display.get_proc_address(name),
                Some(Box::new(move || {
                    again.0.make_current(&again.1).map_err(|e| e.to_string())
                })),
            )?
        };
        // SAFETY: the application's context is current; glow only stores the pointers.
        let app_gl =
            unsafe { glow::Context::from_loader_function_cstr(|n| display.get_proc_address(n)) };
        println!(
            "texflow draws on {} in the application's context",
            ctx.limits().renderer
        );
        // The scene at the size of the inset it is drawn into.
        let mut scene = texflow::scene::load(&self.scene)?;
        scene.render.resolution = [320, 240];
        scene.check()?;
        let engine = texflow::engine::build(&ctx, &scene, 1, EngineKind::Gpu)?;
        Ok(Running {
            engine,
            ctx,
            app_gl,
            gl,
            window,
            frame: 0,
        })
    }
}

fn redraw(r: &mut Running) -> texflow::Result<()> {
    r.engine.advance_frame()?;
    // texflow draws into its frame target (an offscreen framebuffer)...
    r.engine.draw()?;
    let target = r.engine.target();
    // ...the application draws its own frame: here a slate background with a lighter border...
    let size = r.window.inner_size();
    // The application's context is current again if texflow switched away from it.
    r.ctx.make_current()?;
    let gl = &r.app_gl;
    // SAFETY: the application's context is current; framebuffer 0 is its window.
    unsafe {
        gl.bind_framebuffer(glow::FRAMEBUFFER, None);
        gl.viewport(0, 0, size.width as i32, size.height as i32);
        gl.disable(glow::SCISSOR_TEST);
        gl.clear_color(0.25, 0.3, 0.35, 1.0);
        gl.clear(glow::COLOR_BUFFER_BIT);
        gl.enable(glow::SCISSOR_TEST);
        gl.scissor(76, 36, 328, 248);
        gl.clear_color(0.8, 0.8, 0.7, 1.0);
        gl.clear(glow::COLOR_BUFFER_BIT);
        gl.disable(glow::SCISSOR_TEST);
    }
    // ...and the particles go into the inset of its frame.
    target
        .framebuffer()
        .blit_to_default([80, 40, target.width(), target.height()])?;
    r.gl.1
        .swap_buffers(&r.gl.0)
        .map_err(|e| texflow::Error::Gl(e.to_string()))?;
    r.frame += 1;
    Ok(())
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_none() {
            match self.open(event_loop) {
                Ok(r) => self.running = Some(r),
                Err(e) => {
                    self.error = Some(e.to_string());
                    event_loop.exit();
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(r) = &mut self.running else { return };
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(s) => {
                if let (Some(w), Some(h)) = (NonZeroU32::new(s.width), NonZeroU32::new(s.height)) {
                    r.gl.1.resize(&r.gl.0, w, h);
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = redraw(r) {
                    self.error = Some(e.to_string());
                    event_loop.exit();
                } else if self.frames.is_some_and(|n| r.frame >= n) {
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _: &ActiveEventLoop) {
        if let Some(r) = &self.running {
            r.window.request_redraw();
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut app = App {
        scene: args.next().unwrap_or_else(|| "fountain".into()),
        frames: args.next().map(|n| n.parse()).transpose()?,
        running: None,
        error: None,
    };
    EventLoop::new()?.run_app(&mut app)?;
    if let Some(e) = app.error {
        return Err(e.into());
    }
    let frames = app.running.as_ref().map_or(0, |r| r.frame);
    println!("drew {frames} frames into the application's window");
    Ok(())
}
