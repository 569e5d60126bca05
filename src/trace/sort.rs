//! `texflow trace sort`: random keys sorted on the GPU pass by pass, each pass's texture read
//! back and drawn (UberFlow Fig. 1-3, Latta Fig. 3-5, on real data), with an animated GIF.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::picture::{ramp_position, scalar};
use super::Written;
use crate::error::{Error, Result};
use crate::gl::Context;
use crate::output::{write_atomic, write_png_atomic, VideoWriter};
use crate::sort::network::{Entry, Step};
use crate::sort::{NetworkPass, SortOptions, Sorter, Variant};

/// The largest side of a traced sort: 64×64 keys, 4096 entries, at most 78 passes (bitonic) and
/// so at most 79 pictures.
pub const MAX_SORT_SIDE: u32 = 64;

/// Refuses a size the trace does not draw: a power of two from 2 to [`MAX_SORT_SIDE`].
pub fn check_sort_size(side: u32) -> Result<()> {
    if !(2..=MAX_SORT_SIDE).contains(&side) || !side.is_power_of_two() {
        return Err(Error::InvalidInput(format!(
            "--size {side}: a traced sort is a power of two from 2 to {MAX_SORT_SIDE} (N×N keys, \
             one picture per pass); for larger sorts use `texflow sort` or `texflow bench sort`"
        )));
    }
    Ok(())
}

/// What one pass of a variant does, in the papers' terms.
pub fn describe_step(step: &Step, width: u32) -> String {
    match *step {
        Step::Bitonic { block, mirror, .. } if mirror => format!(
            "bitonic merge of {}-row blocks ({block} entries): the reversing first pass, entry \
             i against i XOR {} (UberFlow §4.3.3, Fig. 2)",
            block / width,
            block - 1
        ),
        Step::Bitonic { block, dist, .. } if block <= width => format!(
            "bitonic stage of {block}-entry runs within rows, compare at distance {dist} (runs \
             alternate ascending and descending; UberFlow §4.3.2, Fig. 1)"
        ),
        Step::Bitonic { block, dist, .. } => format!(
            "bitonic merge of {}-row blocks, compare at distance {dist}{} (UberFlow §4.3.3)",
            block / width,
            if dist >= width {
                format!(" ({} rows)", dist / width)
            } else {
                String::new()
            }
        ),
        Step::OddEvenRecursion { step, count } => format!(
            "odd-even merge, recursion program: stride {step}, sub-sequences of {count} entries, \
             odd m against m+1 (Latta §3.4.4, Fig. 4-5)"
        ),
        Step::OddEvenEnd { step } => format!(
            "odd-even merge, end program: stride {step}, halves of {} entries compared (Latta \
             §3.4.4, Fig. 4-5)",
            step
        ),
    }
}

/// The descriptions of a variant's passes on a `side`×`side` texture, in the order the sorter
/// runs them: read from the variant's schedule ([`crate::sort::schedule::network`]), the list the sorter
/// builds its passes from.
pub fn pass_descriptions(variant: Variant, side: u32, options: &SortOptions) -> Vec<String> {
    let network = crate::sort::passes_of(variant, side, side, side * side, options);
    if variant == Variant::Blocked {
        // Between its passes the blocked sort's entries lie in the layers of 3D textures, in a
        // layout that changes from pass to pass: the sort texture is row-major again only after
        // the last, so the trace draws its whole sort as one step.
        return vec![format!(
            "the blocked sort (ours): the key pass, the {} passes of its network over blocks of \
             entries held in the layers of 3D textures, and the pass that writes them back in \
             row-major order, drawn as one step (between these passes the sort texture is not \
             in row-major order; docs/sorting.md)",
            network.len().saturating_sub(1)
        )];
    }
    network
        .iter()
        .map(|p| match p {
            NetworkPass::Step(s) => describe_step(s, side),
            NetworkPass::Group(g) => {
                let parts: Vec<String> = g.iter().map(|s| describe_step(s, side)).collect();
                format!("{} steps in one pass: {}", g.len(), parts.join("; then "))
            }
            NetworkPass::Blocked(b) => format!("a blocked pass of {} steps", b.steps.len()),
            NetworkPass::Unpack => "the entries back in row-major order".to_owned(),
        })
        .collect()
}

/// Keys uniform in [0, 1) from `seed` (splitmix64), ids 0, 1, 2, ...
pub fn random_entries(n: usize, seed: u64) -> Vec<Entry> {
    let mut state = seed;
    (0..n)
        .map(|i| {
            state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^= z >> 31;
            [(z >> 40) as f32 / (1u64 << 24) as f32, i as f32]
        })
        .collect()
}

/// Reads a picture of keys back: the ramp position of each entry's square (key in [0, 1)), or
/// `None` where a square is off the ramp. For tests and for checking a trace by eye.
pub fn keys_from_picture(img: &image::RgbImage, side: u32) -> Vec<Option<f32>> {
    let s = img.width() / side;
    (0..side * side)
        .map(|i| {
            let (x, y) = ((i % side) * s + s / 2, (i / side) * s + s / 2);
            ramp_position(img.get_pixel(x, y).0)
        })
        .collect()
}

/// Sorts `side`×`side` random keys with `variant`, writing `pass_000.png` (the input),
/// `pass_001.png`, ... (the entries after each pass), `sort.gif` and `index.md` into `out`
/// (which must exist).
pub fn trace_sort(
    ctx: &Context,
    variant: Variant,
    side: u32,
    seed: u64,
    out: &Path,
) -> Result<Written> {
    check_sort_size(side)?;
    let options = SortOptions::default();
    let mut sorter = Sorter::new(ctx, variant, side, side, options)?;
    let entries = random_entries((side * side) as usize, seed);
    sorter.load(&entries)?;
    let descriptions = pass_descriptions(variant, side, &options);
    // Sorter passes per traced step: all of them for the blocked sort, else one (the sorter's
    // passes are its schedule's, one for one: tests/sort_schedule.rs).
    let per = match variant {
        Variant::Blocked => sorter.pass_count(),
        Variant::Fp | Variant::GpFp | Variant::Packed | Variant::OddEven | Variant::Multistep => 1,
    };
    let mut trace = Trace {
        out,
        side,
        passes: descriptions.len(),
        pictures: Vec::new(),
        files: Vec::new(),
        md: intro(variant, side, seed),
    };
    trace.record(0, &entries, "The keys as loaded, before any pass")?;
    for (i, d) in descriptions.iter().enumerate() {
        sorter.run_passes(per);
        let now = sorter.read()?;
        trace.record(i + 1, &now, d)?;
    }
    let last = sorter.read()?;
    let sorted = last
        .windows(2)
        .all(|w| !crate::sort::entry_less(w[1], w[0]));
    let gif = out.join("sort.gif");
    let size = [trace.pictures[0].width(), trace.pictures[0].height()];
    let mut video = VideoWriter::create(&gif, size, trace.pictures.len() as u64, 4.0)?;
    for p in &trace.pictures {
        video.push(p)?;
    }
    trace.files.push(video.finish()?);
    let index = out.join("index.md");
    write_atomic(&index, trace.md.as_bytes())?;
    trace.files.push(index);
    Ok(Written {
        files: trace.files,
        passes: sorter.pass_count(),
        ok: sorted,
    })
}

/// The index's opening: the command and how to read the pictures.
fn intro(variant: Variant, side: u32, seed: u64) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Sort trace: {} on {side}×{side} random keys\n\n\
         `texflow trace sort --variant {} --size {side} --seed {seed}`. Each picture is the sort \
         texture read back after one pass: entry i is the square at column i mod {side}, row i \
         div {side} (row 0 at the top); its colour is its key on a ramp from dark blue (0) to \
         yellow (1). The keys are uniform in [0, 1); ids are the entries' starting places. \
         Animation: [sort.gif](sort.gif).\n",
        variant.name(),
        variant.name()
    );
    md
}

/// What the trace has written so far: one picture per pass, their files, the index's text.
struct Trace<'a> {
    out: &'a Path,
    side: u32,
    passes: usize,
    pictures: Vec<image::RgbImage>,
    files: Vec<PathBuf>,
    md: String,
}

impl Trace<'_> {
    /// Writes the picture of `entries` after pass `index` (0: the input, before any pass) and
    /// its paragraph in the index, saying `what` the pass did.
    fn record(&mut self, index: usize, entries: &[Entry], what: &str) -> Result<()> {
        let side = self.side;
        let keys: Vec<f32> = entries.iter().map(|e| e[0]).collect();
        let img = scalar(&keys, side, side, (0.0, 1.0));
        let name = format!("pass_{index:03}.png");
        let path = self.out.join(&name);
        write_png_atomic(&path, &img)?;
        let inversions = crate::sort::network::inversions(entries);
        let _ = writeln!(
            self.md,
            "## {}\n\n{what}. Out of order afterwards: {inversions} pairs.\n\n![{name}]({name})\n",
            if index == 0 {
                "Input".to_owned()
            } else {
                format!("Pass {index} of {}", self.passes)
            }
        );
        self.pictures.push(img);
        self.files.push(path);
        Ok(())
    }
}
