//! The GPU side of our blocked sort ([`crate::sort::blocked`]): the 3D textures whose layers
//! hold the entries between passes, the passes' programs and uniforms.

use std::collections::HashMap;

use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, Program, Sampled, Texture, Texture3D,
    TextureFormat, UniformList, FULLSCREEN_VERTEX,
};
use crate::sort::blocked::BlockPass;

mod merge;
use merge::Partition;

/// Group bits per pass, whether logical bit 0 is pinned to the lane, and the entry size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockedShape {
    /// Entries per fragment: 2^bits (exact: 2 to 4, 2 to 8 render targets; compact: 2 to 5,
    /// 1 to 8).
    pub bits: u32,
    /// Logical bit 0 stays in the lane of every layout (half the fetches, one bit less).
    pub pinned: bool,
    /// 4-byte entries: the key quantised into the bits the identifier leaves free of one uint
    /// (lossy among keys closer than one quantisation step; see `compact_level`). Needs the
    /// keys' range ([`Sorter::set_key_range`](super::Sorter::set_key_range)).
    pub compact: bool,
    /// Sort runs of 2^bits entries with the network, then merge them in passes that double
    /// them ([`merge_schedule`](crate::sort::blocked::merge_schedule)): one pass a bit instead
    /// of about bits / 2 a bit. Not with the pinned lane.
    pub merge: bool,
}

impl Default for BlockedShape {
    fn default() -> Self {
        BlockedShape {
            bits: 4,
            pinned: false,
            compact: false,
            merge: true,
        }
    }
}

impl BlockedShape {
    /// The shape's short name in tables: bits, then `p` if pinned, `c` if compact, `m` if
    /// merging (`"5cm"`).
    pub fn label(&self) -> String {
        format!(
            "{}{}{}{}",
            self.bits,
            if self.pinned { "p" } else { "" },
            if self.compact { "c" } else { "" },
            if self.merge { "m" } else { "" }
        )
    }
}

/// How the compact entries quantise keys: level `floor((key - lo) * scale)` clamped to
/// `0..=top - 1`, where `top = 2^(32 - id_bits) - 1` is the level of +inf and NaN keys.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantiser {
    /// Bits of the identifier (log2 of the entries sorted).
    pub id_bits: u32,
    /// The key of level 0.
    pub lo: f32,
    /// Levels per unit of key.
    pub scale: f32,
}

impl Quantiser {
    /// The quantiser that spreads `[lo, hi]` over every finite level of `id_bits`-bit
    /// identifiers.
    pub fn new(id_bits: u32, lo: f32, hi: f32) -> Result<Self> {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(Error::InvalidInput(format!(
                "key range [{lo}, {hi}] for the compact sort: give finite bounds, low first"
            )));
        }
        let top = (1u64 << (32 - id_bits)) - 1;
        let scale = if hi > lo {
            (top - 1) as f32 / (hi - lo)
        } else {
            0.0
        };
        Ok(Quantiser { id_bits, lo, scale })
    }

    /// The level of `key`: the CPU twin of `compact_entry` in `glsl/sort/blocked.frag`.
    pub fn level(&self, key: f32) -> u32 {
        compact_level(key, self.lo, self.scale, self.id_bits)
    }

    /// The packed entry of `(key, id)`.
    pub fn entry(&self, key: f32, id: u32) -> u32 {
        (self.level(key) << self.id_bits) | id
    }
}

/// The quantisation level of `key` (see [`Quantiser`]): the same float operations as the shader;
/// -inf takes level 0, +inf and NaN the top level.
pub fn compact_level(key: f32, lo: f32, scale: f32, id_bits: u32) -> u32 {
    let top = ((1u64 << (32 - id_bits)) - 1) as u32;
    let u = key.to_bits();
    if u & 0x7f80_0000 == 0x7f80_0000 {
        return if u == 0xff80_0000 { 0 } else { top };
    }
    let q = ((key - lo) * scale).floor();
    if q >= (top - 1) as f32 {
        top - 1
    } else if q > 0.0 {
        q as u32
    } else {
        0
    }
}

/// Most cells of a lattice whose keys rows-only compact exact entries hold: cell keys are exact
/// floats up to 2^24.
const ROW_CELLS_MAX: u64 = 1 << 24;

/// Whether rows-only compact exact entries hold every key of a lattice of `cells` cells sorted
/// in blocks of 2^`block_bits` entries (one row, or a set of rows): the position in the block
/// takes the low `block_bits` bits, and the `32 - block_bits` high bits one level for each
/// cell plus three for -inf, +inf (dead particles) and NaN (padding). 1024 wide: 4,194,301
/// cells.
pub fn row_cells_fit(cells: u64, block_bits: u32) -> bool {
    (2..=24).contains(&block_bits)
        && cells <= ROW_CELLS_MAX
        && cells + 3 <= 1u64 << (32 - block_bits)
}

/// The rows-only compact exact entry of `key` at row-major index `index` (the CPU twin of
/// `row_cell_entry` in `glsl/sort/blocked.frag`): level 0 for -inf, `key + 1` for a whole
/// key, `top - 1` for +inf and `top` for NaN (`top = 2^(32 - block_bits) - 1`), above the
/// index's position in its block. Lossless for whole keys up to `top - 3`, so comparing entries
/// as uints orders them as the exact (key, id) entries whose ids are their indices.
pub fn row_cell_entry(key: f32, index: u32, block_bits: u32) -> u32 {
    let top = ((1u64 << (32 - block_bits)) - 1) as u32;
    let u = key.to_bits();
    let level = if u & 0x7fff_ffff > 0x7f80_0000 {
        top
    } else if u == 0x7f80_0000 {
        top - 1
    } else if u == 0xff80_0000 {
        0
    } else {
        key.clamp(0.0, (top - 3) as f32) as u32 + 1
    };
    (level << block_bits) | (index & ((1 << block_bits) - 1))
}

/// The blocked network's state and passes. Framebuffers before textures: they are dropped first.
pub(super) struct Blocked {
    fbs: [Framebuffer; 2],
    tex: [Texture3D; 2],
    /// Which of `tex` holds the entries after the last pass run.
    front: usize,
    passes: Vec<BlockPass>,
    /// Logical bits.
    n: u32,
    bits: u32,
    pinned: bool,
    log_w: u32,
    natural_log_w: u32,
    programs: HashMap<(bool, Vec<u32>), Program>,
    /// The merge passes' program, where the schedule merges.
    merge: Option<Program>,
    /// The partition passes and the merges that read them, where the schedule has any.
    partition: Option<Partition>,
    unpack: Program,
    /// 4-byte entries (quantised, or rows-only exact).
    compact: bool,
    /// With quantised 4-byte entries: how keys are quantised (the range is set before each
    /// sort).
    quantiser: Option<Quantiser>,
    /// With rows-only compact exact entries: log2 of the entries of a sorted block.
    row_cells: Option<u32>,
    /// Whether the last pass leaves the entries row-major within the blocks (it merges).
    identity: bool,
}

impl std::fmt::Debug for Blocked {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Blocked({} passes, 2^{} entries per fragment)",
            self.passes.len(),
            self.bits
        )
    }
}

fn log2(v: u32) -> u32 {
    v.trailing_zeros()
}

impl Blocked {
    /// A blocked network over a `width`×`height` natural texture (powers of two) that runs
    /// `passes`, the network passes of [`crate::sort::schedule::network`]; `row_cells`: the
    /// log2 of the entries of a sorted block, for rows-only compact exact entries (`shape` is
    /// then compact).
    pub(super) fn new(
        ctx: &Context,
        [width, height]: [u32; 2],
        shape: BlockedShape,
        passes: Vec<BlockPass>,
        row_cells: Option<u32>,
    ) -> Result<Self> {
        let n = log2(width * height);
        let quantiser = check_entries(shape, n, row_cells)?;
        let bits = shape.bits.min(n).max(1);
        let pixels = (width * height) >> bits;
        let w = width.min(pixels).max(1);
        let h = (pixels / w).max(1);
        let (lanes, format) = if shape.compact {
            (4, TextureFormat::Rgba32Ui)
        } else {
            (2, TextureFormat::Rgba32F)
        };
        let layers = (1u32 << bits).div_ceil(lanes);
        let make = |i: usize| {
            Texture3D::new(
                ctx,
                &format!("blocked sort {i}"),
                format,
                [w, h, layers],
                None,
            )
        };
        let tex = [make(0)?, make(1)?];
        let fbs = [
            Framebuffer::layers(ctx, "blocked sort 0", &tex[0])?,
            Framebuffer::layers(ctx, "blocked sort 1", &tex[1])?,
        ];
        let mut d: Defines = vec![("BITS".to_string(), bits.to_string())];
        if shape.compact {
            d.push(("COMPACT".into(), "1".into()));
        }
        if row_cells.is_some() {
            d.push(("ROW_CELLS".into(), "1".into()));
        }
        let last_layout = passes.last().map(|l| l.layout(n));
        let identity =
            last_layout.is_none_or(|l| l.iter().enumerate().all(|(i, &b)| b == i as u32));
        if identity {
            d.push(("IDENTITY_LAYOUT".into(), "1".into()));
        }
        let unpack = Program::new(ctx, FULLSCREEN_VERTEX, "sort/blocked_unpack.frag", &d)?;
        let (merge, partition) = merge::programs(ctx, &passes, [n, bits, w], shape.compact)?;
        let mut b = Blocked {
            fbs,
            tex,
            front: 0,
            passes,
            n,
            bits,
            pinned: shape.pinned && bits >= 2,
            log_w: log2(w),
            natural_log_w: log2(width),
            programs: HashMap::new(),
            merge,
            partition,
            unpack,
            compact: shape.compact,
            quantiser,
            row_cells,
            identity,
        };
        for i in 0..b.passes.len() {
            if b.passes[i].merge.is_some() || b.passes[i].partition.is_some() {
                continue;
            }
            let key = b.program_key(i);
            if !b.programs.contains_key(&key) {
                let p = b.build_program(ctx, &key)?;
                b.programs.insert(key, p);
            }
        }
        Ok(b)
    }

    /// Sets the range of keys the compact entries spread over their levels; an error for exact
    /// entries.
    pub(super) fn set_key_range(&mut self, lo: f32, hi: f32) -> Result<()> {
        match &mut self.quantiser {
            Some(q) => {
                *q = Quantiser::new(q.id_bits, lo, hi)?;
                Ok(())
            }
            None => Err(Error::InvalidInput(
                "a key range is for the compact blocked sort only: exact entries keep the keys"
                    .into(),
            )),
        }
    }

    /// The quantiser of compact entries.
    pub(super) fn quantiser(&self) -> Option<Quantiser> {
        self.quantiser
    }

    /// The framebuffer the next network pass writes (for floors).
    pub(super) fn target(&self) -> &Framebuffer {
        &self.fbs[1 - self.front]
    }

    /// The program of pass `i`'s name, for the pass list.
    pub(super) fn pass_program(&self, i: usize) -> &str {
        self.merge_program_name(i)
            .unwrap_or_else(|| self.programs[&self.program_key(i)].name())
    }

    /// Whether a gather can read the sorted entries where the last pass left them: exact
    /// entries (key and identifier as written) in row-major order within the blocks.
    pub(super) fn gathers_in_place(&self) -> bool {
        self.identity && !self.compact
    }

    /// The sorted entries after the last pass, the defines `glsl/sort/blocked_entry.glsl`
    /// reads them with and its `u_log_w`.
    pub(super) fn sorted_layout(&self) -> (&Texture3D, Defines, i32) {
        let d = vec![("BITS".to_string(), self.bits.to_string())];
        (&self.tex[self.front], d, self.log_w as i32)
    }

    /// The unpack's program name, for the pass list.
    pub(super) fn unpack_program(&self) -> &str {
        self.unpack.name()
    }

    fn program_key(&self, i: usize) -> (bool, Vec<u32>) {
        (i == 0, self.passes[i].local_bits())
    }

    fn build_program(&self, ctx: &Context, key: &(bool, Vec<u32>)) -> Result<Program> {
        // Every compare-exchange of the pass, in order: step s flips slot bit key.1[s].
        let size = 1u32 << self.bits;
        let mut network = String::new();
        for (s, &bit) in key.1.iter().enumerate() {
            for c in (0..size).filter(|c| c >> bit & 1 == 0) {
                network.push_str(&format!("CX({s}, {c}, {}) ", c | 1 << bit));
            }
        }
        let mut d: Defines = vec![
            ("BITS".into(), self.bits.to_string()),
            ("STEP_COUNT".into(), key.1.len().to_string()),
            ("NETWORK".into(), network),
        ];
        if key.0 {
            d.push(("NATURAL_INPUT".into(), "1".into()));
        }
        if self.pinned {
            d.push(("PINNED".into(), "1".into()));
        }
        if self.compact {
            d.push(("COMPACT".into(), "1".into()));
        }
        if key.0 && self.row_cells.is_some() {
            d.push(("ROW_CELLS".into(), "1".into()));
        }
        Program::new(ctx, FULLSCREEN_VERTEX, "sort/blocked.frag", &d)
    }

    /// Storage bit of every logical bit in the layout pass `i` reads (`i = 0`: row-major).
    fn input_layout(&self, i: usize) -> Vec<u32> {
        if i == 0 {
            (0..self.n).collect()
        } else {
            self.passes[i - 1].layout(self.n)
        }
    }

    /// Runs network pass `i`; the first reads `natural`, the others the last pass's blocks.
    pub(super) fn run(&mut self, i: usize, natural: &Texture, fullscreen: &FullscreenPass) {
        if self.run_merge(i, fullscreen) {
            return;
        }
        let pass = &self.passes[i];
        let prev = self.input_layout(i);
        let p = &self.programs[&self.program_key(i)];
        let mut u = UniformList::new();
        let input: (&str, Sampled) = if i == 0 {
            u.i32("u_in_log_w", self.natural_log_w as i32);
            ("u_natural", natural.into())
        } else {
            u.i32("u_in_log_w", self.log_w as i32);
            ("u_blocks", (&self.tex[self.front]).into())
        };
        u.i32("u_log_w", self.log_w as i32);
        if let (true, Some(q)) = (i == 0, self.quantiser) {
            set_quantiser(&mut u, &q);
        }
        if let (true, Some(b)) = (i == 0, self.row_cells) {
            u.i32("u_block_bits", b as i32);
        }
        let pixel_bits = pass.pixel_bits(self.n);
        u.i32("u_pixel_bits", pixel_bits.len() as i32);
        let pix_prev: Vec<i32> = pixel_bits
            .iter()
            .map(|&l| prev[l as usize] as i32)
            .collect();
        let pix_logical: Vec<i32> = pixel_bits.iter().map(|&l| l as i32).collect();
        if !pixel_bits.is_empty() {
            u.i32s("u_pix_prev", &pix_prev);
            u.i32s("u_pix_logical", &pix_logical);
        }
        let size = 1usize << self.bits;
        let mut prev_slot = vec![0i32; size];
        let mut slot_logical = vec![0i32; size];
        for c in 0..size {
            for (t, &g) in pass.group.iter().enumerate() {
                if c >> t & 1 == 1 {
                    prev_slot[c] |= 1 << prev[g as usize];
                    slot_logical[c] |= 1 << g;
                }
            }
        }
        u.i32s("u_prev_slot", &prev_slot);
        u.i32s("u_slot_logical", &slot_logical);
        let dir: Vec<i32> = pass
            .steps
            .iter()
            .map(|s| s.dir.map_or(-1, |d| d as i32))
            .collect();
        u.i32s("u_dir", &dir);
        fullscreen.draw(p, &[input], u.values(), &self.fbs[1 - self.front]);
        self.front = 1 - self.front;
    }

    /// The last pass: the sorted entries, row-major, into `target` (the sorter's texture).
    pub(super) fn unpack(&self, target: &Framebuffer, fullscreen: &FullscreenPass) {
        let p = &self.unpack;
        let mut u = UniformList::new();
        u.i32("u_in_log_w", self.log_w as i32);
        u.i32("u_width_log", self.natural_log_w as i32);
        u.i32("u_bits", self.n as i32);
        if let Some(q) = self.quantiser {
            set_quantiser(&mut u, &q);
        }
        if let Some(b) = self.row_cells {
            u.i32("u_block_bits", b as i32);
        }
        let perm: Vec<i32> = self
            .passes
            .last()
            .map(|l| l.layout(self.n))
            .unwrap_or_default()
            .iter()
            .map(|&b| b as i32)
            .collect();
        u.i32s("u_perm", &perm);
        let blocks = [("u_blocks", Sampled::from(&self.tex[self.front]))];
        fullscreen.draw(p, &blocks, u.values(), target);
    }
}

/// Checks the shape against the entries it holds; the quantiser of lossy compact entries (none
/// for exact ones, nor for rows-only compact exact ones, whose ids take `row_cells` bits).
fn check_entries(shape: BlockedShape, n: u32, row_cells: Option<u32>) -> Result<Option<Quantiser>> {
    if shape.merge && shape.pinned {
        return Err(Error::InvalidInput(
            "the merging blocked sort reads its entries row-major: no pinned lane (drop `p` or `m`)"
                .into(),
        ));
    }
    Ok(if let Some(block_bits) = row_cells {
        check_compact(shape, block_bits)?;
        None
    } else if shape.compact {
        check_compact(shape, n)?;
        Some(Quantiser::new(n, 0.0, 1.0)?)
    } else {
        if !(2..=4).contains(&shape.bits) {
            return Err(Error::InvalidInput(format!(
                "the blocked sort holds 4, 8 or 16 exact entries per fragment (bits 2 to 4), \
                 not 2^{}: 32 (bits 5) takes compact entries",
                shape.bits
            )));
        }
        None
    })
}

fn set_quantiser(u: &mut UniformList, q: &Quantiser) {
    u.i32("u_id_bits", q.id_bits as i32);
    u.f32("u_key_lo", q.lo);
    u.f32("u_key_scale", q.scale);
}

/// Compact entries: 2 to 5 bits a pass, no pinned lane, and at least 8 key bits beside the
/// identifier of `n` bits.
pub(super) fn check_compact(shape: BlockedShape, n: u32) -> Result<()> {
    let bad = |m: String| Err(Error::InvalidInput(m));
    if !(2..=5).contains(&shape.bits) {
        return bad(format!(
            "the compact blocked sort holds 4 to 32 entries per fragment (bits 2 to 5), not 2^{}",
            shape.bits
        ));
    }
    if shape.pinned {
        return bad("the compact blocked sort has four entries per texel: no pinned lane".into());
    }
    if n < 2 {
        return bad("the compact blocked sort needs at least 4 entries".into());
    }
    if n > 24 {
        return bad(format!(
            "2^{n} entries leave {} bits of a compact entry for the key: use at most 2^24 \
             entries (8 key bits), or exact entries",
            32 - n
        ));
    }
    Ok(())
}
