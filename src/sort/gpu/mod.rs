//! The GPU sorter: every pass a draw into ping-pong framebuffers.

mod blocked;
mod geometry;
mod keys;
mod options;
mod rearrange;

use std::cell::RefCell;
use std::collections::HashMap;

use super::network::{bitonic_schedule, group_steps, odd_even_schedule, Entry, Step};
use super::precision::id_table;
use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Draw, DrawState, Framebuffer, FullscreenPass, PingPong, Primitive, Program,
    Sampled, Texture, TextureDesc, TextureFormat, FULLSCREEN_VERTEX,
};
use blocked::Blocked;
pub use blocked::Quantiser;
use geometry::{Geometry, GpProgram};
pub use options::{BlockedShape, KeyMode, SortOptions, Variant};

/// One pass of the sorter.
#[derive(Debug)]
enum Pass {
    Fragment(Step),
    Geometry {
        geometry: usize,
        offset: (i32, i32),
        program: GpProgram,
    },
    Group(Vec<Step>),
    /// Pass `i` of the blocked network.
    Blocked(usize),
    /// The blocked network's last pass: back to the row-major texture.
    Unpack,
}

/// The sorter's programs, one per key, built once each.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum ProgramKey {
    /// UberFlow's FP bitonic pass.
    Fp,
    /// Latta's odd-even merge: a recursion pass.
    OddEvenRecursion,
    /// Latta's odd-even merge: the last pass of a merge.
    OddEvenEnd,
    /// A multistep pass over `levels` wide masks and `steps` steps.
    Multistep { levels: usize, steps: usize },
    /// A GP/FP pass.
    Geometry(GpProgram),
    /// The key pass: lattice cells, viewer distance or age, written fresh or refreshed in place.
    Keys { grid: bool, age: bool, rekey: bool },
}

/// (wide masks, steps) of a multistep pass: the texels it fetches are 2^wide.
fn group_shape(steps: &[Step]) -> (usize, usize) {
    let wide = steps
        .iter()
        .filter(|s| s.mask().is_some_and(|m| m >= 2))
        .count();
    (wide, steps.len())
}

/// Sorts (key, id) entries in a texture with one of the [`Variant`]s.
#[derive(Debug)]
pub struct Sorter {
    ctx: Context,
    variant: Variant,
    width: u32,
    height: u32,
    options: SortOptions,
    state: PingPong,
    passes: Vec<Pass>,
    next: usize,
    programs: HashMap<ProgramKey, Program>,
    geometry: Vec<Geometry>,
    fullscreen: FullscreenPass,
    id_table: Option<Texture>,
    rearrange: RefCell<HashMap<usize, Program>>,
    blocked: Option<Blocked>,
}

impl Sorter {
    /// A sorter of `width`×`height` entries (powers of two; width ≥ 2 for the packed variant).
    pub fn new(
        ctx: &Context,
        variant: Variant,
        width: u32,
        height: u32,
        options: SortOptions,
    ) -> Result<Self> {
        let bad = |m: String| Err(Error::InvalidInput(m));
        if !width.is_power_of_two() || !height.is_power_of_two() {
            return bad(format!(
                "sort texture {width}x{height}: both sides must be powers of two"
            ));
        }
        if variant.packed() && width < 2 {
            return bad("the packed variant needs rows of at least 2 entries".into());
        }
        let block = match options.rows {
            None => width * height,
            Some(k) if k.is_power_of_two() && k <= height => width * k,
            Some(k) => {
                return bad(format!(
                    "rows-only sort over {k} rows: use a power of two up to the height {height}"
                ))
            }
        };
        if options.id_table && options.precision.is_none() {
            return bad("the identifier table is for emulated precision only".into());
        }
        if !(1..=3).contains(&options.steps_per_pass) {
            return bad("steps per pass must be 1, 2 or 3".into());
        }
        if variant == Variant::Blocked
            && (options.precision.is_some() || options.passes_per_frame.is_some())
        {
            return bad(
                "the blocked sort runs whole sorts in fp32: no emulated precision and no sort \
                 spread over frames (its layout changes from pass to pass)"
                    .into(),
            );
        }
        if variant == Variant::Blocked && options.blocked.compact {
            blocked::check_compact(options.blocked, (width * height).trailing_zeros())?;
        }
        if options.passes_per_frame == Some(0) {
            return bad("passes per frame must be at least 1".into());
        }
        let (tw, format) = if variant.packed() {
            (width / 2, TextureFormat::Rgba32F)
        } else {
            (width, TextureFormat::Rg32F)
        };
        crate::gl::check_size(ctx, "sort texture", tw, height)?;
        let state = PingPong::new(ctx, "sort", &["keys"], &[format], tw, height)?;
        let mut sorter = Sorter {
            ctx: ctx.clone(),
            variant,
            width,
            height,
            options,
            state,
            passes: Vec::new(),
            next: 0,
            programs: HashMap::new(),
            geometry: Vec::new(),
            fullscreen: FullscreenPass::new(ctx)?,
            id_table: None,
            rearrange: RefCell::new(HashMap::new()),
            blocked: None,
        };
        sorter.build(block)?;
        if options.id_table {
            let f = options.precision.unwrap_or(super::precision::R300);
            let values = id_table((width * height) as usize, &f);
            let tex = Texture::new(
                ctx,
                TextureDesc {
                    width,
                    height,
                    format: TextureFormat::R32F,
                    label: "id table",
                },
            )?;
            tex.upload_f32(&values)?;
            sorter.id_table = Some(tex);
        }
        ctx.check_error("building the sorter")?;
        Ok(sorter)
    }

    fn defines(&self) -> Defines {
        let mut d = Defines::new();
        if let Some(f) = self.options.precision {
            d.extend(f.defines());
        }
        d
    }

    fn program(
        &mut self,
        key: ProgramKey,
        vertex: &str,
        fragment: &str,
        extra: &[(&str, &str)],
    ) -> Result<()> {
        if self.programs.contains_key(&key) {
            return Ok(());
        }
        let mut d = self.defines();
        d.extend(extra.iter().map(|(k, v)| (k.to_string(), v.to_string())));
        let p = Program::new(&self.ctx, vertex, fragment, &d)?;
        self.programs.insert(key, p);
        Ok(())
    }

    fn build(&mut self, block: u32) -> Result<()> {
        let w = self.width;
        match self.variant {
            Variant::Fp => {
                self.program(
                    ProgramKey::Fp,
                    FULLSCREEN_VERTEX,
                    "sort/bitonic_fp.frag",
                    &[],
                )?;
                self.passes = bitonic_schedule(w, block)
                    .into_iter()
                    .map(Pass::Fragment)
                    .collect();
            }
            Variant::OddEven => {
                self.program(
                    ProgramKey::OddEvenRecursion,
                    FULLSCREEN_VERTEX,
                    "sort/oddeven_recursion.frag",
                    &[],
                )?;
                self.program(
                    ProgramKey::OddEvenEnd,
                    FULLSCREEN_VERTEX,
                    "sort/oddeven_end.frag",
                    &[],
                )?;
                self.passes = odd_even_schedule(block)
                    .into_iter()
                    .map(Pass::Fragment)
                    .collect();
            }
            Variant::Multistep => {
                let groups = group_steps(&bitonic_schedule(w, block), self.options.steps_per_pass);
                for g in &groups {
                    let (levels, steps) = group_shape(g);
                    let (l, s) = (levels.to_string(), steps.to_string());
                    self.program(
                        ProgramKey::Multistep { levels, steps },
                        FULLSCREEN_VERTEX,
                        "sort/multistep.frag",
                        &[("LEVELS", &l), ("STEPS", &s)],
                    )?;
                }
                self.passes = groups.into_iter().map(Pass::Group).collect();
            }
            Variant::Blocked => {
                self.passes.clear();
                if self.width * self.height > 1 {
                    let b = Blocked::new(&self.ctx, w, self.height, block, self.options.blocked)?;
                    self.passes = (0..b.network_passes()).map(Pass::Blocked).collect();
                    self.passes.push(Pass::Unpack);
                    self.blocked = Some(b);
                }
            }
            Variant::GpFp | Variant::Packed => {
                let frag = if self.variant.packed() {
                    "sort/bitonic_packed.frag"
                } else {
                    "sort/bitonic_gpfp.frag"
                };
                let gp = ProgramKey::Geometry;
                self.program(gp(GpProgram::Plain), "sort/gpfp.vert", frag, &[])?;
                let mirror = [("MIRROR", "1")];
                self.program(gp(GpProgram::Mirror), "sort/gpfp.vert", frag, &mirror)?;
                if self.variant.packed() {
                    let same = [("SAME_TEXEL", "1")];
                    self.program(gp(GpProgram::SameTexel), "sort/gpfp.vert", frag, &same)?;
                }
                let mut shapes: HashMap<(u8, u32, u32), usize> = HashMap::new();
                let mut passes = Vec::new();
                for step in bitonic_schedule(w, block) {
                    let shape = self.quads(&step);
                    let geometry = match shapes.get(&shape.key) {
                        Some(&g) => g,
                        None => {
                            let g = self.upload_geometry(&shape.vertices)?;
                            shapes.insert(shape.key, g);
                            g
                        }
                    };
                    passes.push(Pass::Geometry {
                        geometry,
                        offset: shape.offset,
                        program: shape.program,
                    });
                }
                self.passes = passes;
            }
        }
        Ok(())
    }
    /// The variant.
    pub fn variant(&self) -> Variant {
        self.variant
    }
    /// Entries per row.
    pub fn width(&self) -> u32 {
        self.width
    }
    /// Rows.
    pub fn height(&self) -> u32 {
        self.height
    }
    /// Number of entries.
    pub fn len(&self) -> usize {
        (self.width * self.height) as usize
    }
    /// Whether the sorter holds no entries (never: sizes are at least 1×1).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// The passes of one full sort (the key pass and the rearrangement not counted).
    pub fn pass_count(&self) -> usize {
        self.passes.len()
    }
    /// Passes already run in the current sequence (see [`Sorter::run_passes`]).
    pub fn passes_done(&self) -> usize {
        self.next
    }
    /// The texture holding the entries now (RG32F, or RGBA32F packed).
    pub fn keys(&self) -> &Texture {
        self.state.front().only_texture()
    }
    /// The framebuffer the next pass writes (for floors in benchmarks): for the blocked
    /// variant, the layers its network passes write.
    pub fn target(&self) -> &Framebuffer {
        match &self.blocked {
            Some(b) => b.target(),
            None => self.state.back(),
        }
    }
    /// The framebuffer the key pass writes next (the row-major sort texture), for floors.
    pub fn keys_target(&self) -> &Framebuffer {
        self.state.back()
    }

    /// The passes of one full sort that are network passes (all but the blocked variant's
    /// unpack pass).
    pub fn network_pass_count(&self) -> usize {
        self.passes
            .iter()
            .filter(|p| !matches!(p, Pass::Unpack))
            .count()
    }

    /// Texel fetches of one run of the network (every pass once), counted from what each pass's
    /// fragment program fetches: for the cost model (`texflow report cost`).
    pub fn network_fetches(&self) -> u64 {
        let n = self.len() as u64;
        self.passes
            .iter()
            .map(|p| match p {
                Pass::Fragment(_) => 2 * n,
                Pass::Group(steps) => (n / 2) << group_shape(steps).0,
                Pass::Geometry { .. } if self.variant.packed() => n,
                Pass::Geometry { .. } => 2 * n,
                Pass::Blocked(_) if self.options.blocked.pinned => n / 2,
                Pass::Blocked(_) | Pass::Unpack => n,
            })
            .sum()
    }

    /// The options.
    pub fn options(&self) -> &SortOptions {
        &self.options
    }

    /// The range of keys that the blocked sort's compact entries spread over their levels
    /// (keys outside it take the end levels): set it before sorting, e.g. from the distances
    /// of the scene's bounds to the eye. An error for any other sort.
    pub fn set_key_range(&mut self, lo: f32, hi: f32) -> Result<()> {
        match &mut self.blocked {
            Some(b) => b.set_key_range(lo, hi),
            None => Err(Error::InvalidInput(
                "a key range is for the compact blocked sort only".into(),
            )),
        }
    }

    /// How the compact blocked sort quantises keys (`None` for exact entries).
    pub fn quantiser(&self) -> Option<blocked::Quantiser> {
        self.blocked.as_ref().and_then(|b| b.quantiser())
    }

    /// Uploads entries (row-major, `len()` of them) and restarts the pass sequence. For the CLI and
    /// tests; in the pipeline the key pass writes the entries.
    pub fn load(&mut self, entries: &[Entry]) -> Result<()> {
        if entries.len() != self.len() {
            return Err(Error::InvalidInput(format!(
                "{} entries for a {}x{} sorter",
                entries.len(),
                self.width,
                self.height
            )));
        }
        let flat: Vec<f32> = if self.variant.packed() {
            entries.iter().flatten().copied().collect()
        } else {
            entries.iter().flat_map(|e| [e[0], e[1]]).collect()
        };
        self.state.front().only_texture().upload_f32(&flat)?;
        self.next = 0;
        Ok(())
    }

    /// Reads the entries back, unpacked, row-major.
    pub fn read(&self) -> Result<Vec<Entry>> {
        // RG32F texels are entries; packed RGBA32F texels are two consecutive entries.
        let raw = self.keys().read_f32()?;
        Ok(raw.chunks_exact(2).map(|c| [c[0], c[1]]).collect())
    }

    /// One frame's share of the sort: `passes_per_frame` passes (continuing the sequence, and
    /// starting it again after its last pass), or the whole sort without that option.
    pub fn sort_frame(&mut self) -> usize {
        match self.options.passes_per_frame {
            Some(n) => {
                if self.next == self.passes.len() {
                    self.next = 0;
                }
                self.run_passes(n)
            }
            None => {
                self.next = 0;
                self.run_passes(self.passes.len())
            }
        }
    }

    /// Runs every remaining pass of the sequence.
    pub fn sort(&mut self) {
        self.run_passes(self.passes.len());
    }

    /// Runs up to `n` further passes (Latta: a full sort spread over frames); returns how many
    /// ran. After the last pass the sequence starts again from the first.
    pub fn run_passes(&mut self, n: usize) -> usize {
        let mut done = 0;
        while done < n && self.next < self.passes.len() {
            self.run_pass(self.next);
            self.next += 1;
            done += 1;
        }
        if self.next == self.passes.len() && done < n {
            self.next = 0;
        }
        done
    }

    /// Starts the pass sequence again without touching the entries.
    pub fn restart(&mut self) {
        self.next = 0;
    }

    fn run_pass(&mut self, index: usize) {
        if let (Some(b), Pass::Blocked(i)) = (self.blocked.as_mut(), &self.passes[index]) {
            b.run(*i, self.state.front().only_texture(), &self.fullscreen);
            return;
        }
        let w = self.width as i32;
        let front = self.state.front().only_texture();
        let keys = [("u_keys", Sampled::from(front))];
        match &self.passes[index] {
            Pass::Fragment(step) => {
                let p = match step {
                    Step::Bitonic {
                        block,
                        dist,
                        mirror,
                    } => {
                        let p = &self.programs[&ProgramKey::Fp];
                        p.bind();
                        p.set_i32("u_block", *block as i32);
                        p.set_i32("u_dist", *dist as i32);
                        p.set_i32("u_mirror", *mirror as i32);
                        p
                    }
                    Step::OddEvenRecursion { step, count } => {
                        let p = &self.programs[&ProgramKey::OddEvenRecursion];
                        p.bind();
                        p.set_i32("u_step", *step as i32);
                        p.set_i32("u_count", *count as i32);
                        p
                    }
                    Step::OddEvenEnd { step } => {
                        let p = &self.programs[&ProgramKey::OddEvenEnd];
                        p.bind();
                        p.set_i32("u_step", *step as i32);
                        p
                    }
                };
                p.textures(&keys);
                p.set_i32("u_width", w);
                self.fullscreen.draw(p, self.state.back());
            }
            Pass::Group(steps) => {
                let (levels, steps_n) = group_shape(steps);
                let p = &self.programs[&ProgramKey::Multistep {
                    levels,
                    steps: steps_n,
                }];
                p.bind();
                p.textures(&keys);
                p.set_i32("u_width", w);
                if let Step::Bitonic { block, .. } = steps[0] {
                    p.set_i32("u_block", block as i32);
                }
                // Wide masks in order are the basis of the sub-network (see multistep.frag).
                let wide = steps.iter().filter_map(Step::mask).filter(|&m| m >= 2);
                for (b, mask) in wide.enumerate() {
                    p.set_i32(&format!("u_basis[{b}]"), mask as i32);
                }
                for (s, step) in steps.iter().enumerate() {
                    let mirror = matches!(step, Step::Bitonic { mirror: true, .. });
                    p.set_i32(&format!("u_mirror[{s}]"), mirror as i32);
                }
                self.fullscreen.draw(p, self.state.back());
            }
            Pass::Blocked(_) => unreachable!("blocked passes return above"),
            Pass::Unpack => {
                if let Some(b) = &self.blocked {
                    b.unpack(self.state.back(), &self.fullscreen);
                }
            }
            Pass::Geometry {
                geometry,
                offset,
                program,
            } => {
                let p = &self.programs[&ProgramKey::Geometry(*program)];
                p.bind();
                p.textures(&keys);
                let fb = self.state.back();
                p.set_vec2(
                    "u_size",
                    glam::Vec2::new(fb.width() as f32, fb.height() as f32),
                );
                p.set_ivec2("u_offset", offset.0, offset.1);
                let g = &self.geometry[*geometry];
                self.ctx.draw(&Draw {
                    program: p,
                    target: fb,
                    viewport: None,
                    vertices: &g.vao,
                    primitive: Primitive::Triangles,
                    count: g.vertices,
                    state: &DrawState::REPLACE,
                });
            }
        }
        self.state.swap();
    }
}
