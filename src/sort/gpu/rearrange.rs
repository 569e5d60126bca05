//! UberFlow §4.3.1: the particle state gathered in sorted order, one MRT pass for all textures.

use super::Sorter;
use crate::error::{Error, Result};
use crate::gl::{Defines, Framebuffer, Program, Sampled, Texture, Uniform, FULLSCREEN_VERTEX};

impl Sorter {
    /// Gathers every texture of `source` into `dest` in sorted order: texel j of `dest` takes the
    /// state of the particle at sorted position j (UberFlow §4.3.1, one MRT pass for all).
    pub fn rearrange(&self, source: &Framebuffer, dest: &Framebuffer) -> Result<()> {
        let sources: Vec<&Texture> = source.textures().iter().collect();
        self.gather(&sources, dest)
    }

    /// Like [`rearrange`](Self::rearrange), from any textures of the state's size (the static
    /// texture lives in its own framebuffer, for instance). A blocked sort that kept its layout
    /// is read there ([`SortOptions::keep_blocked`](super::SortOptions)).
    pub fn gather(&self, sources: &[&Texture], dest: &Framebuffer) -> Result<()> {
        if !self.sorted_in_place() {
            return self.gather_by(self.keys(), sources, dest);
        }
        let b = self
            .blocked
            .as_ref()
            .expect("a sort in place has a blocked network");
        let (blocks, defines, log_w) = b.sorted_layout();
        let p = self.gather_pass(sources, dest, Some(defines))?;
        let uniforms = [
            ("u_log_w", Uniform::I32(log_w)),
            ("u_state_width", Uniform::I32(dest.width() as i32)),
        ];
        self.draw_gather(&p, ("u_blocks", blocks.into()), sources, &uniforms, dest);
        Ok(())
    }

    /// Like [`gather`](Self::gather), in the order of `sorted`: row-major entries of this
    /// sorter's layout sorted elsewhere (the fluid's coherent re-sort), or its own
    /// ([`keys`](Self::keys)).
    pub fn gather_by(
        &self,
        sorted: &Texture,
        sources: &[&Texture],
        dest: &Framebuffer,
    ) -> Result<()> {
        let p = self.gather_pass(sources, dest, None)?;
        let uniforms = [
            ("u_sort_width", Uniform::I32(self.width as i32)),
            ("u_state_width", Uniform::I32(dest.width() as i32)),
        ];
        self.draw_gather(&p, ("u_sorted", sorted.into()), sources, &uniforms, dest);
        Ok(())
    }

    /// The gather's program for `sources` into `dest`; `blocked`: the defines of the blocked
    /// layout it reads the entries from (else the row-major texture).
    fn gather_pass(
        &self,
        sources: &[&Texture],
        dest: &Framebuffer,
        blocked: Option<Defines>,
    ) -> Result<std::cell::Ref<'_, Program>> {
        let targets = sources.len();
        if targets == 0 || targets > 4 || dest.textures().len() != targets {
            return Err(Error::InvalidInput(
                "rearrangement takes 1 to 4 state textures of the same layout".into(),
            ));
        }
        let key = (targets, blocked.is_some());
        let mut cache = self.rearrange.borrow_mut();
        if let std::collections::hash_map::Entry::Vacant(slot) = cache.entry(key) {
            let mut d = self.defines();
            d.push(("TARGETS".into(), targets.to_string()));
            if self.variant.packed() {
                d.push(("PACKED".into(), "1".into()));
            }
            if self.id_table.is_some() {
                d.push(("ID_TABLE".into(), "1".into()));
            }
            if let Some(b) = blocked {
                d.push(("BLOCKED".into(), "1".into()));
                d.extend(b);
            }
            slot.insert(Program::new(
                &self.ctx,
                FULLSCREEN_VERTEX,
                super::pass_list::REARRANGE,
                &d,
            )?);
        }
        drop(cache);
        Ok(std::cell::Ref::map(self.rearrange.borrow(), |c| &c[&key]))
    }

    fn draw_gather(
        &self,
        p: &Program,
        entries: (&str, Sampled),
        sources: &[&Texture],
        uniforms: &[(&str, Uniform)],
        dest: &Framebuffer,
    ) {
        let names = ["u_state0", "u_state1", "u_state2", "u_state3"];
        let mut textures: Vec<(&str, Sampled)> = vec![entries];
        textures.extend(names.into_iter().zip(sources.iter().map(|&t| t.into())));
        self.fullscreen.draw(p, &textures, uniforms, dest);
        // The sorted identifier, then each source at it.
        let texels = dest.width() as u64 * dest.height() as u64;
        self.ctx.count_fetches(texels * (1 + sources.len() as u64));
    }
}
