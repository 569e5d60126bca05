//! What a scene's simulation compiles and runs ([`Features`]): derived from the scene file
//! alone, turned into the programs' `#define`s and into the pass list `texflow scene passes`
//! prints.

use super::super::allocator::AllocatorKind;
use crate::gl::Defines;
use crate::scene::{
    self, EmitterKind, ForceKind, Integrator, Precision, SceneFile, VelocityFormat,
};
use crate::sim::{Pass, Stage};

// The names of the forces and of the constraint passes, for the pass list.
mod names;

/// How particles come into being.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Emission {
    /// Latta §3.4.1: a CPU allocator; new particles drawn as single pixels.
    Allocator(AllocatorKind),
    /// UberFlow §4.1: phases in the static texture, respawn in the shader.
    Timestamp,
    /// Every texel filled at the start; `life`: they die once, else they are permanent.
    Initial {
        /// Whether the particles have a life.
        life: bool,
    },
}

impl Emission {
    /// The births of the scene's emitters: those of its one kind that owns the texels (the
    /// first in [`EmitterKind::ALL`]'s order), permanent particles without one.
    fn of(em: &scene::Emitters) -> Self {
        let births = |kind: EmitterKind| {
            let list = em.of_kind(kind);
            let first = list.first()?;
            match kind {
                EmitterKind::Allocator => Some(Emission::Allocator(
                    match first.allocator.unwrap_or_default() {
                        scene::AllocatorKind::Stack => AllocatorKind::Stack,
                        scene::AllocatorKind::MinHeap => AllocatorKind::MinHeap,
                    },
                )),
                EmitterKind::Timestamp => Some(Emission::Timestamp),
                EmitterKind::Initial => Some(Emission::Initial {
                    life: list.iter().any(|e| e.life.is_some()),
                }),
                // Born in the integration pass of another kind's particles (`children`).
                EmitterKind::Child => None,
            }
        };
        (EmitterKind::ALL.into_iter())
            .find_map(births)
            .unwrap_or(Emission::Initial { life: false })
    }
}

/// What a scene's simulation compiles and runs: derived from the scene file alone.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Features {
    /// Integrator.
    pub integrator: Integrator,
    /// One MRT pass or a velocity pass and a position pass (explicit integrators).
    pub passes: scene::UpdatePasses,
    /// Positions from start values and time by a closed form (`simulation = "stateless"`).
    pub stateless: bool,
    /// Birth and death.
    pub emission: Emission,
    /// Number of particle types (emitters).
    pub types: usize,
    /// Any gravity.
    pub gravity: bool,
    /// Point attractors and repulsors (the scene's, then every emitter's).
    pub attractors: usize,
    /// Springs (the scene's, then every emitter's).
    pub springs: usize,
    /// Vortices (the scene's, then every emitter's).
    pub vortices: usize,
    /// Some emitter carries forces of its own: gravity and damping per type, and an owner
    /// type for every attractor, spring and vortex.
    pub emitter_forces: bool,
    /// Any damping.
    pub damping: bool,
    /// A wind flow field.
    pub wind: bool,
    /// How the wind acts (0 drag, 1 Latta eq. 1-2, 2 UberFlow eq. 1).
    pub wind_form: scene::WindForm,
    /// Some emitter gives a mass range: a mass per particle (Latta §3.3).
    pub mass_range: bool,
    /// How many colliders of each kind.
    pub collider_counts: scene::ColliderCounts,
    /// Velocity storage.
    pub velocity_format: VelocityFormat,
    /// Precision of what the passes write.
    pub precision: Precision,
    /// Collisions between particles: (neighbours, staggered, rows_only).
    pub collisions: Option<(u32, bool, Option<u32>)>,
    /// The collision detection mode (with `collisions`).
    pub detection: crate::scene::Detection,
    /// Whether the first and the staggered lattice's rows-only blocked sorts take 4-byte exact
    /// entries (cell key and column: [`crate::sort::SortOptions::row_cells`]).
    pub collision_row_cells: [bool; 2],
    /// The collision sorts' network (`collisions.sort`).
    pub collision_sort: crate::scene::CollisionSort,
    /// The exact detection's pairs respond with the DEM contact force (`collisions.response`).
    pub dem: bool,
    /// User pair forces (`[[forces.pair]]`).
    pub pair_forces: usize,
    /// Weakly compressible SPH (`[fluid]`, src/sim/fluid/): its passes in the collision stage;
    /// the value says whether plane colliders get the wall treatment.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fluid: Option<bool>,
    /// `fluid.resort = "coherent"`: the re-sort's block (src/sim/fluid/resort.rs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fluid_resort: Option<u32>,
    /// The fluid's lattice cell over its smoothing length h (`fluid.cell`: 1 or 2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fluid_cell: Option<u32>,
    /// Time stamps in texel order (`collisions.row_phases`), so a release shares a row.
    pub row_phases: bool,
    /// Some timestamp emitter moves each release to its own place (`release_spread`).
    pub release_spread: bool,
    /// Distance constraints (Latta §3.4.3): kind, iterations per step, scheme and whether the
    /// long-range attachments run.
    pub constraints: Option<(scene::ConstraintKind, u32, scene::RelaxScheme, bool)>,
    /// Spinning spheres (`collisions.spin`, UberFlow §4.5): a third state texture of angular
    /// velocity and angle, written by integration and the collision response.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub spin: bool,
    /// Child emitters (the thesis §2): their texels are born from their parents' state in the
    /// integration pass.
    pub children: usize,
    /// The user forces' GLSL files (`[[forces.custom]]`), compiled into the integration pass.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub custom_forces: Vec<String>,
    /// The user's own states (`[[state]]`, `user_state.rs`): name and texel format.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub user_states: Vec<(String, scene::StateFormat)>,
    /// The user states whose update runs in the integration pass (`pass = "integrate"`,
    /// `user_state_mrt.rs`): further render targets of it, no pass of their own.
    pub integrated_states: Vec<String>,
    /// The user states exchanged with the neighbours (`pair`, `collide/carry.rs`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub exchanges: Vec<String>,
    /// The exact searches that read a cell-start table (`collide/cells.rs`).
    pub cell_tables: crate::sim::collide::CellTables,
}

impl Features {
    /// Reads what a (non-fire) scene needs.
    pub fn of(scene: &SceneFile) -> Self {
        let em = &scene.emitters;
        let emission = Emission::of(em);
        let f = &scene.forces;
        // The scene's forces of a kind, then every emitter's (the uniform arrays' order).
        let with_emitters = |k| f.count(k) + em.all().map(|e| e.forces.count(k)).sum::<usize>();
        let c = &scene.colliders;
        Features {
            integrator: scene.integrator,
            passes: scene.passes,
            stateless: scene.simulation == scene::StateModel::Stateless,
            emission,
            types: em.len().max(1),
            gravity: f.count(ForceKind::Gravity) > 0,
            attractors: with_emitters(ForceKind::Attractor),
            springs: with_emitters(ForceKind::Spring),
            vortices: with_emitters(ForceKind::Vortex),
            emitter_forces: em.all().any(|e| e.forces != scene::Forces::default()),
            damping: f.count(ForceKind::Damping) > 0,
            wind: f.count(ForceKind::Wind) > 0,
            wind_form: f.wind.first().map(|w| w.form).unwrap_or_default(),
            mass_range: em.all().any(|e| e.mass_range.is_some()),
            collider_counts: scene::ColliderCounts::of(c),
            velocity_format: scene.particles.velocity_format,
            precision: scene.particles.precision,
            collisions: scene
                .collisions
                .as_ref()
                .map(|c| (c.neighbours, c.staggered, c.rows_only)),
            detection: scene
                .collisions
                .as_ref()
                .map_or(Default::default(), |c| c.detection),
            collision_sort: (scene.collisions.as_ref()).map_or(Default::default(), |c| c.sort),
            collision_row_cells: [false, true].map(|staggered| {
                scene.collisions.as_ref().is_some_and(|c| {
                    crate::sim::collide::sort_options(c, staggered)
                        .row_cells(c.sort.variant(), scene.particles.size[0])
                })
            }),
            dem: (scene.collisions.as_ref())
                .is_some_and(|c| c.response == crate::scene::Response::Dem),
            pair_forces: scene.forces.pair.len(),
            fluid: scene.fluid.as_ref().map(|f| f.wall_correction),
            fluid_resort: (scene.fluid.as_ref())
                .and_then(|f| crate::sim::fluid::coherent_block(f, scene.particles.size)),
            fluid_cell: (scene.fluid.as_ref()).map(|f| {
                match f.fine_cell(crate::scene::fluid_particles(scene)) {
                    true => 1,
                    false => 2,
                }
            }),
            row_phases: scene.collisions.as_ref().is_some_and(|c| c.row_phases),
            release_spread: em.timestamp.iter().any(|e| e.release_spread.is_some()),
            constraints: scene
                .constraints
                .as_ref()
                .map(|c| (c.kind, c.iterations, c.scheme, c.attachments)),
            spin: scene.collisions.as_ref().is_some_and(|c| c.spin),
            children: em.child.len(),
            custom_forces: (scene.forces.custom.iter())
                .map(|c| c.glsl.clone())
                .collect(),
            user_states: (scene.state.iter())
                .map(|s| (s.name.clone(), s.format))
                .collect(),
            integrated_states: (super::user_state::integrated(scene).into_iter())
                .map(|i| scene.state[i].name.clone())
                .collect(),
            exchanges: (scene.state.iter().filter(|s| s.pair.is_some()))
                .map(|s| s.name.clone())
                .collect(),
            cell_tables: crate::sim::collide::CellTables::of(scene),
        }
    }

    /// The integration pass's defines of the forces, kind by kind.
    fn force_defines(&self, def: &mut impl FnMut(&str, String)) {
        for kind in ForceKind::ALL {
            match kind {
                ForceKind::Gravity if self.gravity => def("GRAVITY", "1".into()),
                ForceKind::Damping => {
                    if self.damping {
                        def("DAMPING", "1".into());
                    }
                    // Each emitter's own gravity and damping come after the scene's.
                    if self.emitter_forces {
                        def("EMITTER_FORCES", "1".into());
                    }
                }
                ForceKind::Wind if self.wind => {
                    def("WIND", "1".into());
                    def("WIND_FORM", (self.wind_form as u8).to_string());
                }
                ForceKind::Gravity | ForceKind::Wind => {}
                ForceKind::Attractor => def("N_ATTRACTORS", self.attractors.to_string()),
                ForceKind::Spring => def("N_SPRINGS", self.springs.to_string()),
                ForceKind::Vortex => def("N_VORTICES", self.vortices.to_string()),
                // N_CUSTOM: src/sim/particles/custom.rs; the pair forces' own passes:
                // src/sim/collide/.
                ForceKind::Custom | ForceKind::Pair => {}
            }
        }
    }

    /// Whether the scene has any collider.
    pub fn colliders(&self) -> bool {
        self.collider_counts.any()
    }

    /// Whether particles have a life (and the pass counts it down).
    pub fn life(&self) -> bool {
        !matches!(self.emission, Emission::Initial { life: false })
    }

    /// Whether passes can be limited to the rows that hold live particles (the min-heap keeps
    /// them packed at the start, Latta §3.4.1).
    pub fn live_rows(&self) -> bool {
        // Child emitters' texels lie after the parents' and must be stepped too.
        self.emission == Emission::Allocator(AllocatorKind::MinHeap) && self.children == 0
    }

    /// Whether a step writes velocity and position in two passes (`passes = "separate"`).
    pub fn separate(&self) -> bool {
        self.passes == scene::UpdatePasses::Separate && self.integrator != Integrator::Verlet
    }

    /// Whether the position pass of a separate update can read the new velocity instead of
    /// recomputing the step and still write the MRT pass's bits: Euler and UberFlow advance the
    /// position from the new velocity alone, unless a collider moves it too, or the velocity is
    /// stored rounded (rgba16f, fp24) while the MRT pass advances with the unrounded one.
    pub fn position_from_velocity(&self) -> bool {
        matches!(self.integrator, Integrator::Euler | Integrator::Uberflow)
            && !self.colliders()
            && self.velocity_format == VelocityFormat::Rgba32f
            && self.precision == Precision::Fp32
    }

    /// The `#define`s of the simulation programs.
    pub fn defines(&self) -> Defines {
        let mut d: Defines = Vec::new();
        let mut def = |k: &str, v: String| d.push((k.to_owned(), v));
        match self.integrator {
            Integrator::Euler => def("EULER", "1".into()),
            Integrator::Uberflow => def("UBERFLOW", "1".into()),
            Integrator::Verlet => def("VERLET", "1".into()),
            Integrator::Heun => def("HEUN", "1".into()),
            Integrator::Rk4 => def("RK4", "1".into()),
            Integrator::Leapfrog => def("LEAPFROG", "1".into()),
        }
        if self.integrator.multistage() {
            def("MULTISTAGE", "1".into());
        }
        match self.emission {
            Emission::Allocator(_) => {
                def("ALLOCATOR", "1".into());
                def("LIFE", "1".into());
            }
            Emission::Timestamp => {
                def("TIMESTAMP", "1".into());
                if self.release_spread {
                    def("RELEASE_SPREAD", "1".into());
                }
                if self.row_phases {
                    def("ROW_PHASES", "1".into());
                }
            }
            Emission::Initial { life } => {
                def("INITIAL", "1".into());
                if life {
                    def("LIFE", "1".into());
                }
            }
        }
        if self.children > 0 {
            def("CHILDREN", "1".into());
        }
        self.force_defines(&mut def);
        if self.mass_range {
            def("MASS_RANGE", "1".into());
        }
        for kind in scene::ColliderKind::ALL {
            let n = self.collider_counts.get(kind);
            match kind {
                scene::ColliderKind::Plane => def("N_PLANES", n.to_string()),
                scene::ColliderKind::Sphere => def("N_SPHERES", n.to_string()),
                scene::ColliderKind::Box => def("N_BOXES", n.to_string()),
                scene::ColliderKind::HeightField if n > 0 => def("HEIGHTFIELD", "1".into()),
                scene::ColliderKind::Sdf if n > 0 => def("SDF", "1".into()),
                scene::ColliderKind::HeightField | scene::ColliderKind::Sdf => {}
            }
        }
        def("HAS_COLLIDERS", (self.colliders() as u8).to_string());
        if self.spin {
            def("SPIN", "1".into());
        }
        if self.precision == Precision::Fp24 {
            let f = crate::sort::precision::R300;
            def("EMULATE_FLOAT", "1".into());
            def("FLOAT_MANTISSA", f.mantissa_bits.to_string());
            def("FLOAT_EXPONENT", f.exponent_bits.to_string());
        }
        d
    }

    /// The simulation passes of one step, in order, each with the stage that runs it: what a
    /// step runs, `texflow scene passes` prints and the benchmarks time.
    pub fn step_passes(&self) -> Vec<Pass> {
        let mut out = Vec::new();
        let mut add = |stage: Stage, names: Vec<String>| {
            out.extend(names.into_iter().map(|name| Pass { stage, name }));
        };
        let verlet = self.integrator == Integrator::Verlet;
        add(Stage::Births, self.emit_pass(verlet).into_iter().collect());
        add(Stage::Integrate, self.integration_lines());
        add(Stage::Relax, self.constrain_passes());
        let mut collide = Vec::new();
        self.collision_passes(&mut collide);
        if self.collisions.is_some() {
            collide.extend(crate::sim::collide::carry_passes(
                self.user_states.len(),
                &self.exchanges,
                self.cell_tables.collisions_trimmed,
            ));
        } else if self.fluid.is_some() {
            collide.extend(super::fluid::fluid_carry_passes(
                self.user_states.len(),
                &self.exchanges,
            ));
        }
        if self.spin {
            collide.push(
                "spin (UberFlow §4.5): angular velocity and angle, a third MRT target of \
                 integration and response, gathered in cell order by a pass of its own after \
                 each collision sort; contact friction turns v and ω together"
                    .into(),
            );
        }
        add(Stage::Collide, collide);
        out
    }

    /// The collision stage: neighbour forces, the exact search or UberFlow's sorted rows.
    fn collision_passes(&self, out: &mut Vec<String>) {
        if let Some(walls) = self.fluid {
            out.extend(crate::sim::fluid::fluid_passes(
                walls && self.collider_counts.get(scene::ColliderKind::Plane) > 0,
                self.fluid_resort,
                self.cell_tables.fluid,
                self.fluid_cell.unwrap_or(2),
            ));
        }
        if self.dem || self.pair_forces > 0 {
            out.extend(crate::sim::collide::neighbour_passes(
                self.dem,
                self.pair_forces,
                self.collision_sort,
                self.cell_tables,
            ));
        }
        if self.dem {
            // The dem response replaces the impulse: the neighbour passes are the whole stage.
        } else if self.collisions.is_some() && self.detection == crate::scene::Detection::Exact {
            out.extend(crate::sim::collide::exact_passes(
                self.colliders(),
                self.collision_sort,
                self.cell_tables,
            ));
        } else if let Some((k, staggered, rows)) = self.collisions {
            let lattices: &[&str] = if staggered {
                &["lattice", "staggered lattice"]
            } else {
                &["lattice"]
            };
            let through =
                crate::sim::collide::reads_through_first(staggered, false, self.pair_forces > 0);
            for (l, &row_cells) in lattices.iter().zip(&self.collision_row_cells) {
                let sort = crate::sim::collide::uberflow_sort(self.collision_sort, rows, row_cells);
                out.push(format!("collision keys: cell index in the {l} (z, y, x)"));
                out.push(format!("collision sort: {sort}"));
                out.push(match (*l == "staggered lattice", through) {
                    (false, false) => "gather position, velocity, static in cell order".into(),
                    (false, true) => "gather position in cell order (the staggered lattice \
                                      reads velocity and static through both sorts)"
                        .into(),
                    (true, false) => "gather position, velocity, static and the first detection \
                                      in cell order"
                        .into(),
                    (true, true) => "gather position, velocity, static and the first detection \
                                     in cell order (velocity and static through both sorts, \
                                     from the state the first sort read)"
                        .into(),
                });
                out.push(format!(
                    "collision detection: closest of {k} neighbours each side in the row; \
                     mutual check"
                ));
            }
            out.push(format!(
                "collision response: back-tracking to contact, momentum exchange, overlap separation{}",
                if self.colliders() {
                    "; boundary conditions (colliders)"
                } else {
                    ""
                }
            ));
        }
    }
}
