//! The programs the draws ran, recorded on request: what a frame drew, named by program
//! (`vertex+fragment`), for comparing with the passes the stages list ([`PassInfo`]).

use std::cell::RefCell;

use super::{Draw, Primitive, Rect, Sampled, TextureFormat};

thread_local! {
    // One log per thread: a GL context is current on one thread only.
    static LOG: RefCell<Option<Vec<String>>> = const { RefCell::new(None) };
    static SHAPES: RefCell<Option<Vec<DrawShape>>> = const { RefCell::new(None) };
    // Every live texture's name and the serial number it was made with: a name freed and made
    // anew is another texture, which a recorded draw did not read.
    static LIVE: RefCell<std::collections::HashMap<glow::Texture, u64>> = RefCell::default();
    static SERIAL: std::cell::Cell<u64> = const { std::cell::Cell::new(0) };
}

/// Notes texture `raw` as made: its serial number.
pub(super) fn made(raw: glow::Texture) -> u64 {
    let id = SERIAL.with(|s| {
        s.set(s.get() + 1);
        s.get()
    });
    LIVE.with(|l| l.borrow_mut().insert(raw, id));
    id
}

/// Notes texture `raw` as freed.
pub(super) fn freed(raw: glow::Texture) {
    LIVE.with(|l| l.borrow_mut().remove(&raw));
}

/// Whether `r` is still the texture that was recorded (not freed, its name not made anew).
pub(super) fn lives(r: &RecordedTexture) -> bool {
    LIVE.with(|l| l.borrow().get(&r.raw) == Some(&r.serial))
}

/// One texture a draw read, as data: its size (`[w, h, 1]` for a 2D texture) and format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ReadShape {
    /// Width, height and depth in texels.
    pub size: [u32; 3],
    /// A 3D texture (else 2D).
    pub three_d: bool,
    /// Texel format.
    pub format: TextureFormat,
}

/// The texture one read of a recorded draw bound, by its GL name: a later draw may read the same
/// data again (a floor built from the draw reads what the draw read, compressed or not as the
/// driver keeps it) while the texture lives; [`Context::is_live`](super::Context::is_live)
/// tells whether it still does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct RecordedTexture {
    pub(super) raw: glow::Texture,
    pub(super) serial: u64,
    /// Its size and format.
    pub shape: ReadShape,
}

/// One draw as data, without its program: what it wrote (the target's size and formats, the
/// viewport), what it drew, and the textures it read (one per sampler, in the draw's order).
/// What a floor built from a phase's own draws needs.
#[derive(Debug, Clone, PartialEq)]
pub struct DrawShape {
    /// The program (`vertex+fragment`).
    pub program: String,
    /// The target's width and height.
    pub size: [u32; 2],
    /// Its attachments' formats.
    pub formats: Vec<TextureFormat>,
    /// The viewport; `None`: all of the target.
    pub viewport: Option<Rect>,
    /// What the vertices made.
    pub primitive: Primitive,
    /// Vertices drawn.
    pub count: u32,
    /// The textures bound, one per sampler.
    pub reads: Vec<ReadShape>,
    /// The same textures by name, one per read (empty for a shape made by hand).
    pub sources: Vec<RecordedTexture>,
    /// The samplers they were bound to, one per read (empty for a shape made by hand).
    pub samplers: Vec<String>,
    /// The defines the program was compiled with.
    pub defines: Vec<(String, String)>,
    /// For a program that walks the cells around every live particle
    /// ([`Program::walks_every_live`](super::Program::walks_every_live)): the values of its
    /// integer uniforms at the draw; else empty.
    pub ints: Vec<(String, Vec<i32>)>,
    /// For such a program: the values of its float uniforms at the draw (a trimmed search's
    /// geometry among them); else empty.
    pub floats: Vec<(String, Vec<f32>)>,
}

/// The include of the exact neighbour search: a draw of a program built with it walks the
/// cells around each particle, and its shape records the search's uniforms.
pub const WALK_INCLUDE: &str = "collide/cells.glsl";

impl DrawShape {
    /// Whether its program walks the cells around every live particle.
    pub fn walks(&self) -> bool {
        !self.ints.is_empty()
    }
}

/// Records every draw on this thread as a [`DrawShape`] from [`ShapeRecorder::start`] until
/// [`ShapeRecorder::finish`] (or the recorder's drop).
#[derive(Debug)]
pub struct ShapeRecorder(());

impl ShapeRecorder {
    /// Starts recording (anew, where a recording was under way).
    pub fn start() -> Self {
        SHAPES.with(|l| *l.borrow_mut() = Some(Vec::new()));
        ShapeRecorder(())
    }

    /// Stops recording: the draws since the start, in order.
    pub fn finish(self) -> Vec<DrawShape> {
        SHAPES.with(|l| l.borrow_mut().take()).unwrap_or_default()
    }
}

impl Drop for ShapeRecorder {
    fn drop(&mut self) {
        SHAPES.with(|l| l.borrow_mut().take());
    }
}

/// Notes the shape of `d` where a recording is under way.
pub(crate) fn note_shape(d: &Draw<'_>) {
    SHAPES.with(|l| {
        if let Some(log) = l.borrow_mut().as_mut() {
            let reads = d.textures.iter().map(|(_, t)| match t {
                Sampled::D2(t) => ReadShape {
                    size: [t.width(), t.height(), 1],
                    three_d: false,
                    format: t.format(),
                },
                Sampled::D3(t) => ReadShape {
                    size: t.size(),
                    three_d: true,
                    format: t.format(),
                },
                Sampled::Recorded(r) => r.shape,
            });
            let sources = d.textures.iter().map(|(_, t)| match t {
                Sampled::D2(t) => t.recorded(),
                Sampled::D3(t) => t.recorded(),
                Sampled::Recorded(r) => *r,
            });
            let walks = d.program.walks_every_live();
            log.push(DrawShape {
                program: d.program.name().to_owned(),
                size: [d.target.width(), d.target.height()],
                formats: d.target.formats().to_vec(),
                viewport: d.viewport,
                primitive: d.primitive,
                count: d.count,
                reads: reads.collect(),
                sources: sources.collect(),
                samplers: d.textures.iter().map(|(n, _)| n.to_string()).collect(),
                defines: d.program.defines().clone(),
                ints: if walks {
                    d.program.int_uniforms()
                } else {
                    Vec::new()
                },
                floats: if walks {
                    d.program.float_uniforms()
                } else {
                    Vec::new()
                },
            });
        }
    });
}

/// Records the program of every draw on this thread from [`DrawRecorder::start`] until
/// [`DrawRecorder::finish`] (or the recorder's drop).
#[derive(Debug)]
pub struct DrawRecorder(());

impl DrawRecorder {
    /// Starts recording (anew, where a recording was under way).
    pub fn start() -> Self {
        LOG.with(|l| *l.borrow_mut() = Some(Vec::new()));
        DrawRecorder(())
    }

    /// Stops recording: the programs drawn since the start, in order.
    pub fn finish(self) -> Vec<String> {
        LOG.with(|l| l.borrow_mut().take()).unwrap_or_default()
    }
}

impl Drop for DrawRecorder {
    fn drop(&mut self) {
        LOG.with(|l| l.borrow_mut().take());
    }
}

/// Notes one draw of `program` where a recording is under way.
pub(crate) fn note(program: &str) {
    LOG.with(|l| {
        if let Some(log) = l.borrow_mut().as_mut() {
            log.push(program.to_owned());
        }
    });
}

/// One pass a stage compiled, as the pass list prints it: its stage, what it does in the
/// papers' words (with their sections), the program it draws and how many times a frame (or a
/// step) draws it.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct PassInfo {
    /// The stage that runs it: births, integrate, relax, collide, sort, gather or render.
    pub stage: &'static str,
    /// What it does, what it reads and writes, in the papers' words.
    pub name: String,
    /// The programs it draws (`vertex+fragment`), each with its draws per step (simulation
    /// stages) or per frame (the others); a pass that draws nothing of its own (CPU work, a
    /// texture copy) lists none.
    pub draws: Vec<(String, u64)>,
    /// Its draws depend on the data (births, live slices): at most `draws`, each at least once
    /// when it runs at all.
    pub varies: bool,
}

/// Draws of one program that a stage runs, for the pass list line that starts with `line`
/// (after any `N × ` count): what the stage's code returns next to its programs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PassDraw {
    /// How the line of the pass begins.
    pub line: String,
    /// The program (`vertex+fragment`).
    pub program: String,
    /// Draws per step (simulation stages) or per frame.
    pub times: u64,
    /// The draws depend on the data (see [`PassInfo::varies`]).
    pub varies: bool,
}

impl PassDraw {
    /// `times` draws of the program named `program` for the line beginning with `line`.
    pub fn new(line: impl Into<String>, program: impl Into<String>, times: u64) -> Self {
        PassDraw {
            line: line.into(),
            program: program.into(),
            times,
            varies: false,
        }
    }

    /// Like [`PassDraw::new`], for a program the stage holds.
    pub fn of(line: impl Into<String>, program: &super::Program, times: u64) -> Self {
        Self::new(line, program.name(), times)
    }

    /// The draws depend on the data.
    pub fn varying(mut self) -> Self {
        self.varies = true;
        self
    }
}

/// The passes of one stage: its `lines` (in order), each with the `draws` that name it. Draws
/// are taken in the lines' order: each goes to the first line from the previous draw's on that
/// begins with its `line`, so that a pass listed twice (two lattices) takes the draws listed
/// twice. A draw that names no line is left out, where the pass-list test finds it drawn but
/// not listed.
pub fn attach_draws(
    stage: &'static str,
    lines: Vec<String>,
    draws: Vec<PassDraw>,
) -> Vec<PassInfo> {
    let mut out: Vec<PassInfo> = lines.into_iter().map(|l| PassInfo::new(stage, l)).collect();
    let mut at = 0;
    for d in draws {
        let found = (at..out.len()).find(|&i| strip_count(&out[i].name).starts_with(&d.line));
        if let Some(i) = found {
            out[i].add(&d.program, d.times);
            out[i].varies |= d.varies;
            at = i;
        }
    }
    out
}

/// A line without its leading `N × ` (a pass repeated N times).
fn strip_count(line: &str) -> &str {
    match line.split_once(" × ") {
        Some((n, rest)) if n.chars().all(|c| c.is_ascii_digit()) => rest,
        _ => line,
    }
}

impl PassInfo {
    /// A pass of `stage` named `name` that draws nothing yet (see [`PassInfo::draws`]).
    pub fn new(stage: &'static str, name: impl Into<String>) -> Self {
        PassInfo {
            stage,
            name: name.into(),
            draws: Vec::new(),
            varies: false,
        }
    }

    /// The pass draws `program` `times` times.
    pub fn draws(mut self, program: &super::Program, times: u64) -> Self {
        self.add(program.name(), times);
        self
    }

    /// Adds `times` draws of the program named `name`.
    pub fn add(&mut self, name: &str, times: u64) {
        match self.draws.iter_mut().find(|(n, _)| n == name) {
            Some((_, t)) => *t += times,
            None => self.draws.push((name.to_owned(), times)),
        }
    }
}
