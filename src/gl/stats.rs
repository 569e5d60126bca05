//! What draws did, counted by the GL layer: passes, bytes written and points, for the
//! benchmarks' floors and the cost model.

use super::Context;

/// What a sequence of draws did: how many, and the bytes their fragments wrote into colour
/// attachments (full-screen and rectangle passes: the viewport's texels times the bytes per
/// texel of every attachment; point draws count as draws without bytes, their coverage being
/// unknown to the GL layer).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct DrawStats {
    /// Draw calls (passes).
    pub draws: u64,
    /// Of those, the draws into the framebuffer that the draw counted before drew into: they
    /// wait on no other target's writes (the slices of a lit render's light or eye passes
    /// drawn apart, a frame's geometry after its background); [`DrawStats::chained`] counts
    /// the passes of a chain.
    pub follow_ons: u64,
    /// Of those, the draws that wait on no earlier draw counted with them: neither the first,
    /// nor a follow-on, nor reading a texture an earlier one wrote, nor writing one an earlier
    /// one read (the births' draws into the static and the state textures; a fetch floor's
    /// passes). A GPU may run them beside the draws before; the others of a phase's draws are
    /// a chain, each waiting on the one before.
    pub concurrent: u64,
    /// Of those, triangle draws over a rectangle of the target (full-screen passes).
    pub passes: u64,
    /// Bytes the triangle draws wrote into colour attachments.
    pub bytes_written: u64,
    /// Vertices of the point draws (particles drawn as points or sprites).
    pub points: u64,
    /// Vertices of every draw, whatever they make (points, triangles, lines).
    pub vertices: u64,
    /// Uniform uploads (one `glUniform*` call each, arrays counting once): the values given that
    /// the program did not hold already (all of them with the uniform cache off).
    pub uniform_uploads: u64,
    /// Texels of colour attachments cleared (`Framebuffer::clear`: its size times its
    /// attachments): a render pass clears its frame first.
    pub cleared: u64,
    /// Texel fetches that the passes declared ([`Context::count_fetches`](super::Context::count_fetches)):
    /// the sorts' passes and gathers, which know what their programs fetch; 0 for the others.
    pub fetches: u64,
}

impl DrawStats {
    /// `k` runs of these draws.
    pub fn times(self, k: u64) -> Self {
        DrawStats {
            draws: self.draws * k,
            follow_ons: self.follow_ons * k,
            concurrent: self.concurrent * k,
            passes: self.passes * k,
            bytes_written: self.bytes_written * k,
            points: self.points * k,
            vertices: self.vertices * k,
            uniform_uploads: self.uniform_uploads * k,
            cleared: self.cleared * k,
            fetches: self.fetches * k,
        }
    }

    /// The draws that wait on the draws before them: neither follow-ons nor concurrent (the
    /// first draw counted is one).
    pub fn chained(&self) -> u64 {
        self.draws
            .saturating_sub(self.follow_ons)
            .saturating_sub(self.concurrent)
    }

    /// These draws and `other`'s together.
    pub fn plus(self, other: DrawStats) -> Self {
        DrawStats {
            draws: self.draws + other.draws,
            follow_ons: self.follow_ons + other.follow_ons,
            concurrent: self.concurrent + other.concurrent,
            passes: self.passes + other.passes,
            bytes_written: self.bytes_written + other.bytes_written,
            points: self.points + other.points,
            vertices: self.vertices + other.vertices,
            uniform_uploads: self.uniform_uploads + other.uniform_uploads,
            cleared: self.cleared + other.cleared,
            fetches: self.fetches + other.fetches,
        }
    }
}

/// A texture a draw reads, by sampler name (as [`Draw::textures`](super::Draw::textures)
/// lists them).
type Read<'a> = (&'a str, super::Sampled<'a>);

/// What a draw waits on, among the draws counted with it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Wait {
    /// The draws before it: the first draw, or one that reads what an earlier one wrote or
    /// writes what an earlier one read (a pass of a chain).
    Before,
    /// The draw before it only, into the same framebuffer (a follow-on).
    FollowOn,
    /// None of them.
    None,
}

/// What the draws since the counts were last taken drew into and read: whether the next one
/// waits on them.
#[derive(Debug, Default)]
pub(super) struct Hazards {
    /// The framebuffer the last draw drew into.
    last: Option<glow::Framebuffer>,
    /// The textures drawn into.
    written: Vec<glow::Texture>,
    /// The textures read.
    read: Vec<glow::Texture>,
}

impl Hazards {
    /// Notes a draw into `target` reading `reads`: what it waits on.
    pub(super) fn note(&mut self, target: &super::Framebuffer, reads: &[Read<'_>]) -> Wait {
        let wait = match self.last.replace(target.raw) {
            None => Wait::Before,
            Some(last) if last == target.raw => Wait::FollowOn,
            Some(_) => {
                let reads_written = reads.iter().any(|(_, t)| self.written.contains(&t.raw()));
                let writes_read = target.writes.iter().any(|t| self.read.contains(t));
                match reads_written || writes_read {
                    true => Wait::Before,
                    false => Wait::None,
                }
            }
        };
        for t in &target.writes {
            if !self.written.contains(t) {
                self.written.push(*t);
            }
        }
        for t in reads.iter().map(|(_, t)| t.raw()) {
            if !self.read.contains(&t) {
                self.read.push(t);
            }
        }
        wait
    }
}

impl Context {
    /// Changes the draw counts ([`DrawStats`]).
    fn update_stats(&self, f: impl FnOnce(&mut DrawStats)) {
        let stats = self.counts().0;
        let mut s = stats.get();
        f(&mut s);
        stats.set(s);
    }

    /// Counts one uniform upload (see [`DrawStats::uniform_uploads`]).
    pub(crate) fn count_upload(&self) {
        self.update_stats(|s| s.uniform_uploads += 1);
    }

    /// Counts one draw into `target` reading `reads` (see [`DrawStats`]).
    pub(crate) fn count_draw(
        &self,
        (target, reads): (&super::Framebuffer, &[Read<'_>]),
        pass: bool,
        bytes: u64,
        (points, vertices): (u64, u64),
    ) {
        let wait = self.counts().1.borrow_mut().note(target, reads);
        self.update_stats(|s| {
            s.vertices += vertices;
            s.draws += 1;
            s.follow_ons += (wait == Wait::FollowOn) as u64;
            s.concurrent += (wait == Wait::None) as u64;
            s.passes += pass as u64;
            s.bytes_written += bytes;
            s.points += points;
        });
    }

    /// Counts `texels` cleared (see [`DrawStats::cleared`]).
    pub(crate) fn count_clear(&self, texels: u64) {
        self.update_stats(|s| s.cleared += texels);
    }

    /// Adds `n` to the texel fetches of [`DrawStats`]: a pass that knows what its program
    /// fetches declares it after drawing (for the cost model).
    pub fn count_fetches(&self, n: u64) {
        self.update_stats(|s| s.fetches += n);
    }
}
