//! Collisions between particles as UberFlow does them (§4.3-4.5): every step, after the
//! collisionless motion, the particles are sorted by the index of their cell in a lattice of mesh
//! size g0 (cells enumerated z, y, x), the state is gathered in that order, each particle looks
//! for its closest partner among `neighbours` particles to each side in its row, and a response
//! pass backs colliding spheres up to first contact and exchanges momentum. With the staggered
//! lattice (Fig. 3) the state is sorted a second time on a lattice shifted by g0/2 and the closer
//! partner of the two detections wins. Boundary conditions (colliders, §4.6) follow in the same
//! response pass.
//!
//! Pairing is made symmetric per lattice: a partner counts only if it chose this particle too
//! (`glsl/collide/mutual.frag`), so both sides of a pair apply opposite impulses. Across the two
//! lattices a particle may still take a partner from one lattice while that partner takes a closer
//! one from the other; the collision statistics of `report::collide_stats` count these conflicts.
//! The response (`glsl/collide/pair.glsl`) also separates what still overlaps along the line of
//! centres, mass-weighted, so that a resting pile settles instead of sinking into itself.
//!
//! Beyond the paper, `collisions.detection = "exact"` finds every pair closer than 2r (up to
//! [`EXACT_SCAN`] particles in a run of three cells): per iteration a full sort, then a count
//! pass and a response pass that each walk the 27 cells around a particle, each run of three
//! cells bounded by a cell-start table written after the sort (`cells.rs`,
//! `glsl/collide/cells.glsl`). The momentum exchange is applied to
//! mutual closest pairs (weight 1, two-body collisions: momentum conserved, energy kept at
//! e = 1); the separation of overlaps to every partner, weighted 1 / max(n_i, n_j). Every
//! iteration sorts again, so each one searches the cells the particles are in now.
//!
//! The statistics themselves (what a step's detection found against the true pairs) are measured
//! there, from [`CollisionStage::read_back`]: this module only runs the passes.

use crate::error::{Error, Result};
use crate::gl::{
    Attachment, Context, Defines, Framebuffer, FullscreenPass, PingPong, Program, Sampled, Texture,
    TextureDesc, TextureFormat, Uniform, UniformList, FULLSCREEN_VERTEX,
};
use crate::scene::{self, SceneFile};
use crate::sim::state::{POSITION, STATIC, VELOCITY};
use crate::sort::SortOptions;

mod carry;
pub mod cells;
mod census;
mod exact;
pub mod grid;
mod lattices;
mod neighbours;
mod pass_list;
pub(crate) mod tally;
pub mod walk_order;

pub use carry::carry_passes;
pub(crate) use carry::exchange_defines;
pub use cells::{CellTables, Lattice};
pub use census::PairCensus;
pub use lattices::reads_through_first;
pub use neighbours::{check_pair_forces, neighbour_passes, NeighbourReadback};
pub use pass_list::{exact_passes, uberflow_sort};

/// The staggered lattice's layout: the first lattice's detection, gathered along with the state
/// (read by the response as `u_partner2`).
const FIRST_PARTNER: Attachment = Attachment::named("first partner");
/// The exact count pass's outputs: (partners, truncated, closest, its distance); the sum of the
/// separations with every partner; the same sum with the closest partner's exchange in its place.
const PARTNERS: Attachment = Attachment::named("partners");
const SEPARATION: Attachment = Attachment::named("separation");
const EXCHANGED: Attachment = Attachment::named("separation with the exchange");

/// Most neighbours per side of UberFlow's detection (the scene's bound).
pub use crate::scene::MAX_NEIGHBOURS;

/// One lattice's sorted grid and detection output.
#[derive(Debug)]
struct Grid {
    /// The lattice, its sort, the state in its sorted order (position, velocity, static and, for
    /// the staggered lattice, the first lattice's detection, gathered along) and its search.
    sorted: grid::SortedGrid,
    /// Detection output before the mutual check: (partner or -1, distance), RG32F.
    raw: Framebuffer,
    /// Detection output after the mutual check: (partner or -1, distance), RG32F (8 bytes a
    /// particle: the response reads no more, and the staggered layout gathers it along).
    partner: Framebuffer,
    /// Spinning spheres: the spin (angular velocity, angle) in this lattice's sorted order.
    spin: Option<Framebuffer>,
}

/// The collision stage of a scene.
#[derive(Debug)]
pub struct CollisionStage {
    ctx: Context,
    config: scene::Collisions,
    first: Grid,
    second: Option<Grid>,
    passes: Passes,
    /// The dem response and the pair forces (`neighbours.rs`), if the scene has either.
    neighbours: Option<neighbours::Neighbours>,
    copy: Program,
    pass: FullscreenPass,
    width: u32,
    dt: f32,
    /// Exact mode: read back each iteration's detection into `recorded`.
    record: bool,
    recorded: Vec<Readback>,
    /// Exact mode: searches that hit their bound, counted over the run on the GPU.
    tally: Option<tally::TruncationTally>,
    /// The user states carried along the sorts, and their exchange (`carry.rs`).
    carry: Option<carry::Carry>,
    /// The first lattice gathers positions alone; the staggered one reads the rest through
    /// both sorts ([`reads_through_first`], `lattices.rs`).
    through: bool,
}

/// The programs of one detection mode.
#[derive(Debug)]
enum Passes {
    /// UberFlow §4.4: closest of k neighbours in the row, mutual check, one partner.
    Uberflow {
        detect: Program,
        mutual: Program,
        /// The first lattice's mutual check where it names partners by their place in the
        /// state the first sort read ([`reads_through_first`]).
        mutual_first: Option<Box<Program>>,
        response: Program,
    },
    /// Every partner in the 27 cells around each particle: a count pass, then the response.
    Exact {
        counts: Framebuffer,
        count: Program,
        response: Program,
    },
}

/// Most particles the exact detection walks in a run of three cells along x (its stated
/// density limit: validation refuses a cell whose runs could hold more spheres that do not
/// overlap; past it, `collide-stats` counts the run as truncated).
pub use crate::scene::EXACT_SCAN;

fn texture(ctx: &Context, label: &str, w: u32, h: u32, format: TextureFormat) -> Result<Texture> {
    Texture::new(
        ctx,
        TextureDesc {
            width: w,
            height: h,
            format,
            label,
        },
    )
}

/// A framebuffer of one RGBA32F texture of `size`, both labelled `label`.
fn single_target(ctx: &Context, label: &str, size: [u32; 2]) -> Result<Framebuffer> {
    single_target_of(ctx, label, size, TextureFormat::Rgba32F)
}

/// A framebuffer of one texture of `format` and `size`, both labelled `label`.
fn single_target_of(
    ctx: &Context,
    label: &str,
    [w, h]: [u32; 2],
    format: TextureFormat,
) -> Result<Framebuffer> {
    let t = texture(ctx, label, w, h, format)?;
    Framebuffer::new(ctx, label, vec![t])
}

/// The options of a lattice's collision sort (the first, or the `staggered` one): rows only
/// where the scene asks and the detection allows, and the lattice's cell count, so that a
/// rows-only blocked sort takes 4-byte exact entries where they hold every cell
/// ([`SortOptions::row_cells`]).
pub fn sort_options(config: &scene::Collisions, staggered: bool) -> SortOptions {
    let exact = config.detection == scene::Detection::Exact;
    SortOptions {
        rows: if exact { None } else { config.rows_only },
        cell_keys: Some(Lattice::of(config, staggered).cells()),
        ..Default::default()
    }
}

impl Grid {
    /// The first lattice's sort, layout and detection target, or (`staggered`) the second's,
    /// whose layout also takes the first lattice's detection along.
    fn new(
        ctx: &Context,
        config: &scene::Collisions,
        size: [u32; 2],
        velocity_format: TextureFormat,
        staggered: bool,
        positions_only: bool,
    ) -> Result<Grid> {
        let lattice = Lattice::of(config, staggered);
        let cells = lattice.dims.x as u64 * lattice.dims.y as u64 * lattice.dims.z as u64;
        if cells > 1 << 24 {
            return Err(Error::InvalidInput(format!(
                "the collision lattice has {cells} cells; cell keys are exact floats only up \
                 to 2^24: use a larger cell or smaller bounds"
            )));
        }
        let name = if staggered { "staggered" } else { "lattice" };
        // The spin in a framebuffer of its own: a gather takes at most four textures.
        let spin = match config.spin {
            true => Some(single_target(ctx, &format!("{name} spin"), size)?),
            false => None,
        };
        let options = sort_options(config, staggered);
        let exact = config.detection == scene::Detection::Exact;
        let rg = TextureFormat::Rg32F;
        let spec = grid::GridSpec {
            variant: config.sort.variant(),
            options,
            name,
            velocity_format,
            extra: if staggered {
                &[(FIRST_PARTNER, "first partner", rg)]
            } else {
                &[]
            },
            searched: exact && !staggered,
            positions_only,
        };
        Ok(Grid {
            sorted: grid::SortedGrid::new(ctx, lattice, size, spec)?,
            spin,
            raw: single_target_of(ctx, &format!("{name} detection"), size, rg)?,
            partner: single_target_of(ctx, &format!("{name} partner"), size, rg)?,
        })
    }
}

impl Passes {
    /// The programs and the intermediate target of the exact detection, or of UberFlow's;
    /// `first_lookup`: the defines of the first sort's lookup where the first lattice's mutual
    /// check names partners through it.
    fn new(
        ctx: &Context,
        exact: bool,
        size: [u32; 2],
        d: &Defines,
        first_lookup: Option<Defines>,
    ) -> Result<Self> {
        let program = |fragment: &str| Program::new(ctx, FULLSCREEN_VERTEX, fragment, d);
        let [w, h] = size;
        // The count pass takes the particles in the walk's order, and the response reads it.
        let walk = walk_order::walk_defines(d, size);
        let walked = |fragment: &str| Program::new(ctx, FULLSCREEN_VERTEX, fragment, &walk);
        Ok(if exact {
            Passes::Exact {
                counts: Framebuffer::named(
                    ctx,
                    "partner counts",
                    [PARTNERS, SEPARATION, EXCHANGED]
                        .into_iter()
                        .map(|a| Ok((a, texture(ctx, a.name(), w, h, TextureFormat::Rgba32F)?)))
                        .collect::<Result<_>>()?,
                )?,
                count: Program::new(
                    ctx,
                    FULLSCREEN_VERTEX,
                    "collide/exact_count.frag",
                    &cells::partner_mask(&walk, cells::PartnerWork::Contacts),
                )?,
                response: walked("collide/exact_response.frag")?,
            }
        } else {
            Passes::Uberflow {
                detect: program("collide/detect.frag")?,
                mutual: program("collide/mutual.frag")?,
                mutual_first: match first_lookup {
                    Some(lookup) => {
                        let mut d = d.clone();
                        d.push(("FIRST_ID".into(), "1".into()));
                        d.extend(lookup);
                        let p = Program::new(ctx, FULLSCREEN_VERTEX, "collide/mutual.frag", &d)?;
                        Some(Box::new(p))
                    }
                    None => None,
                },
                response: program("collide/response.frag")?,
            }
        })
    }
}

impl CollisionStage {
    /// Builds the stage for `scene` (which has a `[collisions]` section); `defines` are the
    /// simulation's, so the response pass applies the same colliders and precision.
    pub fn new(
        ctx: &Context,
        scene: &SceneFile,
        defines: &Defines,
        velocity_format: TextureFormat,
    ) -> Result<Self> {
        let Some(config) = scene.collisions.clone() else {
            return Err(Error::InvalidInput(
                "the scene has no [collisions] section".into(),
            ));
        };
        let size = scene.particles.size;
        let exact = config.detection == scene::Detection::Exact;
        let defines = &exact::search_layout(defines, &config, size);
        let neighbours = neighbours::Neighbours::new(ctx, scene, defines)?;
        let through = reads_through_first(config.staggered, exact, neighbours.is_some());
        let first = Grid::new(ctx, &config, size, velocity_format, false, through)?;
        let second = if config.staggered && !exact {
            Some(Grid::new(ctx, &config, size, velocity_format, true, false)?)
        } else {
            None
        };
        let d = exact::stage_defines(defines, second.is_some());
        let first_lookup = through.then(|| {
            let sorter = first.sorted.sorter();
            let mut lookup = sorter.id_defines();
            lookup.extend(sorter.lookup_defines());
            lookup
        });
        let passes = Passes::new(ctx, exact, size, &d, first_lookup)?;
        Ok(CollisionStage {
            carry: None,
            through,
            passes,
            neighbours,
            copy: Program::new(ctx, FULLSCREEN_VERTEX, "collide/copy.frag", &d)?,
            pass: FullscreenPass::new(ctx)?,
            ctx: ctx.clone(),
            config,
            first,
            second,
            width: size[0],
            dt: scene.time.dt,
            record: false,
            recorded: Vec::new(),
            tally: if exact {
                Some(tally::TruncationTally::new(ctx, size)?)
            } else {
                None
            },
        })
    }

    /// Exact searches that walked a run of three cells past [`EXACT_SCAN`] particles (and so
    /// may have missed partners), summed over every step and iteration so far: one read-back of
    /// one texel, for the end of a run. 0 in UberFlow's mode, whose search has no such bound.
    pub fn truncated_searches(&self) -> Result<u64> {
        self.tally.as_ref().map_or(Ok(0), |t| t.total())
    }

    /// The stage's configuration.
    pub fn config(&self) -> &scene::Collisions {
        &self.config
    }

    /// The first lattice and, with the staggered grid, the second.
    pub fn lattices(&self) -> (Lattice, Option<Lattice>) {
        (
            self.first.sorted.lattice(),
            self.second.as_ref().map(|g| g.sorted.lattice()),
        )
    }

    /// The exact detection's search of the first lattice (`None` in UberFlow's mode).
    pub fn search(&self) -> Option<&cells::CellSearch> {
        self.first.sorted.search()
    }

    /// The sorted keys the last search read (`None` in UberFlow's mode).
    pub fn read_sorted_keys(&self) -> Result<Option<Vec<f32>>> {
        let g = &self.first;
        g.sorted
            .search()
            .map(|s| s.read_keys(g.sorted.keys()))
            .transpose()
    }

    /// The detection mode.
    pub fn detection(&self) -> scene::Detection {
        self.config.detection
    }

    /// UberFlow's detection on grid `g`'s layout into its `raw` target, then the mutual check
    /// into its `partner` (for the `first` lattice, naming partners through the first sort
    /// where the staggered lattice reads through it).
    fn detect_into(&self, g: &Grid, first: bool) {
        let Passes::Uberflow {
            detect,
            mutual,
            mutual_first,
            ..
        } = &self.passes
        else {
            return;
        };
        let (mutual, (lookup, lookup_uniforms)) = match (first, mutual_first) {
            (true, Some(m)) => (&**m, self.first.sorted.sorter().lookup_bindings()),
            _ => (mutual, (Vec::new(), Vec::new())),
        };
        let (positions, raw, out) = (g.sorted.layout().texture(POSITION), &g.raw, &g.partner);
        let width = ("u_width", Uniform::I32(self.width as i32));
        let uniforms = [
            width.clone(),
            ("u_neighbours", Uniform::I32(self.config.neighbours as i32)),
            ("u_radius", Uniform::F32(self.config.radius)),
        ];
        let position = [("u_position", positions.into())];
        self.pass.draw(detect, &position, &uniforms, raw);
        let mut partner = vec![("u_partner", raw.only_texture().into())];
        partner.extend(lookup);
        let mut uniforms = vec![width];
        uniforms.extend(lookup_uniforms);
        self.pass.draw(mutual, &partner, &uniforms, out);
        // The mutual check's own fetch; its second, at the partner (and, naming partners through
        // the first sort, the lookup of its place), only where one was found.
        let (w, rows) = (self.width, raw.height());
        let window = pass_list::detection_fetches(w, rows, self.config.neighbours);
        self.ctx.count_fetches(window + w as u64 * rows as u64);
    }

    /// One collision step on the state after the collisionless motion: sorts, detects, responds
    /// into `state.back()` (then swaps) and leaves the static texture in the new order.
    /// `constants` are the run's uniforms (colliders, masses) the response passes read;
    /// `fields` are the colliders' textures under their sampler names.
    pub fn run(
        &mut self,
        state: &mut PingPong,
        statics: &mut Framebuffer,
        dt: f32,
        fields: &[(&str, Sampled<'_>)],
        constants: &UniformList,
    ) -> Result<()> {
        if self.neighbours.is_some() {
            self.run_neighbours(state, statics, dt, fields, constants)?;
            if !self.impulse_runs() {
                return Ok(());
            }
        }
        if matches!(self.passes, Passes::Exact { .. }) {
            return self.run_exact(state, statics, dt, fields, constants);
        }
        let count = self.width as usize * state.height() as usize;
        self.sort_first(state, statics)?;
        self.exchange(constants);
        self.detect_into(&self.first, true);
        self.sort_second(count, state, statics)?;
        if let Some(g2) = &self.second {
            self.detect_into(g2, false);
        }
        // Response in the last layout.
        let (own, partner) = match &self.second {
            Some(g2) => (g2.sorted.layout(), &g2.partner),
            None => (self.first.sorted.layout(), &self.first.partner),
        };
        let Passes::Uberflow { response: p, .. } = &self.passes else {
            unreachable!("the exact mode returned above");
        };
        let textures = self.response_textures(p, (own, partner), (state, statics), fields);
        let uniforms = [
            ("u_width", Uniform::I32(self.width as i32)),
            ("u_radius", Uniform::F32(self.config.radius)),
            ("u_restitution", Uniform::F32(self.config.restitution)),
            ("u_dt", Uniform::F32(dt)),
        ];
        let uniforms = constants.for_draw(p, uniforms);
        self.pass.draw(p, &textures, &uniforms, state.back());
        state.swap();
        self.take_statics(true, statics)?;
        self.carry_back(self.second.is_some());
        Ok(())
    }

    /// Every texture the response program `p` samples: the last layout `own` and its
    /// `partner`, with the staggered lattice the first's partners and the state they name
    /// (`lattices.rs`), the spins, and the colliders' `fields` it declares.
    fn response_textures<'a>(
        &'a self,
        p: &Program,
        (own, partner): (&'a Framebuffer, &'a Framebuffer),
        (state, statics): (&'a PingPong, &'a Framebuffer),
        fields: &[(&'a str, Sampled<'a>)],
    ) -> Vec<(&'a str, Sampled<'a>)> {
        // Every sampler named on this draw: the sorts' gathers bind their own textures, and
        // nothing they leave is read here.
        let mut textures: Vec<(&str, Sampled)> = vec![
            ("u_position", own.texture(POSITION).into()),
            ("u_velocity", own.texture(VELOCITY).into()),
            ("u_static", own.texture(STATIC).into()),
            ("u_partner", partner.only_texture().into()),
        ];
        if self.second.is_some() {
            textures.extend(self.first_partner_textures(own, state, statics));
        }
        // Spinning spheres: this layout's spin (the first's, with the partners' above).
        let spin = match &self.second {
            Some(g2) => g2.spin.as_ref(),
            None => self.first.spin.as_ref(),
        };
        if let Some(s) = spin {
            textures.push(("u_spin", s.only_texture().into()));
        }
        textures.extend(fields.iter().filter(|(n, _)| p.declares(n)).copied());
        textures
    }

    /// Reads back one lattice's state after the last step's detection, in that lattice's sorted
    /// order (the first lattice, or with `staggered` the second; `None` if there is none), so
    /// that statistics can be taken on the CPU.
    pub fn read_back(&self, staggered: bool) -> Result<Option<Readback>> {
        let grid = if staggered {
            self.second.as_ref()
        } else {
            Some(&self.first)
        };
        grid.map(|g| {
            let partners = match (&self.passes, self.neighbour_counts()?) {
                (_, Some(counts)) => counts,
                (Passes::Exact { counts, .. }, None) => self.read_partners(counts)?,
                (Passes::Uberflow { .. }, None) => detections(g)?,
            };
            Ok(Readback {
                positions: g.sorted.layout().texture(POSITION).read_f32()?,
                velocities: match staggered {
                    true => g.sorted.layout().texture(VELOCITY).read_f32()?,
                    false => self.first_velocities()?,
                },
                partners,
            })
        })
        .transpose()
    }

    /// State texture width: the length of a sorted row.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// The scene's time step (s).
    pub fn dt(&self) -> f32 {
        self.dt
    }

    /// The context.
    pub fn context(&self) -> &Context {
        &self.ctx
    }
}

/// UberFlow's detection on grid `g` as [`Readback::partners`] gives it: (partner after the
/// mutual check or -1, distance, 1 if mutual, partner before the check) per particle, each
/// partner by its place in `g`'s layout. (The check keeps the partner found or writes -1; the
/// first lattice's may name the partner by its place in another state, `lattices.rs`.)
fn detections(g: &Grid) -> Result<Vec<f32>> {
    let partner = g.partner.only_texture().read_f32()?;
    let raw = g.raw.only_texture().read_f32()?;
    Ok((partner.chunks_exact(2).zip(raw.chunks_exact(2)))
        .flat_map(|(p, r)| {
            let mutual = p[0] >= 0.0;
            [
                if mutual { r[0] } else { -1.0 },
                p[1],
                mutual as u8 as f32,
                r[0],
            ]
        })
        .collect())
}

/// One lattice's state after a step's detection, read back by [`CollisionStage::read_back`]; RGBA
/// texels, four floats per particle, in the lattice's sorted order.
#[derive(Debug, Clone)]
pub struct Readback {
    /// Positions (xyz, life).
    pub positions: Vec<f32>,
    /// Velocities.
    pub velocities: Vec<f32>,
    /// (partner after the mutual check or -1, distance, mutual, partner before the check); in
    /// the exact mode (partners closer than 2 radius, 1 if a run was truncated, 0, 0); with the
    /// dem response (partners closer than 2 radius, 0, -1, 0): its force pass does not flag
    /// truncated runs.
    pub partners: Vec<f32>,
}
