//! The blocked sort's merge passes and their partition passes: the programs, the splits'
//! texture, and the passes' draws ([`crate::sort::blocked::merge_schedule`]).

use super::{log2, Blocked};
use crate::error::Result;
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, Program, Sampled, Texture, TextureDesc,
    TextureFormat, UniformList, FULLSCREEN_VERTEX,
};
use crate::sort::blocked::{partition_bits, BlockPass};

/// The splits of a partition pass and the programs that write and read them.
pub(super) struct Partition {
    /// One R32F texel a split (its texture inside).
    fb: Framebuffer,
    /// log2 of the split texture's width.
    log_w: u32,
    /// log2 of the outputs between splits.
    bits: u32,
    program: Program,
    /// The merge that searches between two splits.
    merge: Program,
}

/// The merge program and the partition passes' state, where `passes` (of 2^n entries, `bits`
/// a fragment, the blocks `w` wide) merge and partition.
pub(super) fn programs(
    ctx: &Context,
    passes: &[BlockPass],
    [n, bits, w]: [u32; 3],
    compact: bool,
) -> Result<(Option<Program>, Option<Partition>)> {
    let merge = match passes.iter().any(|p| p.merge.is_some()) {
        true => Some(merge_program(ctx, bits, compact, false)?),
        false => None,
    };
    let partition = match passes.iter().any(|p| p.partition.is_some()) {
        true => Some(Partition::new(ctx, n, bits, compact, w)?),
        false => None,
    };
    Ok((merge, partition))
}

/// The merge passes' program (`partitioned`: searching between the splits of a partition pass).
/// They read what the network or the last merge wrote: never ROW_CELLS (the first pass's input
/// format only).
fn merge_program(ctx: &Context, bits: u32, compact: bool, partitioned: bool) -> Result<Program> {
    let mut m: Defines = vec![("BITS".to_string(), bits.to_string())];
    if compact {
        m.push(("COMPACT".into(), "1".into()));
    }
    if partitioned {
        m.push(("PARTITIONED".into(), "1".into()));
    }
    Program::new(ctx, FULLSCREEN_VERTEX, "sort/merge.frag", &m)
}

impl Partition {
    /// The splits of 2^`n` entries, `bits` bits a fragment, in a texture `w` wide at most (the
    /// blocks texture's width).
    fn new(ctx: &Context, n: u32, bits: u32, compact: bool, w: u32) -> Result<Self> {
        let part = partition_bits(bits);
        let count = 1u32 << n.saturating_sub(part);
        let width = count.min(w);
        let texture = Texture::new(
            ctx,
            TextureDesc {
                width,
                height: count / width,
                format: TextureFormat::R32F,
                label: "blocked sort splits",
            },
        )?;
        let mut d: Defines = vec![("BITS".to_string(), bits.to_string())];
        if compact {
            d.push(("COMPACT".into(), "1".into()));
        }
        Ok(Partition {
            fb: Framebuffer::new(ctx, "blocked sort splits", vec![texture])?,
            log_w: log2(width),
            bits: part,
            program: Program::new(ctx, FULLSCREEN_VERTEX, "sort/merge_partition.frag", &d)?,
            merge: merge_program(ctx, bits, compact, true)?,
        })
    }
}

impl Blocked {
    /// `Some(r)` where pass `i` merges runs of 2^r entries.
    pub(in crate::sort::gpu) fn merge_run(&self, i: usize) -> Option<u32> {
        self.passes.get(i).and_then(|p| p.merge)
    }

    /// `Some(r)` where pass `i` is the partition pass of the merge of runs of 2^r entries.
    pub(in crate::sort::gpu) fn partition_run(&self, i: usize) -> Option<u32> {
        self.passes.get(i).and_then(|p| p.partition)
    }

    /// Whether merge pass `i` searches between the splits of the partition pass before it.
    pub(in crate::sort::gpu) fn partitioned(&self, i: usize) -> bool {
        let r = self.merge_run(i);
        r.is_some() && i > 0 && self.partition_run(i - 1) == r
    }

    /// log2 of the outputs between two splits of the partition passes (0: none).
    pub(in crate::sort::gpu) fn partition_bits(&self) -> u32 {
        self.partition.as_ref().map_or(0, |p| p.bits)
    }

    /// The framebuffer the partition passes write (for floors), where the schedule has any.
    pub(in crate::sort::gpu) fn partition_target(&self) -> Option<&Framebuffer> {
        self.partition.as_ref().map(|p| &p.fb)
    }

    /// The program name of pass `i` if it is a partition or a merge pass, for the pass list.
    pub(super) fn merge_program_name(&self, i: usize) -> Option<&str> {
        let p = &self.passes[i];
        match (&self.merge, &self.partition) {
            (_, Some(q)) if p.partition.is_some() => Some(q.program.name()),
            (_, Some(q)) if self.partitioned(i) => Some(q.merge.name()),
            (Some(m), _) if p.merge.is_some() => Some(m.name()),
            _ => None,
        }
    }

    /// Runs pass `i` if it is a partition or a merge pass (`true`), else nothing (`false`).
    pub(super) fn run_merge(&mut self, i: usize, fullscreen: &FullscreenPass) -> bool {
        let pass = &self.passes[i];
        if let (Some(r), Some(q)) = (pass.partition, &self.partition) {
            // The splits only: the entries stay where they are.
            let mut u = UniformList::new();
            u.i32("u_log_w", self.log_w as i32);
            u.i32("u_run_log", r as i32);
            u.i32("u_part_bits", q.bits as i32);
            u.i32("u_split_log_w", q.log_w as i32);
            let input = [("u_blocks", Sampled::from(&self.tex[self.front]))];
            fullscreen.draw(&q.program, &input, u.values(), &q.fb);
            return true;
        }
        if let (Some(r), Some(m)) = (pass.merge, &self.merge) {
            let mut u = UniformList::new();
            u.i32("u_log_w", self.log_w as i32);
            u.i32("u_run_log", r as i32);
            let blocks = Sampled::from(&self.tex[self.front]);
            match &self.partition {
                Some(q) if self.partitioned(i) => {
                    u.i32("u_part_bits", q.bits as i32);
                    u.i32("u_split_log_w", q.log_w as i32);
                    let input = [
                        ("u_blocks", blocks),
                        ("u_splits", q.fb.only_texture().into()),
                    ];
                    fullscreen.draw(&q.merge, &input, u.values(), &self.fbs[1 - self.front]);
                }
                _ => {
                    let input = [("u_blocks", blocks)];
                    fullscreen.draw(m, &input, u.values(), &self.fbs[1 - self.front]);
                }
            }
            self.front = 1 - self.front;
            return true;
        }
        false
    }
}
