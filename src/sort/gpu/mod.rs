//! The GPU sorter: every pass a draw into ping-pong framebuffers.

mod blocked;
mod counts;
mod geometry;
mod keys;
mod options;
mod output;
mod pass_list;
mod rearrange;
mod run;

use std::cell::{Cell, RefCell};
use std::collections::HashMap;

use super::network::{Entry, Step};
use super::precision::id_table;
use super::schedule::NetworkPass;
use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, PingPong, Program, Texture, TextureDesc,
    TextureFormat, FULLSCREEN_VERTEX,
};
use blocked::Blocked;
pub use blocked::{row_cell_entry, row_cells_fit, Quantiser};
use geometry::{Geometry, GpProgram};
pub use options::{BlockedShape, KeyMode, SortOptions, Variant};
pub use rearrange::LookupBindings;

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
    /// The key pass: lattice cells, viewer distance, age or position along an axis, written
    /// fresh or refreshed in place.
    Keys {
        grid: bool,
        age: bool,
        axis: bool,
        rekey: bool,
    },
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
    /// The pass indices of one spread cycle, in order ([`crate::sort::spread::cycle`]).
    cycle: Vec<usize>,
    programs: HashMap<ProgramKey, Program>,
    geometry: Vec<Geometry>,
    fullscreen: FullscreenPass,
    id_table: Option<Texture>,
    /// The gather's programs by (targets, reading the blocked layout, read through another sort).
    rearrange: RefCell<HashMap<rearrange::GatherKey, Program>>,
    blocked: Option<Blocked>,
    /// The blocked sort runs no unpack: its entries stay in its layout ([`SortOptions::keep_blocked`]).
    in_place: bool,
    /// Whether the row-major texture holds what the sorter holds now (false after a sort that
    /// left its entries in the blocked layout, until something asks for them row-major).
    row_major: Cell<bool>,
}

/// Checks a sorter's size and options against each other; returns the entries per sorted
/// block (the whole texture, or `rows` rows of it).
fn check_options(variant: Variant, width: u32, height: u32, options: &SortOptions) -> Result<u32> {
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
    if options.row_cells(variant, width) {
        let shape = options.blocked_shape(variant, width);
        blocked::check_compact(shape, block.trailing_zeros())?;
    } else if variant == Variant::Blocked && options.blocked.compact {
        blocked::check_compact(options.blocked, (width * height).trailing_zeros())?;
    }
    if options.passes_per_frame == Some(0) {
        return bad("passes per frame must be at least 1".into());
    }
    Ok(block)
}

/// The identifier table of emulated precision, when the options ask for one.
fn id_table_texture(
    ctx: &Context,
    width: u32,
    height: u32,
    options: &SortOptions,
) -> Result<Option<Texture>> {
    if !options.id_table {
        return Ok(None);
    }
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
    Ok(Some(tex))
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
        let block = check_options(variant, width, height, &options)?;
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
            cycle: Vec::new(),
            programs: HashMap::new(),
            geometry: Vec::new(),
            fullscreen: FullscreenPass::new(ctx)?,
            id_table: None,
            rearrange: RefCell::new(HashMap::new()),
            blocked: None,
            in_place: false,
            row_major: Cell::new(true),
        };
        sorter.build(block)?;
        let steps: Vec<_> = (sorter.passes.iter())
            .filter_map(|p| match p {
                Pass::Fragment(s) => Some(*s),
                Pass::Geometry { .. } | Pass::Group(_) | Pass::Blocked(_) | Pass::Unpack => None,
            })
            .collect();
        sorter.cycle = match options.spread {
            crate::sort::spread::Spread::Even => (0..sorter.passes.len()).collect(),
            spread => crate::sort::spread::cycle(&steps, spread)
                .filter(|_| steps.len() == sorter.passes.len())
                .ok_or_else(|| {
                    Error::InvalidInput(
                        "the local spread re-runs the odd-even merge sort's first stages: use \
                         variant = \"oddeven\""
                            .into(),
                    )
                })?,
        };
        sorter.id_table = id_table_texture(ctx, width, height, &options)?;
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
        let network =
            super::schedule::network(self.variant, self.width, self.height, block, &self.options);
        match self.variant {
            Variant::Fp => {
                self.program(
                    ProgramKey::Fp,
                    FULLSCREEN_VERTEX,
                    "sort/bitonic_fp.frag",
                    &[],
                )?;
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
            }
            Variant::Multistep => {
                for p in &network {
                    if let NetworkPass::Group(g) = p {
                        let (levels, steps) = group_shape(g);
                        let (l, s) = (levels.to_string(), steps.to_string());
                        self.program(
                            ProgramKey::Multistep { levels, steps },
                            FULLSCREEN_VERTEX,
                            "sort/multistep.frag",
                            &[("LEVELS", &l), ("STEPS", &s)],
                        )?;
                    }
                }
            }
            Variant::Blocked => {
                let passes: Vec<_> = network
                    .iter()
                    .filter_map(|p| match p {
                        NetworkPass::Blocked(b) => Some(b.clone()),
                        NetworkPass::Step(_) | NetworkPass::Group(_) | NetworkPass::Unpack => None,
                    })
                    .collect();
                self.blocked = if passes.is_empty() {
                    None
                } else {
                    let o = &self.options;
                    let shape = o.blocked_shape(self.variant, self.width);
                    let row_cells =
                        (o.row_cells(self.variant, self.width)).then(|| block.trailing_zeros());
                    let size = [self.width, self.height];
                    Some(Blocked::new(&self.ctx, size, shape, passes, row_cells)?)
                };
            }
            Variant::GpFp | Variant::Packed => return self.build_geometry(&network),
        }
        let mut blocked_index = 0..;
        self.passes = network
            .into_iter()
            .map(|p| match p {
                NetworkPass::Step(step) => Pass::Fragment(step),
                NetworkPass::Group(g) => Pass::Group(g),
                NetworkPass::Blocked(_) => Pass::Blocked(blocked_index.next().unwrap_or(0)),
                NetworkPass::Unpack => Pass::Unpack,
            })
            .collect();
        self.in_place = self.options.keep_blocked
            && (self.blocked.as_ref()).is_some_and(|b| b.gathers_in_place());
        if self.in_place {
            self.passes.retain(|p| !matches!(p, Pass::Unpack));
        }
        Ok(())
    }

    /// The GP/FP and packed variants' programs and passes: one quad geometry per distinct
    /// shape of a bitonic step, uploaded once and shared by the steps of that shape.
    fn build_geometry(&mut self, network: &[NetworkPass]) -> Result<()> {
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
        for step in network.iter().filter_map(|p| match p {
            NetworkPass::Step(step) => Some(*step),
            NetworkPass::Group(_) | NetworkPass::Blocked(_) | NetworkPass::Unpack => None,
        }) {
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

    /// The blocked network's shape as run ([`SortOptions::blocked_shape`]).
    pub fn blocked_shape(&self) -> BlockedShape {
        self.options.blocked_shape(self.variant, self.width)
    }

    /// Whether the blocked sort takes rows-only compact exact entries
    /// ([`SortOptions::row_cells`]).
    pub fn row_cells(&self) -> bool {
        self.options.row_cells(self.variant, self.width)
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
        if self.row_cells() {
            self.check_row_cells(entries)?;
        }
        let flat: Vec<f32> = if self.variant.packed() {
            entries.iter().flatten().copied().collect()
        } else {
            entries.iter().flat_map(|e| [e[0], e[1]]).collect()
        };
        self.state.front().only_texture().upload_f32(&flat)?;
        self.row_major.set(true);
        self.next = 0;
        Ok(())
    }

    /// Entries that rows-only compact exact entries hold as they are: whole keys below the
    /// options' cell count, ±inf or the key pass's NaN, each with its own index as identifier.
    fn check_row_cells(&self, entries: &[Entry]) -> Result<()> {
        let cells = self.options.cell_keys.unwrap_or(0);
        for (i, &[k, id]) in entries.iter().enumerate() {
            let whole = k.to_bits() >> 31 == 0 && k.fract() == 0.0 && (k as u64) < cells;
            let special = k.is_infinite() || k.to_bits() == 0x7fc0_0000;
            if !(whole || special) || id != i as f32 {
                return Err(Error::InvalidInput(format!(
                    "entry {i} ({k}, {id}) for a rows-only sort of cell keys: keys are whole \
                     cells below {cells}, ±inf or NaN (0x7fc00000), ids the entries' indices; \
                     sort other entries without SortOptions::cell_keys"
                )));
            }
        }
        Ok(())
    }

    /// One frame's share of the sort: `passes_per_frame` passes (continuing the sequence, and
    /// starting it again after its last pass), or the whole sort without that option.
    pub fn sort_frame(&mut self) -> usize {
        match self.options.passes_per_frame {
            Some(n) => {
                if self.next == self.cycle.len() {
                    self.next = 0;
                }
                self.run_passes(n)
            }
            None => {
                self.next = 0;
                self.run_passes(self.cycle.len())
            }
        }
    }

    /// Runs every remaining pass of the sequence.
    pub fn sort(&mut self) {
        self.run_passes(self.cycle.len());
    }

    /// Passes of one spread cycle: [`pass_count`](Self::pass_count), plus the stages the
    /// `local` spread re-runs.
    pub fn cycle_len(&self) -> usize {
        self.cycle.len()
    }

    /// Runs up to `n` further passes (Latta: a full sort spread over frames); returns how many
    /// ran. After the last pass the sequence starts again from the first.
    pub fn run_passes(&mut self, n: usize) -> usize {
        let mut done = 0;
        while done < n && self.next < self.cycle.len() {
            self.run_pass(self.cycle[self.next]);
            self.next += 1;
            done += 1;
        }
        if self.next == self.cycle.len() && done < n {
            self.next = 0;
        }
        done
    }

    /// Starts the pass sequence again without touching the entries.
    pub fn restart(&mut self) {
        self.next = 0;
    }
}
