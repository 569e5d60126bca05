//! One owner of a cell-sorted state ([`SortedGrid`]): the lattice, its key pass
//! (`KeyMode::GridCell`), the sorter, the layout the state is gathered into and the search of the
//! sorted keys ([`CellSearch`], with its cell-start table where the lattice fits one). The
//! collision stage's lattices and the fluid each hold one, so the key, sort, gather and table
//! steps are written once.

use crate::error::Result;
use crate::gl::{
    Attachment, Context, Framebuffer, FullscreenPass, PassDraw, Texture, TextureFormat,
};
use crate::sim::collide::cells::{CellSearch, Lattice};
use crate::sim::state::{POSITION, STATIC, VELOCITY};
use crate::sort::{KeyMode, SortOptions, Sorter, Variant};

/// A lattice, its sort and the state gathered in its order, with its search where one reads it.
#[derive(Debug)]
pub struct SortedGrid {
    lattice: Lattice,
    sorter: Sorter,
    /// A view of the layout's position texture alone, where the owner gathers positions only
    /// ([`SortedGrid::sort_positions`]); dropped before the layout it views.
    positions: Option<Framebuffer>,
    /// The state in sorted order (position, velocity, static and what the owner adds).
    layout: Framebuffer,
    search: Option<CellSearch>,
}

/// How a [`SortedGrid`] sorts and what its layout holds.
#[derive(Debug)]
pub struct GridSpec<'a> {
    /// The network: the collision stage's (maybe packed), or the fluid's blocked one.
    pub variant: Variant,
    /// The sorter's options.
    pub options: SortOptions,
    /// The labels' prefix (`lattice`, `staggered`, `fluid`): `{name} position`, …,
    /// `{name} layout`.
    pub name: &'a str,
    /// The velocity texture's format (the simulation's).
    pub velocity_format: TextureFormat,
    /// Further textures of the layout (name, label, format), gathered after position,
    /// velocity and static.
    pub extra: &'a [(Attachment, &'a str, TextureFormat)],
    /// Whether a search of the sorted keys reads this lattice (builds the [`CellSearch`]).
    pub searched: bool,
    /// Whether the owner may gather positions alone ([`SortedGrid::sort_positions`]).
    pub positions_only: bool,
}

impl SortedGrid {
    /// The grid of `lattice` over a `size` state.
    pub fn new(ctx: &Context, lattice: Lattice, size: [u32; 2], spec: GridSpec) -> Result<Self> {
        let [w, h] = size;
        let name = spec.name;
        let texture =
            |what: &str, format| super::texture(ctx, &format!("{name} {what}"), w, h, format);
        let rgba = TextureFormat::Rgba32F;
        let mut layout = vec![
            (POSITION, texture("position", rgba)?),
            (VELOCITY, texture("velocity", spec.velocity_format)?),
            (STATIC, texture("static", rgba)?),
        ];
        for &(a, what, format) in spec.extra {
            layout.push((a, texture(what, format)?));
        }
        let search = match spec.searched {
            true => Some(CellSearch::new(ctx, lattice, size, spec.variant.packed())?),
            false => None,
        };
        // Without a search only the gathers read the sort: a blocked sort then leaves its
        // entries in its own layout for them (no unpack pass).
        let options = SortOptions {
            keep_blocked: spec.options.keep_blocked || search.is_none(),
            ..spec.options
        };
        let layout = Framebuffer::named(ctx, &format!("{name} layout"), layout)?;
        let positions = match spec.positions_only {
            true => Some(Framebuffer::views(
                ctx,
                &format!("{name} positions"),
                &[(&layout, 0)],
            )?),
            false => None,
        };
        Ok(SortedGrid {
            lattice,
            sorter: Sorter::new(ctx, spec.variant, w, h, options)?,
            positions,
            layout,
            search,
        })
    }

    /// The key pass's mode: the cell index in the lattice.
    pub fn mode(&self) -> KeyMode {
        self.lattice.mode()
    }

    /// Keys of `positions` (the first `count` entries) on the lattice and the full sort.
    pub fn sort_keys(&mut self, positions: &Texture, count: usize) -> Result<()> {
        self.sorter
            .write_keys(positions, count, &self.lattice.mode(), true)?;
        self.sorter.sort();
        Ok(())
    }

    /// Keys, sort, the gather of `sources` (as many as the layout holds; the first the
    /// positions) into the layout and the cell-start table.
    pub fn sort(
        &mut self,
        pass: &FullscreenPass,
        count: usize,
        sources: &[&Texture],
    ) -> Result<()> {
        self.sort_keys(sources[0], count)?;
        self.sorter.gather(sources, &self.layout)?;
        self.build_search(pass, None);
        Ok(())
    }

    /// Keys of `positions` (the first `count` entries), the sort and the gather of the positions
    /// alone into the layout (the layout's velocity and static keep what they held): for a
    /// lattice whose later passes read the rest through another sort
    /// ([`SortedGrid::sort_through`]).
    pub fn sort_positions(
        &mut self,
        pass: &FullscreenPass,
        count: usize,
        positions: &Texture,
    ) -> Result<()> {
        if self.positions.is_none() {
            return Err(crate::error::Error::InvalidInput(
                "this grid was built to gather the whole state".into(),
            ));
        }
        self.sort_keys(positions, count)?;
        let view = self.positions.as_ref().expect("checked above");
        self.sorter.gather(&[positions], view)?;
        self.build_search(pass, None);
        Ok(())
    }

    /// Like [`sort`](Self::sort), where `sources` are places in `first`'s layout
    /// (`sources[0]` its positions, which this grid's keys are taken from): the sources with
    /// bit k of `through` set are read at the place `first`'s sort gave each particle instead
    /// (textures of the state `first` sorted, [`Sorter::gather_through`]).
    pub fn sort_through(
        &mut self,
        pass: &FullscreenPass,
        count: usize,
        first: &SortedGrid,
        through: u32,
        sources: &[&Texture],
    ) -> Result<()> {
        self.sort_keys(sources[0], count)?;
        (self.sorter).gather_through(Some((&first.sorter, through)), sources, &self.layout)?;
        self.build_search(pass, None);
        Ok(())
    }

    /// The sorter (for passes that read its identifiers, [`Sorter::lookup_bindings`]).
    pub fn sorter(&self) -> &Sorter {
        &self.sorter
    }

    /// The cell-start table of `keys` (none: this grid's sorted keys), where this grid has a
    /// search. The sorted keys are asked for only then: a blocked sort that kept its layout
    /// writes them row-major (an unpack pass) on the first ask.
    fn build_search(&self, pass: &FullscreenPass, keys: Option<&Texture>) {
        if let Some(s) = &self.search {
            s.build(pass, keys.unwrap_or_else(|| self.sorter.keys()));
        }
    }

    /// The gather of `sources` into the layout in the order of `keys` (this grid's sorted keys,
    /// or entries of its layout sorted elsewhere), then the cell-start table of `keys`.
    pub fn gather_by(
        &self,
        pass: &FullscreenPass,
        keys: &Texture,
        sources: &[&Texture],
    ) -> Result<()> {
        self.sorter.gather_by(keys, sources, &self.layout)?;
        self.build_search(pass, Some(keys));
        Ok(())
    }

    /// Gathers further textures (spin, user states) in the order of the last sort into `dest`.
    pub fn gather(&self, sources: &[&Texture], dest: &Framebuffer) -> Result<()> {
        self.sorter.gather(sources, dest)
    }

    /// Gathers `sources` in the order of `keys` into `dest`.
    pub fn gather_extra_by(
        &self,
        keys: &Texture,
        sources: &[&Texture],
        dest: &Framebuffer,
    ) -> Result<()> {
        self.sorter.gather_by(keys, sources, dest)
    }

    /// The lattice.
    pub fn lattice(&self) -> Lattice {
        self.lattice
    }

    /// The sorted keys of the last full sort.
    pub fn keys(&self) -> &Texture {
        self.sorter.keys()
    }

    /// The state in the last sorted order.
    pub fn layout(&self) -> &Framebuffer {
        &self.layout
    }

    /// The state in the last sorted order, to hand a texture of it over
    /// ([`Framebuffer::exchange`]).
    pub fn layout_mut(&mut self) -> &mut Framebuffer {
        &mut self.layout
    }

    /// The search of the sorted keys, if this grid has one.
    pub fn search(&self) -> Option<&CellSearch> {
        self.search.as_ref()
    }

    /// The draws of the key pass, the sort and the gather, `times` a step, under the pass list
    /// lines `keys` and `sort` (the gather's is `gather`).
    pub fn sort_draws(&self, keys: &str, sort: &str, times: u64) -> Vec<PassDraw> {
        let mut out = vec![PassDraw::new(keys, Sorter::keys_program(), times)];
        for (program, n) in self.sorter.network_draws() {
            out.push(PassDraw::new(sort, program, n * times));
        }
        out.push(PassDraw::new("gather", Sorter::gather_program(), times));
        out
    }

    /// The table passes' draws, `times` a step, under the line `line` (none without a table).
    pub fn table_draws(&self, line: &str, times: u64) -> Vec<PassDraw> {
        (self.search.iter())
            .flat_map(|s| s.pass_draws(line, times))
            .collect()
    }
}
