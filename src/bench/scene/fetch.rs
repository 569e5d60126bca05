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
//! the pass's order of fragments (the count's walk order, `WALK_TILES`). Other reads many times a fragment (relaxation's neighbours, a field
//! sampled at a computed place) are not counted, as no count of them is honest for every pass.
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
    let defines = walk.map(|w| w.defines.clone()).unwrap_or_default();
    (counts, d.formats.len(), unsigned, defines)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gl::{Clock, Rect};

    /// What the floor's inputs hold: value `i` of the flat data (see [`FetchFloor::input`]).
    fn value(i: usize) -> f32 {
        (i as f32 * 0.618_034).fract()
    }

    /// The texel `(x, y, z)` of a float input of `size`, as `texelFetch` returns it (missing
    /// channels 0, alpha 1).
    fn texel(r: &ReadShape, [x, y, z]: [u32; 3]) -> [f32; 4] {
        let c = r.format.channels();
        let at = ((z * r.size[1] + y) * r.size[0] + x) as usize * c;
        let mut out = [0.0, 0.0, 0.0, 1.0];
        for (k, o) in out.iter_mut().enumerate().take(c) {
            *o = value(at + k);
        }
        out
    }

    /// Every target of `shape`'s floor holds, at each texel of its viewport, the sum of one
    /// fetch of each read at the texel clamped to the read's size.
    fn check_sums(floor: &FetchFloor, shape: &DrawShape) {
        let targets = floor.targets.borrow();
        let fb = &targets[&(shape.size, shape.formats.clone())];
        for t in fb.textures() {
            let got = t.read_f32().unwrap();
            for y in 1..4u32 {
                for x in 0..8u32 {
                    let mut want = [0.0f32; 4];
                    for r in &shape.reads {
                        let p = [x.min(r.size[0] - 1), y.min(r.size[1] - 1), 0];
                        // Both reads of `small` hold the same values (the same pattern).
                        for (w, v) in want.iter_mut().zip(texel(r, p)) {
                            *w += v;
                        }
                    }
                    let at = (y * 8 + x) as usize * 4;
                    for k in 0..4 {
                        assert!(
                            (got[at + k] - want[k]).abs() < 1e-5,
                            "texel ({x}, {y}) channel {k}: {} against {}",
                            got[at + k],
                            want[k]
                        );
                    }
                }
            }
        }
    }

    /// The floor's pass fetches, for every target, one texel of each bound texture at the
    /// fragment's texel clamped to the texture (a 3D one at the draw's layer, 0): revealed, it
    /// writes their sum, against the same sum on the CPU; as timed, zeros.
    #[test]
    fn the_fetch_floor_writes_the_sum_of_one_fetch_of_each_texture() {
        let ctx = Context::new(0).unwrap();
        let d2 = |w, h, format| ReadShape {
            size: [w, h, 1],
            three_d: false,
            format,
        };
        let small = d2(5, 3, TextureFormat::Rgba32F);
        let volume = ReadShape {
            size: [2, 2, 2],
            three_d: true,
            format: TextureFormat::Rgba32F,
        };
        let reads = vec![small, d2(8, 4, TextureFormat::R32F), volume, small];
        let shape = DrawShape {
            program: "test".into(),
            size: [8, 4],
            formats: vec![TextureFormat::Rgba32F; 2],
            viewport: Some(Rect {
                x: 0,
                y: 1,
                width: 8,
                height: 3,
            }),
            primitive: Primitive::Triangles,
            count: 3,
            reads: reads.clone(),
            sources: Vec::new(),
            samplers: Vec::new(),
            defines: Vec::new(),
            ints: Vec::new(),
            floats: Vec::new(),
        };
        let floor = FetchFloor::new(&ctx).unwrap();
        let timer = PassTimer::new(&ctx, Clock::Wall).unwrap();
        floor.measure(&timer, std::slice::from_ref(&shape)).unwrap();
        let zeros = |floor: &FetchFloor| {
            let targets = floor.targets.borrow();
            let fb = &targets[&(shape.size, shape.formats.clone())];
            fb.textures()
                .iter()
                .all(|t| t.read_f32().unwrap().iter().all(|&v| v == 0.0))
        };
        assert!(zeros(&floor), "the timed floor writes zeros");
        floor.reveal.set(true);
        let (_, drawn) = floor.measure(&timer, std::slice::from_ref(&shape)).unwrap();
        assert_eq!((drawn.stats.draws, drawn.stats.passes), (1, 1));
        assert_eq!(drawn.stats.bytes_written, 8 * 3 * 32);
        check_sums(&floor, &shape);
        // Draws of points have no fetch floor: nothing drawn, nothing timed.
        let points = DrawShape {
            primitive: Primitive::Points,
            ..shape
        };
        let (ms, drawn) = floor.measure(&timer, &[points]).unwrap();
        assert_eq!((ms, drawn.stats.draws), (0.0, 0));
        ctx.check_error("the fetch floor").unwrap();
    }

    /// A recorded draw's own texture is read while it lives (the same data), and once freed
    /// one of its shape is read instead.
    /// An RGBA32F texture of `[w, h]` holding `data`.
    fn rgba(ctx: &Context, label: &str, [width, height]: [u32; 2], data: &[f32]) -> Texture {
        let desc = TextureDesc {
            width,
            height,
            format: TextureFormat::Rgba32F,
            label,
        };
        let t = Texture::new(ctx, desc).unwrap();
        t.upload_f32(data).unwrap();
        t
    }

    /// A full-screen draw into one RGBA32F target of `size` that read `textures` through the
    /// samplers named beside them, as the recorder notes it.
    fn reading(size: [u32; 2], textures: &[(&str, &Texture)]) -> DrawShape {
        DrawShape {
            program: "test".into(),
            size,
            formats: vec![TextureFormat::Rgba32F],
            viewport: None,
            primitive: Primitive::Triangles,
            count: 3,
            reads: textures.iter().map(|(_, t)| t.recorded().shape).collect(),
            sources: textures.iter().map(|(_, t)| t.recorded()).collect(),
            samplers: textures.iter().map(|(n, _)| n.to_string()).collect(),
            defines: Vec::new(),
            ints: Vec::new(),
            floats: Vec::new(),
        }
    }

    #[test]
    fn the_fetch_floor_reads_the_draws_own_texture_while_it_lives() {
        let ctx = Context::new(0).unwrap();
        let data: Vec<f32> = (0..32).map(|i| 100.0 + i as f32).collect();
        let own = rgba(&ctx, "own", [4, 2], &data);
        let shape = reading([4, 2], &[("u_own", &own)]);
        let floor = FetchFloor::new(&ctx).unwrap();
        floor.reveal.set(true);
        let timer = PassTimer::new(&ctx, Clock::Wall).unwrap();
        let written = |floor: &FetchFloor| {
            floor.measure(&timer, std::slice::from_ref(&shape)).unwrap();
            let targets = floor.targets.borrow();
            targets[&(shape.size, shape.formats.clone())]
                .only_texture()
                .read_f32()
                .unwrap()
        };
        assert_eq!(written(&floor), data);
        drop(own);
        let other: Vec<f32> = (0..32).map(value).collect();
        assert_eq!(written(&floor), other);
        ctx.check_error("the fetch floor").unwrap();
    }

    /// A draw that walked the cells: its floor walks the same cells of the same sorted keys
    /// and fetches each neighbour's position once. Four entries in cells 0, 0, 1 and one with
    /// a +inf key in a lattice of 2 cells along x: entry 0 visits 1 and 2, entry 2 visits 0
    /// and 1, the last nothing; revealed, each fragment's sum is its own position and its
    /// neighbours'.
    #[test]
    fn the_walking_floor_visits_the_same_neighbours() {
        let ctx = Context::new(0).unwrap();
        // Per entry (key, id, 0, 0): keys 0, 0, 1, +inf.
        let inf = f32::INFINITY;
        let k = [
            0., 0., 0., 0., 0., 1., 0., 0., 1., 2., 0., 0., inf, 3., 0., 0.,
        ];
        let keys = rgba(&ctx, "keys", [4, 1], &k);
        let pos: Vec<f32> = (0..16).map(|i| (1u32 << (i / 4)) as f32).collect();
        let position = rgba(&ctx, "position", [4, 1], &pos);
        let shape = DrawShape {
            defines: vec![("EXACT_SCAN".into(), "8".into())],
            ints: vec![
                ("u_key_width".into(), vec![4]),
                ("u_count".into(), vec![4]),
                ("u_dims".into(), vec![2, 1, 1]),
            ],
            ..reading([4, 1], &[("u_keys", &keys), ("u_position", &position)])
        };
        let floor = FetchFloor::new(&ctx).unwrap();
        floor.reveal.set(true);
        let timer = PassTimer::new(&ctx, Clock::Wall).unwrap();
        floor.measure(&timer, std::slice::from_ref(&shape)).unwrap();
        let targets = floor.targets.borrow();
        let got = targets[&(shape.size, shape.formats.clone())]
            .only_texture()
            .read_f32()
            .unwrap();
        // Positions 1, 2, 4, 8 (one value in every channel, live: w > 0), read once at the own
        // texel; the keys only by the walk. The dead entry (+inf key) walks nothing.
        let own = [1.0, 2.0, 4.0, 8.0];
        let walked = [2.0 + 4.0, 1.0 + 4.0, 1.0 + 2.0, 0.0];
        for e in 0..4 {
            assert_eq!(
                got[e * 4],
                own[e] + walked[e],
                "entry {e}: {:?}",
                &got[e * 4..e * 4 + 4]
            );
        }
        ctx.check_error("the walking floor").unwrap();
    }
}
