//! UberFlow §4.3.1: the particle state gathered in sorted order, one MRT pass for all textures.

use super::Sorter;
use crate::error::{Error, Result};
use crate::gl::{Framebuffer, Program, Sampled, Texture, Uniform, FULLSCREEN_VERTEX};

impl Sorter {
    /// Gathers every texture of `source` into `dest` in sorted order: texel j of `dest` takes the
    /// state of the particle at sorted position j (UberFlow §4.3.1, one MRT pass for all).
    pub fn rearrange(&self, source: &Framebuffer, dest: &Framebuffer) -> Result<()> {
        let sources: Vec<&Texture> = source.textures().iter().collect();
        self.gather(&sources, dest)
    }

    /// Like [`rearrange`](Self::rearrange), from any textures of the state's size (the static
    /// texture lives in its own framebuffer, for instance).
    pub fn gather(&self, sources: &[&Texture], dest: &Framebuffer) -> Result<()> {
        self.gather_by(self.keys(), sources, dest)
    }

    /// Like [`gather`](Self::gather), in the order of `sorted`: entries of this sorter's layout
    /// sorted elsewhere (the fluid's coherent re-sort).
    pub fn gather_by(
        &self,
        sorted: &Texture,
        sources: &[&Texture],
        dest: &Framebuffer,
    ) -> Result<()> {
        let targets = sources.len();
        if targets == 0 || targets > 4 || dest.textures().len() != targets {
            return Err(Error::InvalidInput(
                "rearrangement takes 1 to 4 state textures of the same layout".into(),
            ));
        }
        let mut cache = self.rearrange.borrow_mut();
        if let std::collections::hash_map::Entry::Vacant(slot) = cache.entry(targets) {
            let mut d = self.defines();
            d.push(("TARGETS".into(), targets.to_string()));
            if self.variant.packed() {
                d.push(("PACKED".into(), "1".into()));
            }
            if self.id_table.is_some() {
                d.push(("ID_TABLE".into(), "1".into()));
            }
            slot.insert(Program::new(
                &self.ctx,
                FULLSCREEN_VERTEX,
                super::pass_list::REARRANGE,
                &d,
            )?);
        }
        let p = &cache[&targets];
        let uniforms = [
            ("u_sort_width", Uniform::I32(self.width as i32)),
            ("u_state_width", Uniform::I32(dest.width() as i32)),
        ];
        let names = ["u_state0", "u_state1", "u_state2", "u_state3"];
        let mut textures: Vec<(&str, Sampled)> = vec![("u_sorted", sorted.into())];
        textures.extend(names.into_iter().zip(sources.iter().map(|&t| t.into())));
        self.fullscreen.draw(p, &textures, &uniforms, dest);
        // The sorted identifier, then each source at it.
        let texels = dest.width() as u64 * dest.height() as u64;
        self.ctx.count_fetches(texels * (1 + sources.len() as u64));
        Ok(())
    }
}
