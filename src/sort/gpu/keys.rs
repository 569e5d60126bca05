//! The key pass of the sorter (UberFlow §4.3.1): keys and identifiers written into the sort
//! texture, fresh or refreshed in place (Latta's sort spread over frames).

use super::{KeyMode, ProgramKey, Sorter};
use crate::error::{Error, Result};
use crate::gl::{Sampled, Texture, Uniform, FULLSCREEN_VERTEX};

impl Sorter {
    /// The key pass: computes keys and identifiers of the particles in `positions` (xyz, life)
    /// into the sort texture and restarts the pass sequence. `count` particles, row-major in the
    /// position texture; the rest of the sort texture is padding.
    pub fn write_keys(
        &mut self,
        positions: &Texture,
        count: usize,
        mode: &KeyMode,
        cull_dead: bool,
    ) -> Result<()> {
        self.write_keys_with(positions, None, count, mode, cull_dead, false)
    }

    /// [`write_keys`](Self::write_keys) (or with `refresh`, [`refresh_keys`](Self::refresh_keys))
    /// with the particles' static texture (birth time or phase, type, total life, random), which
    /// [`KeyMode::Age`] reads the total life from.
    pub fn write_keys_with_statics(
        &mut self,
        positions: &Texture,
        statics: &Texture,
        count: usize,
        mode: &KeyMode,
        cull_dead: bool,
        refresh: bool,
    ) -> Result<()> {
        if refresh {
            self.check_refresh()?;
            let next = self.next;
            self.write_keys_with(positions, Some(statics), count, mode, cull_dead, true)?;
            self.next = next;
            return Ok(());
        }
        self.write_keys_with(positions, Some(statics), count, mode, cull_dead, false)
    }

    /// The key pass, fresh or (`rekey`) refreshing the sorted entries in place.
    fn write_keys_with(
        &mut self,
        positions: &Texture,
        statics: Option<&Texture>,
        count: usize,
        mode: &KeyMode,
        cull_dead: bool,
        rekey: bool,
    ) -> Result<()> {
        if count > self.len() || count > positions.texels() {
            return Err(Error::InvalidInput(format!(
                "{count} particles do not fit a {}x{} sort texture",
                self.width, self.height
            )));
        }
        let grid = matches!(mode, KeyMode::GridCell { .. });
        let age = matches!(mode, KeyMode::Age { .. });
        let axis = matches!(mode, KeyMode::Axis { .. });
        if age && statics.is_none_or(|t| t.texels() < count) {
            return Err(Error::InvalidInput(
                "age keys read each particle's total life from its static texture: use \
                 write_keys_with_statics with a static texture of the state's size"
                    .into(),
            ));
        }
        let key = ProgramKey::Keys {
            grid,
            age,
            axis,
            rekey,
        };
        let mut extra = self.key_defines(grid, age, rekey);
        if axis {
            extra.push(("KEY_AXIS", "1"));
        }
        self.program(key, FULLSCREEN_VERTEX, super::pass_list::KEYS, &extra)?;
        let p = &self.programs[&key];
        let mut textures: Vec<(&str, Sampled)> = vec![("u_position", positions.into())];
        let int = |v: u32| Uniform::I32(v as i32);
        let mut per_frame = mode_uniforms(mode);
        per_frame.extend([
            ("u_state_width", int(positions.width())),
            ("u_count", int(count as u32)),
            ("u_sort_width", int(self.width)),
            ("u_cull_dead", int(cull_dead as u32)),
        ]);
        if let Some(t) = &self.id_table {
            textures.push(("u_id_table", t.into()));
            per_frame.push(("u_id_table_width", int(t.width())));
        }
        if rekey {
            // The last sort's order, row-major (unpacked here if the sort kept its layout).
            textures.push(("u_sorted", self.keys().into()));
        }
        if let (true, Some(t)) = (age, statics) {
            textures.push(("u_static", t.into()));
        }
        self.fullscreen
            .draw(p, &textures, &per_frame, self.state.back());
        // Each entry's position, and what else the key reads (the sorted entry it refreshes,
        // the static texel of an age key).
        let reads = 1 + rekey as u64 + (age && statics.is_some()) as u64;
        self.ctx.count_fetches(self.len() as u64 * reads);
        self.state.swap();
        self.row_major.set(true);
        self.next = 0;
        Ok(())
    }

    /// The key program's defines: refreshing, lattice or age keys, packed entries, identifier
    /// table.
    fn key_defines(&self, grid: bool, age: bool, rekey: bool) -> Vec<(&'static str, &'static str)> {
        let mut extra: Vec<(&'static str, &'static str)> = Vec::new();
        if rekey {
            extra.push(("REKEY", "1"));
        }
        if grid {
            extra.push(("KEY_GRID", "1"));
        }
        if age {
            extra.push(("KEY_AGE", "1"));
        }
        if self.variant.packed() {
            extra.push(("PACKED", "1"));
        }
        if self.id_table.is_some() {
            extra.push(("ID_TABLE", "1"));
        }
        extra
    }

    /// Latta's sort spread over frames (§3.4.4): recomputes the key of every entry from the new
    /// `positions` of its particle, keeping the order reached so far, and continues the pass
    /// sequence where it stopped. Plain identifiers only (not with the identifier table).
    pub fn refresh_keys(
        &mut self,
        positions: &Texture,
        count: usize,
        mode: &KeyMode,
        cull_dead: bool,
    ) -> Result<()> {
        self.check_refresh()?;
        let next = self.next;
        self.write_keys_with(positions, None, count, mode, cull_dead, true)?;
        self.next = next;
        Ok(())
    }

    fn check_refresh(&self) -> Result<()> {
        if self.id_table.is_some() {
            return Err(Error::InvalidInput(
                "refreshing keys in place needs plain identifiers, not the identifier table".into(),
            ));
        }
        Ok(())
    }
}

/// The key draw's uniforms for `mode`: the eye, the axis or the lattice change from frame to
/// frame, so they travel with the draw.
fn mode_uniforms(mode: &KeyMode) -> Vec<(&'static str, Uniform)> {
    let sign = |b: bool| Uniform::F32(if b { -1.0 } else { 1.0 });
    match *mode {
        KeyMode::ViewerDistance { eye, back_to_front } => vec![
            ("u_eye", Uniform::Vec3(eye)),
            ("u_direction", sign(back_to_front)),
        ],
        // Key = direction × m, where a smaller m is more on top (as a smaller distance is):
        // m = age for the youngest on top, -age for the oldest.
        KeyMode::Age {
            youngest_on_top,
            back_to_front,
        } => vec![
            ("u_direction", sign(back_to_front)),
            ("u_age_sign", sign(!youngest_on_top)),
        ],
        KeyMode::Axis { direction } => vec![("u_axis", Uniform::Vec3(direction))],
        KeyMode::GridCell {
            origin,
            spacing,
            dims,
        } => vec![
            ("u_grid_origin", Uniform::Vec3(origin)),
            ("u_grid_spacing", Uniform::F32(spacing)),
            ("u_grid_dims", Uniform::IVec3(dims.as_ivec3())),
        ],
    }
}
