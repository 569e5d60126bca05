//! The lattice of a cell sort ([`Lattice`]) and the exact neighbour search over the sorted state
//! (`glsl/collide/cells.glsl`, [`CellSearch`]), one owner for the collision stage's exact
//! detection, its neighbour forces and exchanges, and the fluid: the lattice searched, the
//! uniforms and textures every searching pass takes, and the cell-start table (as `cellStart`
//! in NVIDIA's CUDA `particles` sample, here a fragment pass).
//!
//! After each sort and gather that a search reads, two full-screen passes write, for every cell
//! c of the lattice, the first sorted index whose key is not below c, and the live particles'
//! count after the last cell: one search per cell instead of one per row of cells, particle and
//! searching pass. The first (`glsl/collide/cell_block.frag`) finds the start of every block of
//! [`TABLE_BLOCK`] cells by a binary search of all the keys, the second
//! (`glsl/collide/cell_start.frag`) each cell's between its block's and the next's. The search
//! then reads the bounds of each run of cells from the table (two fetches a run). Keys are whole
//! cell indices (or +inf for the dead), so the run it walks is the one the binary search finds:
//! the same neighbours in the same order, every output bit for bit the same.
//!
//! A large fluid's lattice has cells of h, and its search (`SEARCH_TRIM`) walks only the cells
//! within 2h of each particle (about 22 runs, each cut to the cells within 2h along x: 84 cells
//! of h³, 0.39 of the 27 cells of 2h); a small fluid's (cells of 2h) and the collisions' exact
//! detection walk the 27 cells around a particle's cell ([`Walk`]), but where the exact
//! detection's cell is below 2 radius: there it walks the cells within 2 radius, trimmed as the
//! fluid's (on cells of one radius, about 84 cells of r³ instead of 27 of (2r)³: 0.39 of the
//! volume, so of the particles visited).
//!
//! The table costs a few fetches per cell: it pays while the cells are not many more than the
//! particles. A lattice of more cells per entry than its walk allows
//! ([`Walk::table_cells_per_entry`]: 8 for the collisions' 27 cells, 32 for the fluid's), or of
//! more than [`TABLE_MAX_CELLS`], keeps the binary search of every run instead; the pass list
//! says which search runs.

use glam::{UVec3, Vec3};

use crate::error::Result;
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, PassDraw, Program, Sampled, Texture,
    TextureDesc, TextureFormat, Uniform, FULLSCREEN_VERTEX,
};
use crate::scene::{self, SceneFile};
use crate::sort::KeyMode;

/// A lattice: corner of cell (0, 0, 0), mesh size, cells per axis, and how a search walks it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// Corner of cell (0, 0, 0).
    pub origin: Vec3,
    /// Mesh size g0.
    pub spacing: f32,
    /// Cells per axis.
    pub dims: UVec3,
    /// How the neighbour search walks it.
    pub walk: Walk,
}

/// How a neighbour search walks the sorted cells (`glsl/collide/cells.glsl`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Walk {
    /// The collisions' search: the 27 cells around a particle's, 9 runs of three cells along x.
    #[default]
    Cells27,
    /// The fluid's search, in at least two passes a step (density, force).
    Fluid {
        /// On a lattice of cell h: the cells that can hold a particle within the pass's radius
        /// of the particle (`SEARCH_TRIM`): rows farther in y and z skipped, each other row along
        /// x cut to x ± sqrt(radius² − d²) (d its distance across y and z), about 22 runs and 84
        /// cells for a radius of 2h. Else (cells of 2h) the
        /// 27 cells, as the collisions (trimming them ran 6-8 % slower on NVIDIA H100 and H200
        /// for the 8,192-particle `drop`, and saved nothing at a million particles).
        trimmed: bool,
    },
    /// The collisions' exact search on a cell below 2 radius: the cells that can hold a
    /// partner closer than 2 radius (`SEARCH_TRIM`, as the fluid's trimmed walk), about 22 runs
    /// and 84 cells on a cell of one radius. The DEM force and pair forces (whose reach is at
    /// most the cell) walk it with a reach of 2 radius too, an exchange with its own radius.
    Trimmed,
}

impl Walk {
    /// Most cells per sorted entry for which a search of this walk builds the cell-start table
    /// ([`uses_table`]). The table's passes fetch about 3 keys per cell (and log2(entries) per
    /// 32 cells); a search without it fetches log2(entries) keys per run and entry in each
    /// searching pass: 9 runs for the 27 cells, about 22 for the trimmed walk, in at least two
    /// passes for the fluid. (On llvmpipe a table of 24 cells per entry, `dem` at 64² with the
    /// 27 cells, made its collision stage 1.07 times slower; on an NVIDIA H100 the fluid at
    /// 512², 24 cells of h per entry, walked 1.5 times as long without the table as with cells
    /// of 2h and their table.) The collisions' trimmed walk runs about 22 runs in two passes (the
    /// partner count and the response) too: the fluid's rule.
    pub fn table_cells_per_entry(self) -> u64 {
        match self {
            Walk::Cells27 => 8,
            Walk::Fluid { .. } | Walk::Trimmed => 32,
        }
    }

    /// Whether it is a trimmed walk (`SEARCH_TRIM`): the fluid's on cells of h, or the
    /// collisions' on a cell below 2 radius.
    pub fn trims(self) -> bool {
        matches!(self, Walk::Fluid { trimmed: true } | Walk::Trimmed)
    }
}

impl Lattice {
    /// The lattice of a scene's `[collisions]`, or its staggered twin (shifted by g0/2, one cell
    /// more per axis). The exact detection on a cell below 2 radius walks it trimmed.
    pub fn of(c: &scene::Collisions, staggered: bool) -> Self {
        let g = c.cell();
        let walk = if c.detection == scene::Detection::Exact && c.trims() {
            Walk::Trimmed
        } else {
            Walk::Cells27
        };
        let lo = Vec3::from(c.bounds[0]);
        let hi = Vec3::from(c.bounds[1]);
        let dims = ((hi - lo) / g).ceil().max(Vec3::ONE).as_uvec3();
        if staggered {
            Lattice {
                origin: lo - Vec3::splat(0.5 * g),
                spacing: g,
                dims: dims + UVec3::ONE,
                walk,
            }
        } else {
            Lattice {
                origin: lo,
                spacing: g,
                dims,
                walk,
            }
        }
    }

    /// The lattice of the scene's `[fluid]` (a scene without one has none: a lattice of one
    /// cell), from the lower corner of its bounds: cell h, searched by the trimmed walk
    /// (`SEARCH_TRIM` in `glsl/collide/cells.glsl`: the cells within 2h of a particle, about
    /// 84 h³), or 2h, searched in the 27 cells (216 h³), as `fluid.cell` says.
    pub fn of_fluid(scene: &SceneFile) -> Self {
        let Some(f) = &scene.fluid else {
            return Lattice {
                origin: Vec3::ZERO,
                spacing: 1.0,
                dims: UVec3::ONE,
                walk: Walk::Fluid { trimmed: false },
            };
        };
        let n = scene::fluid_particles(scene);
        let (fine, g) = (f.fine_cell(n), f.cell_size(n));
        Lattice {
            origin: Vec3::from(f.bounds[0]),
            spacing: g,
            dims: UVec3::from(f.lattice_dims(g)),
            walk: Walk::Fluid { trimmed: fine },
        }
    }

    /// The cell of `p`, clamped to the lattice (as the key pass does).
    pub fn cell(&self, p: Vec3) -> UVec3 {
        let c = ((p - self.origin) / self.spacing).floor();
        let max = (self.dims - UVec3::ONE).as_vec3();
        c.clamp(Vec3::ZERO, max).as_uvec3()
    }

    /// Cells in the lattice.
    pub fn cells(&self) -> u64 {
        self.dims.x as u64 * self.dims.y as u64 * self.dims.z as u64
    }

    /// The key of a cell, enumerated z, y, x.
    pub fn key(&self, c: UVec3) -> u64 {
        (c.z as u64 * self.dims.y as u64 + c.y as u64) * self.dims.x as u64 + c.x as u64
    }

    /// Whether a search of it over `entries` sorted entries reads a cell-start table
    /// ([`uses_table`]).
    pub fn uses_table(&self, entries: u64) -> bool {
        uses_table(self.cells(), entries, self.walk)
    }

    pub(super) fn mode(&self) -> KeyMode {
        KeyMode::GridCell {
            origin: self.origin,
            spacing: self.spacing,
            dims: self.dims,
        }
    }
}

/// Cells per row of the table (a power of two: the search finds a cell's texel by a mask and a
/// shift, `TABLE_WIDTH_SHIFT`). A table of fewer cells is one row of its own width.
pub const TABLE_WIDTH: u32 = 2048;

/// Most cells a lattice has for the table: with the sentinel, at most 4096 rows of
/// [`TABLE_WIDTH`] texels (32 MiB of R32F), no larger a side than the 4096² state textures
/// texflow runs (the million-particle dam's lattice of cell h has 6.3 million cells).
pub const TABLE_MAX_CELLS: u64 = (1 << 23) - 1;

thread_local! {
    // Set by `with_search` while it builds stages on this thread.
    static FORCED: std::cell::Cell<Option<bool>> = const { std::cell::Cell::new(None) };
}

/// Runs `build` with every search it builds on this thread (stages, their pass lists) reading
/// the table (`table`, for any lattice up to [`TABLE_MAX_CELLS`]) or the binary search, whatever
/// the rule of [`uses_table`] says: for comparing the two searches, which must give the same
/// state bit for bit.
pub fn with_search<T>(table: bool, build: impl FnOnce() -> T) -> T {
    scoped(&FORCED, table, build)
}

/// Runs `build` with `key` holding `value` on this thread, then puts back what it held.
fn scoped<T>(
    key: &'static std::thread::LocalKey<std::cell::Cell<Option<bool>>>,
    value: bool,
    build: impl FnOnce() -> T,
) -> T {
    let before = key.with(|f| f.replace(Some(value)));
    let out = build();
    key.with(|f| f.set(before));
    out
}

thread_local! {
    // Set by `with_partner_work` while it builds stages on this thread.
    static DEFERRED: std::cell::Cell<Option<bool>> = const { std::cell::Cell::new(None) };
}

/// The passes whose walk tests each visited particle and works on the partners it finds, for
/// [`partner_mask`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartnerWork {
    /// The exact detection's count: a partner's work (its static and velocity fetches, the
    /// separation, the exchange) is long beside a visit's test. Deferred by default: `gas`
    /// exact takes 0.61 of the time on llvmpipe and 0.76 on an NVIDIA H100, `spin` 0.43-0.59
    /// and 0.86-0.89.
    Contacts,
    /// The DEM and pair forces and the fluid's force: a partner's work is short, or most
    /// visits are partners. Worked as visited by default: deferred, they took 1.02-1.26 of
    /// the time on llvmpipe and 0.97-1.04 on an NVIDIA H100.
    Forces,
}

impl PartnerWork {
    /// Whether the pass defers its partners' work: [`PartnerWork::Contacts`] does, unless
    /// [`with_partner_work`] says otherwise for both.
    pub fn deferred(self) -> bool {
        DEFERRED
            .with(|f| f.get())
            .unwrap_or(self == PartnerWork::Contacts)
    }
}

/// `defines`, with `PARTNER_MASK` where `work` is [`deferred`](PartnerWork::deferred): the
/// walk of a run of cells tests 32 particles at a time, setting a bit per partner, and the work
/// then takes those partners in the same order (`glsl/collide/cells.glsl`), so the fragments of
/// a warp do a partner's work together rather than each visit waiting for whichever fragment
/// found one. Every sum is the same, term for term.
pub fn partner_mask(defines: &Defines, work: PartnerWork) -> Defines {
    let mut d = defines.clone();
    if work.deferred() {
        d.push(("PARTNER_MASK".into(), "1".into()));
    }
    d
}

/// The words the pass lists give a pass built with [`partner_mask`]: "", or how its walk takes
/// the partners.
pub fn partner_words(work: PartnerWork) -> &'static str {
    if work.deferred() {
        "; each run's partners worked after its tests, in order"
    } else {
        ""
    }
}

/// Runs `build` with every pass it builds on this thread working on each partner as it visits
/// it (`deferred` false) or by [`partner_mask`] (true), whatever [`PartnerWork::deferred`]
/// would say: for comparing the two, which must give the same state bit for bit.
pub fn with_partner_work<T>(deferred: bool, build: impl FnOnce() -> T) -> T {
    scoped(&DEFERRED, deferred, build)
}

/// Whether a search by `walk` of a lattice of `cells` cells over `entries` sorted entries reads
/// a cell-start table: cells ≤ [`Walk::table_cells_per_entry`] × entries and ≤
/// [`TABLE_MAX_CELLS`]; else the binary search.
pub fn uses_table(cells: u64, entries: u64, walk: Walk) -> bool {
    let rule = cells <= walk.table_cells_per_entry() * entries;
    cells <= TABLE_MAX_CELLS && FORCED.with(|f| f.get()).unwrap_or(rule)
}

/// Which searches of a scene read a cell-start table: the exact collision detection's (and its
/// neighbour forces' and exchanges'), and the fluid's. `false` where the scene has no such
/// search or its lattice is too large for the table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct CellTables {
    /// The exact collision detection's lattice.
    pub collisions: bool,
    /// The fluid's lattice (cell h or 2h).
    pub fluid: bool,
    /// Whether the exact collision search walks trimmed ([`Walk::Trimmed`], a cell below 2
    /// radius), table or not.
    pub collisions_trimmed: bool,
}

impl CellTables {
    /// The tables `scene` builds.
    pub fn of(scene: &SceneFile) -> Self {
        let [w, h] = scene.particles.size;
        let entries = w as u64 * h as u64;
        let table = |l: Lattice| l.uses_table(entries);
        CellTables {
            collisions: (scene.collisions.as_ref())
                .filter(|c| c.detection == scene::Detection::Exact)
                .is_some_and(|c| table(Lattice::of(c, false))),
            fluid: scene.fluid.is_some() && table(Lattice::of_fluid(scene)),
            collisions_trimmed: (scene.collisions.as_ref())
                .is_some_and(|c| Lattice::of(c, false).walk == Walk::Trimmed),
        }
    }
}

/// Where the exact collision search looks for the neighbours of a particle, for the pass lists:
/// the 27 cells around it, or the cells within `reach` ([`Walk::Trimmed`]).
pub fn walk_words(trimmed: bool, reach: &str) -> String {
    if trimmed {
        format!("the cells within {reach} of each particle (trimmed: the cell is below 2r)")
    } else {
        "the 27 cells around each particle".into()
    }
}

/// How the search finds each run of cells, for the pass lists.
pub fn search_words(table: bool) -> &'static str {
    if table {
        "run bounds read from the cell-start table, 2 fetches per run"
    } else {
        "binary search of the sorted keys per run (the lattice is too large for a cell-start \
         table)"
    }
}

/// The pass list's line of the table pass, after the gather of `what` (`"collision"`, `"fluid"`)
/// and `when` (`""`, or `", every iteration"`).
pub fn table_line(what: &str, when: &str) -> String {
    let prefix = if what == "fluid" { "fluid " } else { "" };
    format!(
        "{prefix}cell start: one texel per cell of the {what} lattice and a sentinel, the first \
         sorted index whose key is not below the cell's (two passes: that of one cell in \
         {TABLE_BLOCK} by a binary search of all the sorted keys, then each cell's between its \
         block's and the next's){when}"
    )
}

/// The simulation's `defines`, with `CELL_TABLE` (and the table's row width as
/// `TABLE_WIDTH_SHIFT`) where the search of `lattice` over a `size` state reads the table,
/// `SEARCH_TRIM` where it walks the trimmed cells, and `KEY_WIDTH_SHIFT` where the state's width
/// is a power of two (its texels found by a mask and a shift).
pub fn search_defines(defines: &Defines, lattice: &Lattice, size: [u32; 2]) -> Defines {
    let mut d = defines.clone();
    if size[0].is_power_of_two() {
        d.push((
            "KEY_WIDTH_SHIFT".into(),
            size[0].trailing_zeros().to_string(),
        ));
    }
    if lattice.uses_table(size[0] as u64 * size[1] as u64) {
        d.push(("CELL_TABLE".into(), "1".into()));
        d.push((
            "TABLE_WIDTH_SHIFT".into(),
            TABLE_WIDTH.trailing_zeros().to_string(),
        ));
    }
    if lattice.walk.trims() {
        d.push(("SEARCH_TRIM".into(), "1".into()));
    }
    d
}

/// Cells per block of the table's first level: each cell's start is searched among the keys
/// between its block's start and the next's (about 32 cells' particles, a few fetches).
pub const TABLE_BLOCK: u32 = 32;

/// The table's target and pass, and its first level's (the start of every block of
/// [`TABLE_BLOCK`] cells).
#[derive(Debug)]
struct Table {
    target: Framebuffer,
    program: Program,
    blocks: Framebuffer,
    block_program: Program,
}

/// An R32F target of `texels` texels in rows of at most [`TABLE_WIDTH`].
fn table_target(ctx: &Context, label: &'static str, texels: u32) -> Result<Framebuffer> {
    let width = texels.min(TABLE_WIDTH);
    let texture = Texture::new(
        ctx,
        TextureDesc {
            width,
            height: texels.div_ceil(width),
            format: TextureFormat::R32F,
            label,
        },
    )?;
    Framebuffer::new(ctx, label, vec![texture])
}

/// The search of one lattice over the sorted keys of a state: its uniforms, and the cell-start
/// table where the lattice is small enough ([`uses_table`]).
#[derive(Debug)]
pub struct CellSearch {
    lattice: Lattice,
    /// Entries per sorted row (the state width).
    key_width: u32,
    /// Entries (the state size).
    count: u32,
    /// Two entries per texel of the sorted keys (the packed network).
    packed: bool,
    table: Option<Table>,
}

impl CellSearch {
    /// The search of `lattice` over the sorted keys of a `size` state, laid out two entries per
    /// texel with `packed` (the packed network), else one.
    pub fn new(ctx: &Context, lattice: Lattice, size: [u32; 2], packed: bool) -> Result<Self> {
        let [w, h] = size;
        let cells = lattice.cells();
        let table = if lattice.uses_table(w as u64 * h as u64) {
            let mut d = Defines::new();
            if packed {
                d.push(("PACKED_KEYS".into(), "1".into()));
            }
            let program = |f| Program::new(ctx, FULLSCREEN_VERTEX, f, &d);
            Some(Table {
                // Cells and the sentinel; blocks up to the sentinel's and the one after it.
                target: table_target(ctx, "cell start", cells as u32 + 1)?,
                program: program("collide/cell_start.frag")?,
                blocks: table_target(ctx, "cell blocks", cells as u32 / TABLE_BLOCK + 2)?,
                block_program: program("collide/cell_block.frag")?,
            })
        } else {
            None
        };
        Ok(CellSearch {
            lattice,
            key_width: w,
            count: w * h,
            packed,
            table,
        })
    }

    /// The lattice searched.
    pub fn lattice(&self) -> Lattice {
        self.lattice
    }

    /// Whether the search reads a cell-start table (else the binary search).
    pub fn has_table(&self) -> bool {
        self.table.is_some()
    }

    /// Writes the cell-start table of the sorted `keys` (nothing without a table): after every
    /// sort and gather the search reads.
    pub fn build(&self, pass: &FullscreenPass, keys: &Texture) {
        let Some(t) = &self.table else {
            return;
        };
        let blocks = [
            ("u_key_width", Uniform::I32(self.key_width as i32)),
            ("u_count", Uniform::I32(self.count as i32)),
            ("u_block_width", Uniform::I32(t.blocks.width() as i32)),
            ("u_block", Uniform::I32(TABLE_BLOCK as i32)),
            ("u_cells", Uniform::I32(self.lattice.cells() as i32)),
        ];
        let mut cells = blocks.to_vec();
        cells.push(("u_cell_width", Uniform::I32(t.target.width() as i32)));
        let (k, b) = (keys.into(), t.blocks.only_texture().into());
        pass.draw(&t.block_program, &[("u_keys", k)], &blocks, &t.blocks);
        pass.draw(
            &t.program,
            &[("u_keys", k), ("u_blocks", b)],
            &cells,
            &t.target,
        );
    }

    /// The search's uniforms, for the draws of the passes that walk the cells.
    pub fn uniforms(&self) -> Vec<(&'static str, Uniform)> {
        let d = self.lattice.dims.as_ivec3();
        vec![
            ("u_key_width", Uniform::I32(self.key_width as i32)),
            ("u_count", Uniform::I32(self.count as i32)),
            ("u_dims", Uniform::IVec3(d)),
            // The trimmed walk's geometry (`SEARCH_TRIM`); its radius is the pass's own.
            ("u_cell_origin", Uniform::Vec3(self.lattice.origin)),
            ("u_cell_size", Uniform::F32(self.lattice.spacing)),
        ]
    }

    /// The textures the search samples: the sorted `keys` and the table.
    pub fn textures<'a>(&'a self, keys: &'a Texture) -> Vec<(&'static str, Sampled<'a>)> {
        let mut out = vec![("u_keys", keys.into())];
        if let Some(t) = &self.table {
            out.push(("u_cell_start", t.target.only_texture().into()));
        }
        out
    }

    /// The table passes' draws (its first level, then the table), `times` a step, for the pass
    /// list line beginning with `line`; none without a table.
    pub fn pass_draws(&self, line: &str, times: u64) -> Vec<PassDraw> {
        (self.table.iter())
            .flat_map(|t| [&t.block_program, &t.program])
            .map(|p| PassDraw::of(line, p, times))
            .collect()
    }

    /// The sorted keys of `keys` (the texture the search reads), in sorted order, as the
    /// search reads them.
    pub fn read_keys(&self, keys: &Texture) -> Result<Vec<f32>> {
        let raw = keys.read_f32()?;
        let (c, tw) = (keys.format().channels(), keys.width() as usize);
        let w = self.key_width as usize;
        Ok((0..self.count as usize)
            .map(|i| {
                let (row, col) = (i / w, i % w);
                match self.packed {
                    true => raw[(row * tw + col / 2) * c + 2 * (i & 1)],
                    false => raw[(row * tw + col) * c],
                }
            })
            .collect())
    }

    /// The last table written, cell by cell and the sentinel (`None` without a table).
    pub fn read_table(&self) -> Result<Option<Vec<f32>>> {
        let Some(t) = &self.table else {
            return Ok(None);
        };
        let mut v = t.target.only_texture().read_f32()?;
        v.truncate(self.lattice.cells() as usize + 1);
        Ok(Some(v))
    }
}
