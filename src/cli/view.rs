//! `texflow view`: the scene live in a window (winit + glutin, OpenGL 3.3 core, X11 or Wayland).
//!
//! The same engine ([`texflow::Engine`]) and passes as `render` run in the window's own GL context, wrapped
//! with [`Context::from_current`] (the embedding path of examples/embed.rs); each frame is drawn
//! into the engine's frame target and blitted to the window. The mouse orbits (drag) and zooms
//! (wheel); space pauses, `.` or → steps one frame, `r` restarts, Esc or `q` quits. A scene file
//! is reloaded when its modification time changes; an error goes to the title and stderr and
//! the last good scene keeps running. `--frames N --screenshot FILE` writes the window's frame N
//! and quits (for tests under Xvfb).

use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime};

use super::overrides::Overrides;
use clap::Args;
use texflow::gl::{Context, GlWindow};
use texflow::render::ViewOffset;
use texflow::sim::nonfinite::NonFiniteCounter;
use texflow::{Engine, EngineKind};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, KeyEvent, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::WindowId;

use super::{at_least_one, bad, parse_size, time_step};

#[derive(Args)]
#[command(allow_negative_numbers = true)]
pub struct ViewArgs {
    /// The scene: a built-in name or a .toml scene file.
    #[arg(help = super::scene_help("show", " (reloaded when it changes on disk)"), default_value = texflow::scene::DEFAULT_SCENE)]
    scene: String,
    /// Stop after N frames (default: run until the window is closed).
    #[arg(long, value_name = "N", value_parser = at_least_one::<u64>)]
    frames: Option<u64>,
    /// With --frames: write the window's last frame as a PNG, then quit.
    #[arg(long, value_name = "FILE", requires = "frames")]
    screenshot: Option<PathBuf>,
    /// State texture size WxH (one particle per texel), or N for NxN. Default: the scene's.
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    particles: Option<[u32; 2]>,
    /// Frame (and window) size WxH in pixels, or N for NxN. Default: the scene's.
    #[arg(long, value_name = "WxH", value_parser = parse_size)]
    resolution: Option<[u32; 2]>,
    /// Random seed (same seed: the same frames as `render`).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Simulation time step in seconds. Default: the scene's.
    #[arg(long, value_parser = time_step, allow_hyphen_values = true)]
    dt: Option<f32>,
    /// Simulation steps per frame. Default: the scene's.
    #[arg(long, value_parser = at_least_one::<u32>)]
    substeps: Option<u32>,
    /// Drop the scene's collisions between particles.
    #[arg(long)]
    no_collisions: bool,
    #[command(flatten)]
    set: super::set::SetArgs,
}

impl ViewArgs {
    fn overrides(&self) -> Overrides {
        Overrides {
            particles: self.particles,
            resolution: self.resolution,
            dt: self.dt,
            substeps: self.substeps,
            no_collisions: self.no_collisions,
            seed: self.seed,
            device: 0,
            set: self.set.set.clone(),
        }
    }
}

/// What lives while the window is open. Fields drop in order: the engine's GL objects first,
/// then the wrapped context, the window's context and surface, and the window last.
struct Live {
    engine: Box<dyn Engine>,
    counter: NonFiniteCounter,
    ctx: Context,
    gl: GlWindow,
}

/// Milliseconds of wall time per phase, averaged over the frames since the last title update.
#[derive(Default)]
struct Phases {
    frames: u32,
    simulate: f64,
    sort: f64,
    draw: f64,
}

/// The user's turn of the scene's camera.
#[derive(Clone, Copy)]
struct Orbit {
    azimuth: f32,
    elevation: f32,
    zoom: f32,
}

impl Default for Orbit {
    fn default() -> Self {
        Orbit {
            azimuth: 0.0,
            elevation: 0.0,
            zoom: 1.0,
        }
    }
}

struct App {
    args: ViewArgs,
    prepared: super::overrides::Prepared,
    /// The scene file and its modification time, when the scene is a file.
    watched: Option<(PathBuf, Option<SystemTime>)>,
    live: Option<Live>,
    result: texflow::Result<()>,
    frame: u64,
    paused: bool,
    step: bool,
    orbit: Orbit,
    drag: Option<(f64, f64)>,
    cursor: (f64, f64),
    error: Option<String>,
    phases: Phases,
    live_particles: u64,
    /// Whether this engine's dropped births were warned about (once per engine, as `render`).
    warned_drops: bool,
    last_title: Instant,
    last_poll: Instant,
}

fn context_err(reason: impl std::fmt::Display) -> texflow::Error {
    texflow::Error::Context {
        device: 0,
        reason: format!("window: {reason}"),
    }
}

fn mtime(path: &std::path::Path) -> Option<SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

impl App {
    fn open(&mut self, event_loop: &ActiveEventLoop) -> texflow::Result<()> {
        let gl = GlWindow::open(
            event_loop,
            "texflow view",
            self.prepared.scene.render.resolution,
        )?;
        let ctx = gl.context().clone();
        let engine =
            texflow::engine::build(&ctx, &self.prepared.scene, self.args.seed, EngineKind::Gpu)?;
        let [sw, sh] = engine.state_size();
        let counter = NonFiniteCounter::new(&ctx, sw, sh)?;
        self.live = Some(Live {
            engine,
            counter,
            ctx,
            gl,
        });
        Ok(())
    }

    /// A new engine for the current scene, from frame 0.
    fn restart(&mut self) -> texflow::Result<()> {
        let Some(live) = &mut self.live else {
            return Ok(());
        };
        live.engine = texflow::engine::build(
            &live.ctx,
            &self.prepared.scene,
            self.args.seed,
            EngineKind::Gpu,
        )?;
        let [sw, sh] = live.engine.state_size();
        live.counter = NonFiniteCounter::new(&live.ctx, sw, sh)?;
        self.frame = 0;
        self.warned_drops = false;
        Ok(())
    }

    /// Reloads the scene file if it changed on disk; errors stay in the title.
    fn poll_file(&mut self) {
        let Some((path, seen)) = &mut self.watched else {
            return;
        };
        let now = mtime(path);
        if now == *seen {
            return;
        }
        *seen = now;
        let label = path.display().to_string();
        match self.args.overrides().prepare(&label).and_then(|p| {
            if let Some(live) = &self.live {
                self.args.overrides().check_device(&live.ctx, &p)?;
            }
            Ok(p)
        }) {
            Ok(p) => {
                self.prepared = p;
                match self.restart() {
                    Ok(()) => {
                        self.error = None;
                        eprintln!("texflow view: reloaded {label}");
                    }
                    Err(e) => self.report(format!("{e}")),
                }
            }
            Err(e) => self.report(format!("{e}")),
        }
    }

    fn report(&mut self, message: String) {
        eprintln!("texflow view: {message} (the last good scene keeps running)");
        self.error = Some(message);
    }

    /// Simulates (unless paused), sorts and draws one frame into the window, and swaps.
    fn frame(&mut self) -> texflow::Result<()> {
        let orbit = self.orbit;
        let advance = !self.paused || std::mem::take(&mut self.step);
        let live = self.live.as_mut().expect("a window");
        let t0 = Instant::now();
        if advance {
            live.engine.advance_frame()?;
            self.frame += 1;
            let total = live.engine.dropped_births();
            if total > 0 && !self.warned_drops {
                self.warned_drops = true;
                let s = &self.prepared.scene;
                eprintln!("{}", super::warn::births_dropped(s, self.frame - 1, total));
            }
        }
        live.ctx.finish();
        let t1 = Instant::now();
        let (target, sort_ms) = draw(live.engine.as_mut(), &orbit, &live.ctx, t1)?;
        let size = live.gl.window().inner_size();
        target.framebuffer().blit_to_default(fit(
            [target.width(), target.height()],
            [size.width, size.height],
        ))?;
        live.ctx.finish();
        self.phases.sort += sort_ms;
        self.phases.draw += t1.elapsed().as_secs_f64() * 1e3 - sort_ms;
        self.phases.simulate += (t1 - t0).as_secs_f64() * 1e3;
        self.phases.frames += 1;
        if let (Some(n), Some(path)) = (self.args.frames, &self.args.screenshot) {
            if self.frame >= n {
                let img = live.ctx.read_default_rgb(size.width, size.height)?;
                texflow::output::write_png_atomic(path, &img)?;
            }
        }
        live.gl.swap_buffers()?;
        Ok(())
    }

    fn title(&mut self) {
        let Some(live) = &self.live else {
            return;
        };
        let elapsed = self.last_title.elapsed().as_secs_f64();
        if elapsed < 0.5 && self.phases.frames > 0 {
            return;
        }
        if let Ok(c) = live.engine.non_finite(&live.counter) {
            self.live_particles = c.live;
        }
        let p = &self.phases;
        let n = p.frames.max(1) as f64;
        let mut title = format!(
            "texflow view {} | frame {} | {:.1} fps | {} live | simulate {:.1} ms, sort {:.1} ms, draw {:.1} ms",
            self.prepared.label,
            self.frame,
            p.frames as f64 / elapsed.max(1e-9),
            self.live_particles,
            p.simulate / n,
            p.sort / n,
            p.draw / n,
        );
        if self.paused {
            title.push_str(" | paused");
        }
        if let Some(e) = &self.error {
            title.push_str(" | error: ");
            title.push_str(e.lines().next().unwrap_or(""));
        }
        live.gl.window().set_title(&title);
        self.phases = Phases::default();
        self.last_title = Instant::now();
    }

    fn key(&mut self, event: &KeyEvent, event_loop: &ActiveEventLoop) {
        if event.state != ElementState::Pressed {
            return;
        }
        match &event.logical_key {
            Key::Named(NamedKey::Space) => self.paused = !self.paused,
            Key::Named(NamedKey::ArrowRight) => self.single_step(),
            Key::Named(NamedKey::Escape) => event_loop.exit(),
            Key::Character(c) => match c.as_str() {
                "." => self.single_step(),
                "r" | "R" => {
                    if let Err(e) = self.restart() {
                        self.report(format!("{e}"));
                    }
                }
                "q" | "Q" => event_loop.exit(),
                _ => {}
            },
            _ => {}
        }
    }

    fn single_step(&mut self) {
        self.paused = true;
        self.step = true;
    }
}

/// Draws the engine's frame for the viewer's `orbit`: the same sort stage and draw as `render`
/// (the sort follows the viewer's camera); returns the frame target and the sort's ms.
fn draw<'a>(
    engine: &'a mut dyn Engine,
    orbit: &Orbit,
    ctx: &Context,
    start: Instant,
) -> texflow::Result<(&'a texflow::render::FrameTarget, f64)> {
    engine.set_view(ViewOffset {
        azimuth: orbit.azimuth,
        elevation: orbit.elevation,
        zoom: orbit.zoom,
    });
    engine.order_for_drawing()?;
    ctx.finish();
    let sort_ms = start.elapsed().as_secs_f64() * 1e3;
    engine.draw()?;
    ctx.check_error("drawing a frame")?;
    Ok((engine.target(), sort_ms))
}

/// The largest rectangle of the frame's aspect centred in the window (1:1 when the sizes match).
fn fit([fw, fh]: [u32; 2], [ww, wh]: [u32; 2]) -> [u32; 4] {
    if [fw, fh] == [ww, wh] || ww == 0 || wh == 0 {
        return [0, 0, fw, fh];
    }
    let scale = (ww as f64 / fw as f64).min(wh as f64 / fh as f64);
    let (w, h) = (
        ((fw as f64 * scale).round() as u32).max(1),
        ((fh as f64 * scale).round() as u32).max(1),
    );
    [(ww - w.min(ww)) / 2, (wh - h.min(wh)) / 2, w, h]
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.live.is_none() {
            if let Err(e) = self.open(event_loop) {
                self.result = Err(e);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(live) = &self.live {
                    live.gl.resize(size.width, size.height);
                }
            }
            WindowEvent::KeyboardInput { event, .. } => self.key(&event, event_loop),
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.drag = (state == ElementState::Pressed).then_some(self.cursor);
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((x, y)) = self.drag {
                    self.orbit.azimuth -= (position.x - x) as f32 * 0.4;
                    self.orbit.elevation += (position.y - y) as f32 * 0.4;
                    self.drag = Some(self.cursor);
                }
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.orbit.zoom = (self.orbit.zoom * 0.9f32.powf(lines)).clamp(0.05, 20.0);
            }
            WindowEvent::RedrawRequested => {
                if self.live.is_none() {
                    return;
                }
                if self.last_poll.elapsed() >= Duration::from_millis(500) {
                    self.last_poll = Instant::now();
                    self.poll_file();
                }
                if let Err(e) = self.frame() {
                    self.result = Err(e);
                    event_loop.exit();
                    return;
                }
                self.title();
                if self.args.frames.is_some_and(|n| self.frame >= n) {
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        if let Some(live) = &self.live {
            live.gl.window().request_redraw();
        }
        // Paused, the window is still redrawn (orbit), at about 30 frames a second.
        event_loop.set_control_flow(if self.paused {
            ControlFlow::WaitUntil(Instant::now() + Duration::from_millis(33))
        } else {
            ControlFlow::Poll
        });
    }
}

pub fn view(a: ViewArgs) -> texflow::Result<()> {
    let prepared = a.overrides().prepare(&a.scene)?;
    // Without a display, sizes (and custom forces) are checked against a headless device first,
    // so that a size over the limit is refused for the size, not for the display. With one, the
    // window's own context checks them: a headless EGL context made first in the same process
    // makes Mesa's GLX refuse the window's context (BadAccess).
    let display = ["DISPLAY", "WAYLAND_DISPLAY"]
        .iter()
        .any(|v| std::env::var_os(v).is_some_and(|d| !d.is_empty()));
    if !display {
        if let Ok(ctx) = Context::new(0) {
            a.overrides().check_device(&ctx, &prepared)?;
        }
    }
    if let Some(s) = &a.screenshot {
        texflow::output::check_target(s, "--screenshot")?;
        let inputs = super::targets::inputs(&prepared.label, &prepared.scene);
        super::targets::check_file(s, "--screenshot", &inputs)?;
    }
    let file = PathBuf::from(&a.scene);
    let watched = file.is_file().then(|| {
        let t = mtime(&file);
        (file, t)
    });
    let no_display = |reason: String| {
        bad(format!(
            "cannot open a window ({reason}): `texflow view` needs a display (X11 or Wayland; \
             set DISPLAY or WAYLAND_DISPLAY, or run it under xvfb-run); `texflow render` needs \
             none"
        ))
    };
    let set = |v: &str| std::env::var_os(v).is_some_and(|s| !s.is_empty());
    if !set("DISPLAY") && !set("WAYLAND_DISPLAY") {
        return Err(no_display(
            "neither DISPLAY nor WAYLAND_DISPLAY is set".into(),
        ));
    }
    let event_loop = EventLoop::new().map_err(|e| no_display(super::warn::window_reason(&e)))?;
    let mut app = App {
        args: a,
        prepared,
        watched,
        live: None,
        result: Ok(()),
        frame: 0,
        paused: false,
        step: false,
        orbit: Orbit::default(),
        drag: None,
        cursor: (0.0, 0.0),
        error: None,
        phases: Phases::default(),
        live_particles: 0,
        warned_drops: false,
        last_title: Instant::now(),
        last_poll: Instant::now(),
    };
    event_loop
        .run_app(&mut app)
        .map_err(|e| context_err(format!("event loop: {e}")))?;
    app.result
}
