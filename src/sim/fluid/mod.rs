//! Weakly compressible SPH (Monaghan 1992; Becker & Teschner 2007) over the cell-sorted state,
//! in fragment passes only (UberFlow §6: "any physical model that requires access to adjacent
//! particles"). A scene's `[fluid]` sets up its own exact neighbour search: a lattice of cell
//! h or 2h (`fluid.cell`) over `fluid.bounds`, searched by `glsl/collide/cells.glsl` (on cells
//! of h the trimmed walk `SEARCH_TRIM`: every particle of the cells within 2h of a particle; on
//! cells of 2h the 27 cells), each run of cells along x bounded by the cell-start table of
//! `src/sim/collide/cells.rs` or, for a lattice too large for it, a binary search of the sorted
//! keys; at most [`FLUID_SCAN`] per run; a search past it is flagged and counted, and `render`
//! warns.
//!
//! One step, after the integration pass (gravity, the colliders' response, positions moved):
//! keys, a full bitonic sort (or with `resort = "coherent"` a cheaper network for the nearly
//! sorted state, checked, with the full sort as fallback: src/sim/fluid/resort.rs) and the
//! gather of position, velocity and static in cell order, the cell-start table, a density pass
//! (`glsl/fluid/density.frag`: density and Tait pressure), a force pass
//! (`glsl/fluid/force.frag`: symmetric pressure force and Monaghan's artificial viscosity,
//! v += a dt, into the state, now in cell order) and the static texture copied in that order.
//!
//! Boundaries are the scene's colliders, whose response in the integration pass keeps particles
//! out; at plane colliders the fluid adds a wall treatment (`fluid.wall_correction`, on by
//! default): ghost particles (Colagrossi & Landrini 2003), the reflections of a particle's
//! neighbours and of itself in each plane closer than 2h, with their density and pressure and
//! their velocity mirrored (free slip) or, at a plane with `wall = "no_slip"`, reversed, count
//! in its density and forces. The wall then has the
//! density the kernel misses behind it and the pressure gradient of the fluid in front, and
//! pushes particles off before they reach it (`glsl/fluid/kernel.glsl`). Boxes, spheres and
//! the fields have the collider response alone.

mod resort;
mod stats;

use glam::Vec3;

use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, PingPong, Program, Texture, TextureDesc,
    TextureFormat, Uniform, UniformList, FULLSCREEN_VERTEX,
};
use crate::scene::{self, SceneFile};
use crate::sim::collide::cells::{
    partner_mask, partner_words, search_defines, search_words, table_line, CellSearch, PartnerWork,
};
use crate::sim::collide::grid::{GridSpec, SortedGrid};
use crate::sim::collide::tally::{self, TruncationTally};
use crate::sim::collide::Lattice;
use crate::sim::state::{POSITION, STATIC, VELOCITY};
use crate::sort::{SortOptions, Variant};

pub use resort::{coherent_block, coherent_network, out_of_order, resort_passes, ResortCounts};
pub use stats::FluidStats;

/// Most particles the fluid's search walks in a run of cells along x: at rest a run holds about
/// 3 (2h / Δx)³ on cells of 2h (three cells) and 5 (h / Δx)³ on cells of h (at most five), at
/// most 81 and 17 with the largest smoothing length validation allows.
pub const FLUID_SCAN: u32 = 128;

/// The fluid stage of a scene with `[fluid]`.
#[derive(Debug)]
pub struct Fluid {
    config: scene::Fluid,
    /// The lattice of cell h or 2h, its sort, the state in cell order (position, velocity, static)
    /// and its search, with the cell-start table where it fits.
    grid: SortedGrid,
    /// `resort = "coherent"`: the cheap network, its check and counts.
    coherent: Option<resort::CoherentSort>,
    /// Whether the last step's order came from the coherent network (else the full sort).
    coherent_last: bool,
    /// (density, pressure, neighbours within 2h, truncated search) in cell order.
    density: Framebuffer,
    density_pass: Program,
    force_pass: Program,
    place: Program,
    pass: FullscreenPass,
    tally: TruncationTally,
    width: u32,
    gravity: Vec3,
}

/// The lattice of the scene's `[fluid]` (which it has): cell h or 2h (`fluid.cell`) from the
/// lower corner of its bounds.
pub fn lattice_of(scene: &SceneFile) -> Lattice {
    Lattice::of_fluid(scene)
}

/// The passes of one fluid step, as `texflow scene passes` lists them; the lattice's cell is
/// `cell` h (1 or 2).
pub fn fluid_passes(walls: bool, coherent: Option<u32>, table: bool, cell: u32) -> Vec<String> {
    let cell = if cell == 1 { "h" } else { "2h" };
    let wall = if walls {
        ", and over their ghosts in the plane colliders closer than 2h"
    } else {
        ""
    };
    let mut out: Vec<String> = vec![
        format!("fluid keys: cell index in the lattice of cell {cell} (z, y, x)"),
        match coherent {
            None => "fluid sort: full blocked sort (exact (key, id) entries: a network \
                     pass, then merge passes)"
                .into(),
            Some(m) => format!(
                "fluid re-sort: blocks of {m} entries on our blocked sort, the blocks at \
                 offset {} merged (one pass), a check pass and its tally (one read-back); the \
                 full sort (keys again) where the check finds an entry out of order",
                m / 2
            ),
        },
        "gather position, velocity, static in cell order".into(),
    ];
    if table {
        out.push(table_line("fluid", ""));
    }
    out.extend([
        format!(
            "fluid density: ρ = m Σ W over the cells within 2h of each particle (cubic spline, \
             {}, at most {FLUID_SCAN} particles per run){wall}; Tait pressure p = B((ρ/ρ0)^γ − \
             1), at least 0",
            search_words(table)
        ),
        format!(
            "fluid force: symmetric pressure force and Monaghan's artificial viscosity over the \
             same search{}{wall}, v += a dt, positions copied",
            partner_words(PartnerWork::Forces)
        ),
        tally::pass_line("truncation tally: the particles whose search hit the bound"),
    ]);
    out
}

impl Fluid {
    /// The draws of one step, in the order of [`fluid_passes`], from the programs the stage
    /// built.
    pub(crate) fn pass_draws(&self) -> Vec<crate::gl::PassDraw> {
        use crate::gl::PassDraw;
        let mut out = self.grid.sort_draws("fluid keys", "fluid sort", 1);
        out.extend(self.grid.table_draws("fluid cell start", 1));
        out.extend([
            PassDraw::of("fluid density", &self.density_pass, 1),
            PassDraw::of("fluid force", &self.force_pass, 1),
            PassDraw::of("truncation tally", self.tally.program(), self.tally.draws()),
        ]);
        out
    }
}

fn texture(ctx: &Context, label: &str, size: [u32; 2], format: TextureFormat) -> Result<Texture> {
    Texture::new(
        ctx,
        TextureDesc {
            width: size[0],
            height: size[1],
            format,
            label,
        },
    )
}

impl Fluid {
    /// The stage of `scene` (which has `[fluid]`), its programs built with the simulation's
    /// `defines` (colliders, precision).
    pub fn new(
        ctx: &Context,
        scene: &SceneFile,
        defines: &Defines,
        velocity_format: TextureFormat,
    ) -> Result<Self> {
        let Some(config) = scene.fluid.clone() else {
            return Err(Error::InvalidInput(
                "the scene has no [fluid] section".into(),
            ));
        };
        let size = scene.particles.size;
        let lattice = lattice_of(scene);
        let mut d = search_defines(defines, &lattice, size);
        d.push(("EXACT_SCAN".into(), FLUID_SCAN.to_string()));
        if config.wall_correction {
            d.push(("WALLS".into(), "1".into()));
            // Bit k: plane collider k is a no-slip wall (glsl/fluid/kernel.glsl).
            let no_slip = (scene.colliders.plane.iter().enumerate())
                .filter(|(_, p)| p.wall == scene::Wall::NoSlip)
                .fold(0u32, |m, (k, _)| m | 1 << k);
            d.push(("NO_SLIP".into(), no_slip.to_string()));
        }
        let program = |f: &str| Program::new(ctx, FULLSCREEN_VERTEX, f, &d);
        let density = texture(ctx, "fluid density", size, TextureFormat::Rgba32F)?;
        let gravity =
            (scene.forces.gravity.iter()).fold(Vec3::ZERO, |a, g| a + Vec3::from(g.acceleration));
        let spec = GridSpec {
            // Our blocked network with exact (key, id) entries, one per texel: the layout
            // `glsl/collide/cells.glsl` searches without `PACKED_KEYS`.
            variant: Variant::Blocked,
            options: SortOptions::default(),
            name: "fluid",
            velocity_format,
            extra: &[],
            searched: true,
            positions_only: false,
        };
        Ok(Fluid {
            grid: SortedGrid::new(ctx, lattice, size, spec)?,
            coherent: coherent_block(&config, size)
                .map(|m| resort::CoherentSort::new(ctx, size, m))
                .transpose()?,
            coherent_last: false,
            density: Framebuffer::new(ctx, "fluid density", vec![density])?,
            density_pass: program("fluid/density.frag")?,
            force_pass: Program::new(
                ctx,
                FULLSCREEN_VERTEX,
                "fluid/force.frag",
                &partner_mask(&d, PartnerWork::Forces),
            )?,
            place: program("fluid/lattice.frag")?,
            pass: FullscreenPass::new(ctx)?,
            tally: TruncationTally::new(ctx, size)?,
            width: size[0],
            gravity,
            config,
        })
    }

    /// The scene's `[fluid]`.
    pub fn config(&self) -> &scene::Fluid {
        &self.config
    }

    /// The neighbour lattice (cell h).
    pub fn lattice(&self) -> Lattice {
        self.grid.lattice()
    }

    /// The neighbour search, with its cell-start table where the lattice fits one.
    pub fn search(&self) -> &CellSearch {
        self.grid.search().expect("the fluid builds its search")
    }

    /// Places every particle on the lattice of its initial box emitter (`glsl/fluid/lattice.frag`)
    /// into `state` (then swapped).
    pub fn place(&self, scene: &SceneFile, state: &mut PingPong) {
        let initial = &scene.emitters.initial;
        let dx = self.config.spacing;
        // Initial emitters take no curves (refused at their key): their values at t = 0.
        let (mut lattice_min, mut lattice_n, mut lattice_v) = (Vec::new(), Vec::new(), Vec::new());
        let (texels, kinds) = (
            state.width() as usize * state.height() as usize,
            initial.len().max(1),
        );
        for (k, e) in initial.iter().enumerate() {
            let size = Vec3::from(e.size);
            let lo = Vec3::from(e.center.at(0.0)) - 0.5 * size;
            let n = glam::UVec3::from(self.config.box_points(e.size));
            let v = Vec3::from(e.direction.at(0.0)).normalize_or_zero() * e.speed.at(0.0)[0];
            lattice_min.push(lo.extend(dx));
            // The layers this emitter's particles fill (texels of rank k modulo the emitters;
            // a partial fill is a lower layer): the hydrostatic start's column height.
            let count = scene::emitter_texels(texels as u64, kinds as u64, k as u64) as usize;
            let layer = (n.x as usize * n.z as usize).max(1);
            let layers = count.div_ceil(layer).min(n.y as usize);
            lattice_n.push([n.x as i32, n.y as i32, n.z as i32, layers as i32]);
            lattice_v.push(v.extend(0.0));
        }
        // Validation holds "hydrostatic" to gravity along −y: ρ0 |g| / B sets the squeeze.
        let compress = match self.config.initial {
            scene::Initial::Uniform => 0.0,
            scene::Initial::Hydrostatic => {
                self.config.rest_density * self.gravity.length() / self.config.stiffness()
            }
        };
        let uniforms = [
            ("u_width", Uniform::I32(self.width as i32)),
            ("u_emitters", Uniform::I32(initial.len().max(1) as i32)),
            ("u_lattice_min", Uniform::Vec4s(lattice_min.into())),
            ("u_lattice_n", Uniform::IVec4s(lattice_n.into())),
            ("u_lattice_v", Uniform::Vec4s(lattice_v.into())),
            ("u_compress", Uniform::F32(compress)),
            ("u_gamma", Uniform::F32(self.config.gamma)),
        ];
        self.pass.draw(&self.place, &[], &uniforms, state.back());
        state.swap();
    }

    /// The fluid's uniforms (the search's and the material's), for the draws of its passes.
    fn material(&self) -> Vec<(&'static str, Uniform)> {
        let f = &self.config;
        let mut out = self.search().uniforms();
        out.extend([
            ("u_h", Uniform::F32(f.h())),
            ("u_search_radius", Uniform::F32(2.0 * f.h())),
            ("u_mass", Uniform::F32(f.mass())),
            ("u_rest_density", Uniform::F32(f.rest_density)),
            ("u_stiffness", Uniform::F32(f.stiffness())),
            ("u_gamma", Uniform::F32(f.gamma)),
            ("u_alpha", Uniform::F32(f.viscosity)),
            ("u_sound", Uniform::F32(f.speed_of_sound)),
            ("u_gravity", Uniform::Vec3(self.gravity)),
        ]);
        out
    }

    /// One fluid step on the state after the integration pass: sort, gather, density, force
    /// into `state.back()` (then swapped); the statics in the new order are handed over
    /// ([`Framebuffer::exchange`]), not copied. `constants` are the
    /// run's uniforms (the colliders: the planes of the wall treatment) its passes read.
    pub fn run(
        &mut self,
        state: &mut PingPong,
        statics: &mut Framebuffer,
        dt: f32,
        constants: &UniformList,
    ) -> Result<()> {
        let count = self.width as usize * state.height() as usize;
        let front = state.front();
        let coherent = match &mut self.coherent {
            Some(c) => c.try_sort(front.texture(POSITION), count, &self.grid.mode())?,
            None => false,
        };
        if !coherent {
            self.grid.sort_keys(front.texture(POSITION), count)?;
        }
        self.coherent_last = coherent;
        let keys = self.sorted_keys();
        self.grid.gather_by(
            &self.pass,
            keys,
            &[
                front.texture(POSITION),
                front.texture(VELOCITY),
                statics.texture(STATIC),
            ],
        )?;
        let l = self.grid.layout();
        let p = &self.density_pass;
        let uniforms = constants.for_draw(p, self.material());
        let mut textures = self.search().textures(keys);
        textures.push(("u_position", l.texture(POSITION).into()));
        self.pass.draw(p, &textures, &uniforms, &self.density);
        self.tally.add_flags(self.density.only_texture(), 3, count);
        let p = &self.force_pass;
        let mut uniforms = self.material();
        uniforms.push(("u_dt", Uniform::F32(dt)));
        let uniforms = constants.for_draw(p, uniforms);
        let mut textures = self.search().textures(keys);
        textures.extend([
            ("u_position", l.texture(POSITION).into()),
            ("u_velocity", l.texture(VELOCITY).into()),
            ("u_density", self.density.only_texture().into()),
        ]);
        self.pass.draw(p, &textures, &uniforms, state.back());
        state.swap();
        statics.exchange(STATIC, self.grid.layout_mut(), STATIC)
    }

    /// The sorted entries of the last step (the coherent network's or the full sort's).
    pub(crate) fn sorted_keys(&self) -> &Texture {
        match &self.coherent {
            Some(c) if self.coherent_last => c.keys(),
            _ => self.grid.keys(),
        }
    }

    /// The last step's position, velocity and static in cell order.
    pub(crate) fn layout(&self) -> &Framebuffer {
        self.grid.layout()
    }

    /// Gathers `sources` (textures of the state's layout) in the last step's cell order into
    /// `dest`: the user states follow their particles (src/sim/particles/fluid.rs).
    pub(crate) fn gather_sorted(&self, sources: &[&Texture], dest: &Framebuffer) -> Result<()> {
        (self.grid).gather_extra_by(self.sorted_keys(), sources, dest)
    }

    /// Searches that walked a run of three cells past [`FLUID_SCAN`] particles (and so may have
    /// missed neighbours), summed over the run: one read-back of one texel.
    pub fn truncated_searches(&self) -> Result<u64> {
        self.tally.total()
    }

    /// How the coherent re-sort went over the run (zeros with the full sort).
    pub fn resort_counts(&self) -> ResortCounts {
        self.coherent
            .as_ref()
            .map_or(ResortCounts::default(), |c| c.counts())
    }

    /// The last step's gathered layout and density pass, read back (all in cell order).
    pub fn read_back(&self) -> Result<FluidReadback> {
        let l = self.grid.layout();
        Ok(FluidReadback {
            positions: l.texture(POSITION).read_f32()?,
            velocities: l.texture(VELOCITY).read_f32()?,
            density: self.density.only_texture().read_f32()?,
        })
    }

    /// The sum of the scene's gravities (m/s²), for the potential energy.
    pub fn gravity(&self) -> Vec3 {
        self.gravity
    }
}

/// The fluid stage's inputs and density pass of the last step, read back by
/// [`Fluid::read_back`]: RGBA texels, four floats per particle, in cell order.
#[derive(Debug, Clone)]
pub struct FluidReadback {
    /// Positions (xyz, life) after the integration pass, in cell order.
    pub positions: Vec<f32>,
    /// Velocities before the fluid's kick, in cell order.
    pub velocities: Vec<f32>,
    /// (density, pressure, neighbours within 2h, 1 if the search was truncated).
    pub density: Vec<f32>,
}
