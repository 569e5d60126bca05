//! The lattice of a cell sort ([`Lattice`]) and the exact neighbour search over the sorted state
//! (`glsl/collide/cells.glsl`, [`CellSearch`]), one owner for the collision stage's exact
//! detection, its neighbour forces and exchanges, and the fluid: the lattice searched, the
//! uniforms and textures every searching pass takes, and the cell-start table (as `cellStart`
//! in NVIDIA's CUDA `particles` sample, here a fragment pass).
//!
//! After each sort and gather that a search reads, one full-screen pass
//! (`glsl/collide/cell_start.frag`) writes, for every cell c of the lattice, the first sorted
//! index whose key is not below c, and the live particles' count after the last cell: one binary
//! search per cell instead of 9 per particle and searching pass. The search then reads the
//! bounds of each run of three cells from the table (18 fetches per particle). Keys are whole
//! cell indices (or +inf for the dead), so the run it walks is the one the binary search finds:
//! the same neighbours in the same order, every output bit for bit the same.
//!
//! The table costs one binary search per cell: it pays while the cells are not many more than
//! the particles. A lattice of more than 8 cells per entry (see [`uses_table`]), or of more than
//! [`TABLE_MAX_CELLS`], keeps the binary search of every row instead; the pass list says which
//! search runs. (On llvmpipe a table of 24 cells per particle, `dem` at 64×64, made its collision
//! stage 5 times slower.)

use glam::{UVec3, Vec3};

use crate::error::Result;
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, PassDraw, Program, Sampled, Texture,
    TextureDesc, TextureFormat, Uniform, FULLSCREEN_VERTEX,
};
use crate::scene::{self, SceneFile};
use crate::sort::KeyMode;

/// A lattice: corner of cell (0, 0, 0), mesh size, cells per axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lattice {
    /// Corner of cell (0, 0, 0).
    pub origin: Vec3,
    /// Mesh size g0.
    pub spacing: f32,
    /// Cells per axis.
    pub dims: UVec3,
}

impl Lattice {
    /// The lattice of a scene's `[collisions]`, or its staggered twin (shifted by g0/2, one cell
    /// more per axis).
    pub fn of(c: &scene::Collisions, staggered: bool) -> Self {
        let g = c.cell();
        let lo = Vec3::from(c.bounds[0]);
        let hi = Vec3::from(c.bounds[1]);
        let dims = ((hi - lo) / g).ceil().max(Vec3::ONE).as_uvec3();
        if staggered {
            Lattice {
                origin: lo - Vec3::splat(0.5 * g),
                spacing: g,
                dims: dims + UVec3::ONE,
            }
        } else {
            Lattice {
                origin: lo,
                spacing: g,
                dims,
            }
        }
    }

    /// The lattice of `[fluid]`: cell 2h (the cubic spline's support) from the lower corner of
    /// its bounds.
    pub fn of_fluid(f: &scene::Fluid) -> Self {
        let g = 2.0 * f.h();
        let lo = Vec3::from(f.bounds[0]);
        let hi = Vec3::from(f.bounds[1]);
        Lattice {
            origin: lo,
            spacing: g,
            dims: ((hi - lo) / g).ceil().max(Vec3::ONE).as_uvec3(),
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

    pub(super) fn mode(&self) -> KeyMode {
        KeyMode::GridCell {
            origin: self.origin,
            spacing: self.spacing,
            dims: self.dims,
        }
    }
}

/// Cells per row of the table.
pub const TABLE_WIDTH: u32 = 2048;

/// Most cells a lattice has for the table: with the sentinel, at most 2048 rows of
/// [`TABLE_WIDTH`] texels (16 MiB of R32F), a texture every GL ES 3.0 device can hold.
pub const TABLE_MAX_CELLS: u64 = (1 << 22) - 1;

thread_local! {
    // Set by `with_search` while it builds stages on this thread.
    static FORCED: std::cell::Cell<Option<bool>> = const { std::cell::Cell::new(None) };
}

/// Runs `build` with every search it builds on this thread (stages, their pass lists) reading
/// the table (`table`, for any lattice up to [`TABLE_MAX_CELLS`]) or the binary search, whatever
/// the rule of [`uses_table`] says: for comparing the two searches, which must give the same
/// state bit for bit.
pub fn with_search<T>(table: bool, build: impl FnOnce() -> T) -> T {
    let before = FORCED.with(|f| f.replace(Some(table)));
    let out = build();
    FORCED.with(|f| f.set(before));
    out
}

/// Whether a search of a lattice of `cells` cells over `entries` sorted entries reads a
/// cell-start table: cells ≤ 8 × entries and ≤ [`TABLE_MAX_CELLS`]; else the binary search.
/// The table pass fetches about log2(entries) keys per cell, one searching pass 9 log2(entries)
/// per entry: up to 8 cells an entry the table fetches less than the one pass it serves saves.
pub fn uses_table(cells: u64, entries: u64) -> bool {
    let rule = cells <= 8 * entries;
    cells <= TABLE_MAX_CELLS && FORCED.with(|f| f.get()).unwrap_or(rule)
}

/// Which searches of a scene read a cell-start table: the exact collision detection's (and its
/// neighbour forces' and exchanges'), and the fluid's. `false` where the scene has no such
/// search or its lattice is too large for the table.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct CellTables {
    /// The exact collision detection's lattice.
    pub collisions: bool,
    /// The fluid's lattice (cell 2h).
    pub fluid: bool,
}

impl CellTables {
    /// The tables `scene` builds.
    pub fn of(scene: &SceneFile) -> Self {
        let [w, h] = scene.particles.size;
        let entries = w as u64 * h as u64;
        let table = |l: Lattice| uses_table(l.cells(), entries);
        CellTables {
            collisions: (scene.collisions.as_ref())
                .filter(|c| c.detection == scene::Detection::Exact)
                .is_some_and(|c| table(Lattice::of(c, false))),
            fluid: (scene.fluid.as_ref()).is_some_and(|f| table(Lattice::of_fluid(f))),
        }
    }
}

/// How the search finds each run of three cells, for the pass lists.
pub fn search_words(table: bool) -> &'static str {
    if table {
        "run bounds read from the cell-start table, 2 fetches per row of 3 cells"
    } else {
        "binary search of the sorted keys per row of 3 cells (the lattice is too large for a \
         cell-start table)"
    }
}

/// The pass list's line of the table pass, after the gather of `what` (`"collision"`, `"fluid"`)
/// and `when` (`""`, or `", every iteration"`).
pub fn table_line(what: &str, when: &str) -> String {
    let prefix = if what == "fluid" { "fluid " } else { "" };
    format!(
        "{prefix}cell start: one texel per cell of the {what} lattice and a sentinel, the first \
         sorted index whose key is not below the cell's (a binary search of the sorted keys per \
         cell){when}"
    )
}

/// The simulation's `defines` and `CELL_TABLE` where the search of `lattice` over a `size`
/// state reads the table.
pub fn search_defines(defines: &Defines, lattice: &Lattice, size: [u32; 2]) -> Defines {
    let mut d = defines.clone();
    if uses_table(lattice.cells(), size[0] as u64 * size[1] as u64) {
        d.push(("CELL_TABLE".into(), "1".into()));
    }
    d
}

/// The table's target and pass.
#[derive(Debug)]
struct Table {
    target: Framebuffer,
    program: Program,
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
        let table = if uses_table(cells, w as u64 * h as u64) {
            let texels = cells as u32 + 1;
            let width = texels.min(TABLE_WIDTH);
            let texture = Texture::new(
                ctx,
                TextureDesc {
                    width,
                    height: texels.div_ceil(width),
                    format: TextureFormat::R32F,
                    label: "cell start",
                },
            )?;
            let mut d = Defines::new();
            if packed {
                d.push(("PACKED_KEYS".into(), "1".into()));
            }
            Some(Table {
                target: Framebuffer::new(ctx, "cell start", vec![texture])?,
                program: Program::new(ctx, FULLSCREEN_VERTEX, "collide/cell_start.frag", &d)?,
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
        let uniforms = [
            ("u_key_width", Uniform::I32(self.key_width as i32)),
            ("u_count", Uniform::I32(self.count as i32)),
            ("u_cell_width", Uniform::I32(t.target.width() as i32)),
            ("u_cells", Uniform::I32(self.lattice.cells() as i32)),
        ];
        pass.draw(&t.program, &[("u_keys", keys.into())], &uniforms, &t.target);
    }

    /// The search's uniforms, for the draws of the passes that walk the cells.
    pub fn uniforms(&self) -> Vec<(&'static str, Uniform)> {
        let d = self.lattice.dims.as_ivec3();
        let mut out = vec![
            ("u_key_width", Uniform::I32(self.key_width as i32)),
            ("u_count", Uniform::I32(self.count as i32)),
            ("u_dims", Uniform::IVec3(d)),
        ];
        if let Some(t) = &self.table {
            out.push(("u_cell_width", Uniform::I32(t.target.width() as i32)));
        }
        out
    }

    /// The textures the search samples: the sorted `keys` and the table.
    pub fn textures<'a>(&'a self, keys: &'a Texture) -> Vec<(&'static str, Sampled<'a>)> {
        let mut out = vec![("u_keys", keys.into())];
        if let Some(t) = &self.table {
            out.push(("u_cell_start", t.target.only_texture().into()));
        }
        out
    }

    /// The table pass's draws, `times` a step, for the pass list line beginning with `line`.
    pub fn pass_draw(&self, line: &str, times: u64) -> Option<PassDraw> {
        (self.table.as_ref()).map(|t| PassDraw::of(line, &t.program, times))
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
