//! UberFlow §4.3.1: the particle state gathered in sorted order, one MRT pass for all textures.

use super::Sorter;
use crate::error::{Error, Result};
use crate::gl::{Defines, Framebuffer, Program, Sampled, Texture, Uniform, FULLSCREEN_VERTEX};

/// The samplers and uniforms of a pass that reads a sort's identifiers
/// ([`Sorter::lookup_bindings`]).
pub type LookupBindings<'a> = (
    Vec<(&'static str, Sampled<'a>)>,
    Vec<(&'static str, Uniform)>,
);

/// The gather's program key: (targets, reading the blocked layout, the targets read through
/// another sort, that sort's lookup defines).
pub(super) type GatherKey = (usize, bool, u32, Defines);

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
        self.gather_through(None, sources, dest)
    }

    /// Like [`gather`](Self::gather), where this sort ordered places in the layout another
    /// sort gathered (`first`: that sort and the mask of the sources to read through it):
    /// source k with bit k set is read at the place `first` gave the particle, the others at
    /// the identifier itself. The staggered lattice reads velocity and static this way from
    /// the state the first lattice's sort read, so that the first gathers positions only.
    /// `first` must be of this sort's variant and size (its entries may lie in another
    /// layout: blocked in place or row-major); otherwise nothing is drawn and an error says so.
    pub fn gather_through(
        &self,
        first: Option<(&Sorter, u32)>,
        sources: &[&Texture],
        dest: &Framebuffer,
    ) -> Result<()> {
        let in_place = self.sorted_in_place();
        let mut blocked = None;
        let mut textures: Vec<(&str, Sampled)> = Vec::new();
        let mut uniforms = vec![("u_state_width", Uniform::I32(dest.width() as i32))];
        if in_place {
            let b = (self.blocked.as_ref()).expect("a sort in place has a blocked network");
            let (blocks, d, log_w) = b.sorted_layout();
            blocked = Some(d);
            textures.push(("u_blocks", blocks.into()));
            uniforms.push(("u_log_w", Uniform::I32(log_w)));
        } else {
            textures.push(("u_sorted", self.keys().into()));
            uniforms.push(("u_sort_width", Uniform::I32(self.width as i32)));
        }
        let mut through = (0, Defines::new());
        if let Some((f, mask)) = first {
            if f.id_defines() != self.id_defines() || (f.width, f.len()) != (self.width, self.len())
            {
                return Err(Error::InvalidInput(
                    "a gather through another sort needs a sort of the same variant and size"
                        .into(),
                ));
            }
            through = (mask, f.lookup_defines());
            let (t, u) = f.lookup_bindings();
            textures.extend(t);
            uniforms.extend(u);
        }
        let mask = through.0;
        let p = self.gather_pass(sources, dest, blocked, through)?;
        self.draw_gather(&p, textures, sources, &uniforms, dest);
        // The lookup through the first sort, once a texel.
        if mask != 0 {
            self.ctx
                .count_fetches(dest.width() as u64 * dest.height() as u64);
        }
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
        let p = self.gather_pass(sources, dest, None, (0, Defines::new()))?;
        let uniforms = [
            ("u_sort_width", Uniform::I32(self.width as i32)),
            ("u_state_width", Uniform::I32(dest.width() as i32)),
        ];
        let entries = vec![("u_sorted", sorted.into())];
        self.draw_gather(&p, entries, sources, &uniforms, dest);
        Ok(())
    }

    /// The defines of a pass that reads this sort's identifiers by sorted position with
    /// `glsl/sort/first_id.glsl` (beside the identifier's own, [`Sorter::id_defines`]): the
    /// blocked layout's where the sort leaves its entries there, else none (the row-major
    /// texture).
    pub fn lookup_defines(&self) -> Defines {
        match (self.in_place, &self.blocked) {
            (true, Some(b)) => {
                let bits = b.sorted_layout().1.into_iter().find(|(k, _)| k == "BITS");
                let bits = bits.map_or_else(|| "4".to_string(), |(_, v)| v);
                vec![
                    ("FIRST_BLOCKED".into(), "1".into()),
                    ("FIRST_BITS".into(), bits),
                ]
            }
            _ => Defines::new(),
        }
    }

    /// The textures and uniforms of that lookup, where the last sort left its entries.
    pub fn lookup_bindings(&self) -> LookupBindings<'_> {
        match (self.in_place, &self.blocked) {
            (true, Some(b)) => {
                let (blocks, _, log_w) = b.sorted_layout();
                (
                    vec![("u_first_blocks", blocks.into())],
                    vec![("u_first_log_w", Uniform::I32(log_w))],
                )
            }
            _ => (
                vec![("u_first_sorted", self.keys().into())],
                vec![("u_first_sort_width", Uniform::I32(self.width as i32))],
            ),
        }
    }

    /// The defines of reading an identifier from an entry: the sort's precision, packed
    /// entries and the identifier table.
    pub fn id_defines(&self) -> Defines {
        let mut d = self.defines();
        if self.variant.packed() {
            d.push(("PACKED".into(), "1".into()));
        }
        if self.id_table.is_some() {
            d.push(("ID_TABLE".into(), "1".into()));
        }
        d
    }

    /// The gather's program for `sources` into `dest`; `blocked`: the defines of the blocked
    /// layout it reads the entries from (else the row-major texture); `through`: the mask of
    /// the sources read through another sort, and that sort's lookup defines.
    fn gather_pass(
        &self,
        sources: &[&Texture],
        dest: &Framebuffer,
        blocked: Option<Defines>,
        (through, lookup): (u32, Defines),
    ) -> Result<std::cell::Ref<'_, Program>> {
        let targets = sources.len();
        if targets == 0 || targets > 4 || dest.attachments() != targets {
            return Err(Error::InvalidInput(
                "rearrangement takes 1 to 4 state textures of the same layout".into(),
            ));
        }
        let key: GatherKey = (targets, blocked.is_some(), through, lookup.clone());
        let mut cache = self.rearrange.borrow_mut();
        if let std::collections::hash_map::Entry::Vacant(slot) = cache.entry(key.clone()) {
            let mut d = self.id_defines();
            d.push(("TARGETS".into(), targets.to_string()));
            if let Some(b) = blocked {
                d.push(("BLOCKED".into(), "1".into()));
                d.extend(b);
            }
            if through != 0 {
                d.push(("THROUGH".into(), through.to_string()));
                d.extend(lookup);
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

    fn draw_gather<'a>(
        &self,
        p: &Program,
        mut textures: Vec<(&'a str, Sampled<'a>)>,
        sources: &[&'a Texture],
        uniforms: &[(&str, Uniform)],
        dest: &Framebuffer,
    ) {
        let names = ["u_state0", "u_state1", "u_state2", "u_state3"];
        textures.extend(names.into_iter().zip(sources.iter().map(|&t| t.into())));
        self.fullscreen.draw(p, &textures, uniforms, dest);
        // The sorted identifier, then each source at it.
        let texels = dest.width() as u64 * dest.height() as u64;
        self.ctx.count_fetches(texels * (1 + sources.len() as u64));
    }
}
