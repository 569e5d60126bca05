//! `render --video FILE --loop F`: a video that loops without a seam. The run's last F written
//! frames are cross-faded into its first F, and the video starts after those: it shows frames
//! F .. L-1 as written, then g_j = (1 - w_j) f_{L+j} + w_j f_j for j = 0 .. F-1 with
//! w_j = (j + 1) / (F + 1), L = written - F. Every cut is between neighbours: f_{L-1} to g_0
//! (mostly f_L, its successor), g_{F-1} (mostly f_{F-1}) to f_F at the loop's restart.

use texflow::output::VideoWriter;

/// The video of `render`, looped or not.
pub struct LoopedVideo {
    writer: VideoWriter,
    /// Frames cross-faded (0: a plain video).
    fade: u64,
    /// Frames the run writes.
    total: u64,
    /// The first `fade` frames, kept until the last ones arrive.
    head: Vec<image::RgbImage>,
    seen: u64,
}

impl LoopedVideo {
    /// Frames of the video for `written` frames of the run and `fade` cross-faded ones.
    pub fn length(written: u64, fade: u64) -> u64 {
        written - fade
    }

    /// Wraps `writer`, which must have been created for [`LoopedVideo::length`] frames.
    pub fn new(writer: VideoWriter, written: u64, fade: u64) -> Self {
        LoopedVideo {
            writer,
            fade,
            total: written,
            head: Vec::new(),
            seen: 0,
        }
    }

    /// Takes the next written frame.
    pub fn push(&mut self, image: &image::RgbImage) -> texflow::Result<()> {
        let i = self.seen;
        self.seen += 1;
        let tail_start = self.total - self.fade;
        if i < self.fade {
            self.head.push(image.clone());
            return Ok(());
        }
        if i < tail_start {
            return self.writer.push(image);
        }
        let j = (i - tail_start) as usize;
        let w = (j + 1) as f32 / (self.fade + 1) as f32;
        let Some(head) = self.head.get(j) else {
            return self.writer.push(image);
        };
        let mut mixed = image.clone();
        for (m, h) in mixed.pixels_mut().zip(head.pixels()) {
            for c in 0..3 {
                m[c] = ((1.0 - w) * m[c] as f32 + w * h[c] as f32).round() as u8;
            }
        }
        self.writer.push(&mixed)
    }

    /// Finishes the file (see [`VideoWriter::finish`]).
    pub fn finish(self) -> texflow::Result<std::path::PathBuf> {
        self.writer.finish()
    }
}

/// Refuses a `--loop` that leaves no frame of its own: the video needs more than 2 F written
/// frames.
pub fn check(fade: u64, written: u64) -> texflow::Result<()> {
    if fade > 0 && written <= 2 * fade {
        return Err(super::bad(format!(
            "--loop {fade} cross-fades {fade} frames but the run writes only {written}: write \
             more than {} frames (--frames, --start, --every), or fade fewer",
            2 * fade
        )));
    }
    Ok(())
}
