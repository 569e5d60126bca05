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
    /// drawn apart, a frame's geometry after its background), where the others are passes of
    /// a chain.
    pub follow_ons: u64,
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
            passes: self.passes * k,
            bytes_written: self.bytes_written * k,
            points: self.points * k,
            vertices: self.vertices * k,
            uniform_uploads: self.uniform_uploads * k,
            fetches: self.fetches * k,
        }
    }

    /// These draws and `other`'s together.
    pub fn plus(self, other: DrawStats) -> Self {
        DrawStats {
            draws: self.draws + other.draws,
            follow_ons: self.follow_ons + other.follow_ons,
            passes: self.passes + other.passes,
            bytes_written: self.bytes_written + other.bytes_written,
            points: self.points + other.points,
            vertices: self.vertices + other.vertices,
            uniform_uploads: self.uniform_uploads + other.uniform_uploads,
            fetches: self.fetches + other.fetches,
        }
    }
}

impl Context {
    /// Counts one uniform upload (see [`DrawStats::uniform_uploads`]).
    pub(crate) fn count_upload(&self) {
        self.update_stats(|s| s.uniform_uploads += 1);
    }

    /// Counts one draw (see [`DrawStats`]).
    pub(crate) fn count_draw(
        &self,
        target: &super::Framebuffer,
        pass: bool,
        bytes: u64,
        (points, vertices): (u64, u64),
    ) {
        let follow_on = self.note_target(target.raw);
        self.update_stats(|s| {
            s.vertices += vertices;
            s.draws += 1;
            s.follow_ons += follow_on as u64;
            s.passes += pass as u64;
            s.bytes_written += bytes;
            s.points += points;
        });
    }

    /// Adds `n` to the texel fetches of [`DrawStats`]: a pass that knows what its program
    /// fetches declares it after drawing (for the cost model).
    pub fn count_fetches(&self, n: u64) {
        self.update_stats(|s| s.fetches += n);
    }
}
