//! The fetch floor, a second bound of every phase that is not a render pass, built from the
//! phase's own draws (recorded by the GL layer, [`ShapeRecorder`]): for each full-screen draw
//! the phase made, a pass into targets of the same formats and size, over the same viewport,
//! that fetches each texture the draw bound once at the fragment's own texel and writes zeros
//! (`glsl/bench/fetch_floor.frag`). A pass that reads each of its inputs at least once and
//! writes the same bytes costs at least this.
//!
//! It reads the very textures the draw read, where they still live (the phase's state, as the
//! phase left it): what a read costs depends on the data where the driver compresses textures
//! it rendered into (a sparse state of dead particles, all alike, reads and writes for less on
//! NVIDIA), so a floor reading values no driver compresses, as the first version did, cost up to
//! 1.6 times the pass it bounded. For the same reason it writes zeros, no more costly to write
//! than anything the pass writes. A texture freed since (none in the built-in scenes) is
//! replaced by one of the same shape holding values no driver compresses.
//!
//! A draw that walked the cells around every live particle (the exact detection's count, DEM,
//! the fluid's density and force, the pair exchange: `glsl/collide/cells.glsl`) has a floor
//! that walks the same cells with the same sorted keys, table and uniforms and fetches each
//! visited neighbour's position once, which each of those passes reads of every neighbour, in
//! the pass's order of fragments (the count's walk order, `WALK_TILES`). A tally's level (a
//! block reduction, `glsl/collide/tally.frag`) reads a block of `TALLY_BLOCK`² texels a fragment,
//! and its floor reads the same block. Other reads many times a fragment (relaxation's
//! neighbours, a field sampled at a computed place) are not counted, as no count of them is
//! honest for every pass.
//! Draws of points or lines (the births' emit pass) have no fetch floor of their own:
//! where they fall is the data's, and a full-screen pass would write more than they do.

use std::cell::RefCell;
use std::collections::HashMap;

use super::floors::{drawn, Drawn};
use super::walk::{generic_reads, walk_of, Walk};
use crate::bench::stats::PassTimer;
use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Draw, DrawShape, DrawState, Framebuffer, Primitive, Program, ReadShape,
    Sampled, ShapeRecorder, Texture, Texture3D, TextureDesc, TextureFormat, Uniform, VertexArray,
    FULLSCREEN_VERTEX,
};

/// What the fetch floor is, in the phase table.
pub(super) const FETCH_FLOOR: &str = "fetch floor: per full-screen draw, a pass into the same \
    targets and viewport fetching each texture it bound (the same data) once at the fragment's \
    texel, and in a neighbour search each visited neighbour's position, writing zeros";

/// The kinds of sampler the floor's shader declares, their defines, names, most of each, and
/// the uniform array of their sizes.
const KINDS: [(&str, &str, usize, &str); 4] = [
    ("F2", "u_f2_", 16, "u_f2_size"),
    ("U2", "u_u2_", 4, "u_u2_size"),
    ("F3", "u_f3_", 4, "u_f3_size"),
    ("U3", "u_u3_", 2, "u_u3_size"),
];

/// The sizes of the textures draw `d` fetches at its texel (`reads`, in the order [`bound`]
/// names them), by kind: the shader clamps each fetch to them.
fn sizes(d: &DrawShape, reads: &[usize]) -> Vec<(&'static str, Uniform)> {
    let mut per_kind: [Vec<[i32; 4]>; 4] = Default::default();
    for &i in reads {
        let r = &d.reads[i];
        let [w, h, depth] = r.size.map(|n| n as i32);
        per_kind[kind(r)].push([w, h, depth, 0]);
    }
    (KINDS.iter().zip(per_kind))
        .filter(|(_, s)| !s.is_empty())
        .map(|(k, s)| (k.3, Uniform::IVec4s(s.into())))
        .collect()
}

/// The kind of sampler `r` is read through (an index into [`KINDS`]).
fn kind(r: &ReadShape) -> usize {
    let unsigned = r.format == TextureFormat::Rgba32Ui;
    2 * r.three_d as usize + unsigned as usize
}

/// A program of the floor: samplers of each kind, targets, unsigned targets, and for a draw
/// that walked the cells the search's defines (with `WALK`), else none.
type ProgramKey = ([usize; 4], usize, bool, Defines);

/// A target of the floor: size and formats.
type TargetKey = ([u32; 2], Vec<TextureFormat>);

/// A texture the floor reads in place of one a draw bound (same size and format).
enum Input {
    D2(Texture),
    D3(Texture3D),
}

/// Runs `f`, recording the shapes of the draws it made.
pub(super) fn recorded<T>(f: impl FnOnce() -> Result<T>) -> Result<(T, Vec<DrawShape>)> {
    let recorder = ShapeRecorder::start();
    let out = f()?;
    Ok((out, recorder.finish()))
}

/// The fetch floor's programs, targets and inputs, made on first use and kept.
pub(super) struct FetchFloor {
    ctx: Context,
    vao: VertexArray,
    programs: RefCell<HashMap<ProgramKey, Program>>,
    targets: RefCell<HashMap<TargetKey, Framebuffer>>,
    /// By shape and by which read of that shape in one draw it is: two reads of one draw never
    /// share a texture (nor a cache line).
    inputs: RefCell<HashMap<(ReadShape, usize), Input>>,
    /// Write the sum of the fetches, not zeros (a test's view of what was fetched).
    reveal: std::cell::Cell<bool>,
}

impl FetchFloor {
    pub(super) fn new(ctx: &Context) -> Result<Self> {
        Ok(FetchFloor {
            ctx: ctx.clone(),
            vao: VertexArray::empty(ctx, "fetch floor")?,
            programs: RefCell::default(),
            targets: RefCell::default(),
            inputs: RefCell::default(),
            reveal: Default::default(),
        })
    }

    /// The floor of a phase that made `shapes`: its milliseconds and what it drew. Nothing
    /// drawn (no full-screen draw) costs nothing: 0 ms, not timed.
    pub(super) fn measure(&self, timer: &PassTimer, shapes: &[DrawShape]) -> Result<(f64, Drawn)> {
        let draws: Vec<&DrawShape> = shapes
            .iter()
            .filter(|d| d.primitive == Primitive::Triangles && d.count >= 3)
            .collect();
        let walks: Vec<Option<Walk>> = draws.iter().map(|d| walk_of(&self.ctx, d)).collect();
        // Each draw's reads fetched at its texel and its program, found once, before the timing.
        let reads: Vec<Vec<usize>> = (draws.iter().zip(&walks))
            .map(|(d, w)| generic_reads(d, w.as_ref()))
            .collect();
        let keys: Vec<ProgramKey> = (0..draws.len())
            .map(|i| program_key(draws[i], &reads[i], walks[i].as_ref()))
            .collect();
        for i in 0..draws.len() {
            self.prepare(draws[i], &reads[i], &keys[i])?;
        }
        if draws.is_empty() {
            return Ok((0.0, Drawn::default()));
        }
        let (programs, targets) = (self.programs.borrow(), self.targets.borrow());
        let inputs = self.inputs.borrow();
        // Each draw's samplers and textures, by name, made before the timing.
        let bound = self.bound(&inputs, &draws, &reads, &walks);
        let named: Vec<Vec<(&str, Sampled)>> = bound
            .iter()
            .map(|l| l.iter().map(|(n, t)| (n.as_str(), *t)).collect())
            .collect();
        let reveal = Uniform::I32(self.reveal.get() as i32);
        let layers: Vec<Vec<(&str, Uniform)>> = (0..draws.len())
            .map(|i| {
                let mut u = vec![
                    ("u_layer", Uniform::I32(i as i32)),
                    ("u_sentinel", Uniform::F32(f32::NAN)),
                    ("u_reveal", reveal.clone()),
                ];
                u.extend(walks[i].iter().flat_map(|w| w.uniforms.iter().cloned()));
                u.extend(sizes(draws[i], &reads[i]));
                u
            })
            .collect();
        let walked = walks.iter().filter(|w| w.is_some()).count() as u64;
        let (ms, drawn) = drawn(&self.ctx, || {
            timer.time(|| {
                for (i, d) in draws.iter().enumerate() {
                    self.ctx.draw(&Draw {
                        program: &programs[&keys[i]],
                        target: &targets[&(d.size, d.formats.clone())],
                        viewport: d.viewport,
                        vertices: &self.vao,
                        primitive: Primitive::Triangles,
                        count: 3,
                        state: &DrawState::REPLACE,
                        textures: &named[i],
                        uniforms: &layers[i],
                    });
                }
            })
        })?;
        Ok((ms, Drawn { walked, ..drawn }))
    }

    /// Each draw's samplers and the textures bound to them: the draw's own where they live,
    /// else `inputs` of the same shape, then the walk's.
    fn bound<'a>(
        &self,
        inputs: &'a HashMap<(ReadShape, usize), Input>,
        draws: &[&DrawShape],
        reads: &[Vec<usize>],
        walks: &[Option<Walk>],
    ) -> Vec<Vec<(String, Sampled<'a>)>> {
        let mut bound = Vec::new();
        for (i_draw, d) in draws.iter().enumerate() {
            let mut seen = HashMap::new();
            let mut per_kind = [0usize; 4];
            let mut list = Vec::new();
            for &i in &reads[i_draw] {
                let r = &d.reads[i];
                let n = seen.entry(*r).or_insert(0usize);
                let k = kind(r);
                let name = format!("{}{}", KINDS[k].1, per_kind[k]);
                per_kind[k] += 1;
                // The texture the draw read, where it lives: the same data; else one of the
                // same shape holding values no driver compresses.
                let own = (d.sources.get(i)).filter(|t| self.ctx.is_live(t));
                let texture = match (own, &inputs[&(*r, *n)]) {
                    (Some(t), _) => Sampled::Recorded(*t),
                    (None, Input::D2(t)) => Sampled::D2(t),
                    (None, Input::D3(t)) => Sampled::D3(t),
                };
                *n += 1;
                list.push((name, texture));
            }
            for (name, t) in walks[i_draw].iter().flat_map(|w| &w.textures) {
                list.push((name.to_string(), Sampled::Recorded(*t)));
            }
            bound.push(list);
        }
        bound
    }

    /// Makes what the floor of draw `d` needs, where not made yet: its program `key`, its
    /// target, and inputs for its `reads` (indices into `d.reads`).
    fn prepare(&self, d: &DrawShape, reads: &[usize], key: &ProgramKey) -> Result<()> {
        if let Some(k) = (0..4).find(|&k| key.0[k] > KINDS[k].2) {
            return Err(Error::InvalidInput(format!(
                "the fetch floor of a draw of {}: it binds {} textures of kind {}, and \
                 glsl/bench/fetch_floor.frag declares {}; declare more there",
                d.program, key.0[k], KINDS[k].0, KINDS[k].2
            )));
        }
        if !self.programs.borrow().contains_key(key) {
            let mut defines: Defines = (0..4)
                .map(|k| (KINDS[k].0.to_owned(), key.0[k].to_string()))
                .collect();
            defines.push(("TARGETS".into(), key.1.to_string()));
            if key.2 {
                defines.push(("UINT".into(), "1".into()));
            }
            defines.extend(key.3.iter().cloned());
            let p = Program::new(
                &self.ctx,
                FULLSCREEN_VERTEX,
                "bench/fetch_floor.frag",
                &defines,
            )?;
            self.programs.borrow_mut().insert(key.clone(), p);
        }
        let target = (d.size, d.formats.clone());
        if !self.targets.borrow().contains_key(&target) {
            let fb = self.target(d)?;
            self.targets.borrow_mut().insert(target, fb);
        }
        let mut seen = HashMap::new();
        for r in reads.iter().map(|&i| &d.reads[i]) {
            let n = seen.entry(*r).or_insert(0usize);
            if !self.inputs.borrow().contains_key(&(*r, *n)) {
                let t = self.input(r)?;
                self.inputs.borrow_mut().insert((*r, *n), t);
            }
            *n += 1;
        }
        Ok(())
    }

    /// A framebuffer of `d`'s target's size and formats.
    fn target(&self, d: &DrawShape) -> Result<Framebuffer> {
        let [width, height] = d.size;
        let textures = (d.formats.iter().enumerate())
            .map(|(k, &format)| {
                let label = format!("fetch floor target {k}");
                let desc = TextureDesc {
                    width,
                    height,
                    format,
                    label: &label,
                };
                Texture::new(&self.ctx, desc)
            })
            .collect::<Result<Vec<_>>>()?;
        Framebuffer::new(&self.ctx, "fetch floor", textures)
    }

    /// A texture of `r`'s size and format, holding values that differ from texel to texel
    /// (floats; unsigned ones are left as allocated), so that no driver can store it as a
    /// constant.
    fn input(&self, r: &ReadShape) -> Result<Input> {
        let [w, h, depth] = r.size;
        let values =
            |n: usize| -> Vec<f32> { (0..n).map(|i| (i as f32 * 0.618_034).fract()).collect() };
        let n = w as usize * h as usize * depth as usize * r.format.channels();
        if r.three_d {
            let data = r.format.is_float().then(|| values(n));
            let t = Texture3D::new(
                &self.ctx,
                "fetch floor input",
                r.format,
                r.size,
                data.as_deref(),
            )?;
            return Ok(Input::D3(t));
        }
        let desc = TextureDesc {
            width: w,
            height: h,
            format: r.format,
            label: "fetch floor input",
        };
        let t = Texture::new(&self.ctx, desc)?;
        if r.format.is_float() {
            t.upload_f32(&values(n))?;
        }
        Ok(Input::D2(t))
    }
}

/// The program key of the floor of draw `d`, fetching its `reads` at the texel and walking the
/// cells as `walk` says.
fn program_key(d: &DrawShape, reads: &[usize], walk: Option<&Walk>) -> ProgramKey {
    let mut counts = [0usize; 4];
    for &i in reads {
        counts[kind(&d.reads[i])] += 1;
    }
    let unsigned = d.formats.contains(&TextureFormat::Rgba32Ui);
    let mut defines = walk.map(|w| w.defines.clone()).unwrap_or_default();
    // A tally's level reads a block of texels a fragment: its floor reads the same block.
    if let Some((_, b)) = d.defines.iter().find(|(k, _)| k == "TALLY_BLOCK") {
        defines.push(("BLOCK".into(), b.clone()));
    }
    (counts, d.formats.len(), unsigned, defines)
}

#[cfg(test)]
#[path = "fetch_tests.rs"]
mod tests;
