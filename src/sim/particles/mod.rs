//! The general particle system of Latta (§3.3-3.4) and UberFlow (§4.1-4.2, 4.6): state in
//! RGBA float textures, one full-screen integration pass per step, birth by a CPU allocator or by
//! time stamps, forces and colliders compiled into the pass only when the scene has them; with
//! `[constraints]`, relaxation passes after each Verlet step (`relax.rs`, Latta §3.4.3).
//!
//! The state layout, the integrators and the collision response are described in
//! `glsl/sim/integrate.frag` and `glsl/sim/colliders.glsl`; [`Features`] decides what is compiled
//! and which passes run. Each stage names its passes beside the code that draws them (the
//! integration in `integrate.rs`, the births in `births.rs`, the relaxation in
//! `features/names.rs` (drawn in `relax.rs`), the collision and fluid stages in their modules);
//! [`Features::step_passes`] puts the lines in order for `texflow scene passes`, and
//! `pass_list.rs` gives each its draws.

mod births;
mod bounces;
mod children;
mod custom;
mod features;
mod fluid;
mod integrate;
mod pass_list;
mod relax;
mod setup;
mod state_io;
mod stateless;
mod uniforms;
mod user_state;

use glam::UVec2;

use super::allocator::Allocator;
use super::fields::{DistanceField, FlowField, HeightField};
use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, Framebuffer, FullscreenPass, PingPong, Program, Ring3, Sampled, Texture,
    Texture3D, TextureDesc, TextureFormat, Uniform, UniformList, FULLSCREEN_VERTEX,
};
use crate::scene::{Integrator, SceneFile};
use crate::sim::params::Params;
pub use births::BIRTH_VERTEX_BYTES;
pub use custom::check_custom_forces;
pub use features::{Emission, Features};
pub use stateless::ClosedForm;
pub use user_state::check_user_states;

/// The state framebuffers: position and velocity ping-pong for the explicit integrators, a ring
/// of previous, current and next positions for Verlet.
enum State {
    Explicit(PingPong),
    Verlet(Ring3),
}

struct Fields {
    flow: Option<(Texture3D, FlowField)>,
    height: Option<(Texture, HeightField)>,
    sdf: Option<(Texture3D, DistanceField)>,
}

impl Fields {
    /// The fields' textures under the sampler names of `glsl/sim/` (those the scene has).
    fn textures(&self) -> Vec<(&'static str, Sampled<'_>)> {
        let mut out = Vec::new();
        if let Some((t, _)) = &self.flow {
            out.push(("u_flow", t.into()));
        }
        if let Some((t, _)) = &self.height {
            out.push(("u_height", t.into()));
        }
        if let Some((t, _)) = &self.sdf {
            out.push(("u_sdf", t.into()));
        }
        out
    }
}

/// The textures of one simulation draw: `own` (each of which the program must declare) and the
/// fields the program declares.
fn draw_textures<'a>(
    p: &Program,
    own: &[(&'a str, Sampled<'a>)],
    fields: &'a Fields,
) -> Vec<(&'a str, Sampled<'a>)> {
    let mut list = own.to_vec();
    list.extend(fields.textures().into_iter().filter(|(n, _)| p.declares(n)));
    list
}

/// The particle simulation of a scene.
pub struct ParticleSim {
    ctx: Context,
    /// The scene's name, for messages.
    name: String,
    /// The numbers the passes read, packed once from the scene (which the simulation does not
    /// keep: the engine holds it).
    params: Params,
    features: Features,
    /// The stages of a step, from the pass list of `features` (kept: a step runs them).
    stages: Vec<crate::sim::Stage>,
    width: u32,
    height: u32,
    state: State,
    statics: Framebuffer,
    integrate: Program,
    /// The position pass of a separate update (`passes = "separate"`); `integrate` then writes
    /// the velocity alone.
    integrate_position: Option<Program>,
    /// The closed-form pass of a stateless scene, which replaces the integration.
    stateless: Option<stateless::Stateless>,
    emit_state: Option<Program>,
    emit_previous: Option<Program>,
    emit_static: Option<Program>,
    start: Option<Program>,
    collisions: Option<super::collide::CollisionStage>,
    /// The SPH stage of a scene with `[fluid]` (src/sim/fluid/).
    fluid: Option<super::fluid::Fluid>,
    /// The exchange passes (`pair`) of a scene with `[fluid]`, with their states' indices.
    fluid_exchange: Vec<(usize, Program, f32)>,
    /// The count of paths past the bound on bounces at colliders (`bounces.rs`).
    bounces: Option<super::collide::tally::TruncationTally>,
    relax: Option<relax::Relaxation>,
    /// The user's own per-particle states (`[[state]]`, `user_state.rs`).
    user: Option<user_state::UserStates>,
    /// Their names, in the scene's order.
    state_names: Vec<String>,
    pass: FullscreenPass,
    fields: Fields,
    /// The run's constant uniforms (emitters, masses, forces, colliders), given with every
    /// draw of a simulation program: built once from the parameter blocks.
    constants: UniformList,
    allocator: Option<Allocator>,
    owed: Vec<f64>,
    emitted: u64,
    dropped: u64,
    seed: u32,
    step: u64,
    time: f64,
}

impl std::fmt::Debug for ParticleSim {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "ParticleSim({} {}x{})",
            self.name, self.width, self.height
        )
    }
}

fn state_texture(ctx: &Context, label: &str, w: u32, h: u32, f: TextureFormat) -> Result<Texture> {
    Texture::new(
        ctx,
        TextureDesc {
            width: w,
            height: h,
            format: f,
            label,
        },
    )
}

impl ParticleSim {
    /// Builds the state, the fields and the programs of `scene` and draws the initial state.
    pub fn new(ctx: &Context, scene: &SceneFile, seed: u32) -> Result<Self> {
        if scene.fire.is_some() {
            return Err(Error::InvalidInput(format!(
                "scene `{}` is the thesis's fire: run it with the fire simulation",
                scene.name
            )));
        }
        scene.check()?;
        let [width, height] = scene.particles.size;
        crate::gl::check_size(ctx, "particle texture (particles.size)", width, height)?;
        let features = Features::of(scene);
        let vel_format = setup::velocity_format(features.velocity_format);
        let state = setup::state(ctx, &features, vel_format, width, height)?;
        let statics = setup::statics(ctx, width, height)?;
        let fields = setup::fields(ctx, scene)?;
        let defines = features.defines();
        let verlet = features.integrator == Integrator::Verlet;
        let (emit_state, emit_previous, emit_static) =
            setup::emit_programs(ctx, &features, &defines)?;
        let params = Params::of(scene);
        let (integrate, integrate_position) =
            setup::integrate_programs(ctx, scene, &features, &defines)?;
        let types = features.types;
        let constants = uniforms::constants(&params, &fields, [width, height], seed, types);
        let mut sim = ParticleSim {
            integrate,
            integrate_position,
            stateless: stateless::Stateless::of(ctx, scene, &defines, [width, height])?,
            emit_state,
            emit_previous,
            emit_static,
            start: setup::verlet_start(ctx, verlet, &defines)?,
            collisions: match &scene.collisions {
                Some(_) => Some(
                    super::collide::CollisionStage::new(ctx, scene, &defines, vel_format)?
                        .carry_states(
                            scene,
                            user_state::exchange_programs(ctx, scene, &defines)?,
                        )?,
                ),
                None => None,
            },
            fluid: match &scene.fluid {
                Some(_) => Some(super::fluid::Fluid::new(ctx, scene, &defines, vel_format)?),
                None => None,
            },
            fluid_exchange: fluid::exchange_programs(ctx, scene, &defines)?,
            bounces: bounces::tally(ctx, &features, [width, height])?,
            relax: relax::Relaxation::new(ctx, scene, params.constraints.as_ref(), &defines)?,
            user: user_state::UserStates::new(ctx, scene, &defines, [width, height])?,
            state_names: scene.state.iter().map(|s| s.name.clone()).collect(),
            pass: FullscreenPass::new(ctx)?,
            allocator: match features.emission {
                // Child emitters keep texels of their own: the allocator hands out the rest.
                Emission::Allocator(kind) => {
                    Some(Allocator::new(kind, scene.parent_slots() as u32))
                }
                Emission::Timestamp | Emission::Initial { .. } => None,
            },
            owed: vec![0.0; scene.emitters.len()],
            emitted: 0,
            dropped: 0,
            ctx: ctx.clone(),
            name: scene.name.clone(),
            params,
            stages: crate::sim::stages_of(&features.step_passes()),
            features,
            width,
            height,
            state,
            statics,
            fields,
            constants,
            seed,
            step: 0,
            time: 0.0,
        };
        sim.start_up(scene)?;
        Ok(sim)
    }

    /// The uniforms of a draw of `p`: the run's constants and this draw's `more`, those `p`
    /// declares.
    fn uniforms(
        &self,
        p: &Program,
        more: impl IntoIterator<Item = (&'static str, Uniform)>,
    ) -> Vec<(&'static str, Uniform)> {
        self.constants.for_draw(p, more)
    }

    /// Draws the initial state with `sim/init.frag` (one pass per target) and restarts the clock.
    fn initialise(&mut self) -> Result<()> {
        let mut defines = self.features.defines();
        let program = |out: &str, d: &mut Defines| -> Result<Program> {
            let mut d = d.clone();
            d.push((out.to_owned(), "1".to_owned()));
            Program::new(&self.ctx, FULLSCREEN_VERTEX, "sim/init.frag", &d)
        };
        let state = program("OUT_STATE", &mut defines)?;
        let statics = program("OUT_STATIC", &mut defines)?;
        let t = draw_textures(&statics, &[], &self.fields);
        self.pass
            .draw(&statics, &t, &self.uniforms(&statics, []), &self.statics);
        let t = draw_textures(&state, &[], &self.fields);
        let u = self.uniforms(&state, []);
        match &self.state {
            State::Explicit(pp) => {
                // Both sides, so rows a live-row restricted pass never touches are dead too.
                self.pass.draw(&state, &t, &u, pp.front());
                self.pass.draw(&state, &t, &u, pp.back());
                if let Some(sl) = &self.stateless {
                    self.pass.draw(&state, &t, &u, &sl.start);
                }
            }
            State::Verlet(ring) => {
                let previous = program("OUT_PREVIOUS", &mut defines)?;
                let tp = draw_textures(&previous, &[], &self.fields);
                let [p, c, n] = ring.roles();
                self.pass
                    .draw(&previous, &tp, &self.uniforms(&previous, []), p);
                self.pass.draw(&state, &t, &u, c);
                self.pass.draw(&state, &t, &u, n);
            }
        }
        self.step = 0;
        self.time = 0.0;
        Ok(())
    }

    /// What the scene compiles and runs.
    pub fn features(&self) -> &Features {
        &self.features
    }

    /// The numbers the passes read, packed once from the scene.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// State texture size.
    pub fn size(&self) -> UVec2 {
        UVec2::new(self.width, self.height)
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// Simulation time in seconds.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The CPU allocator (allocator emission only).
    pub fn allocator(&self) -> Option<&Allocator> {
        self.allocator.as_ref()
    }

    /// Particles emitted by the allocator, and those dropped because every index was live.
    pub fn emitted(&self) -> (u64, u64) {
        (self.emitted, self.dropped)
    }

    /// Births dropped so far because every index of the state texture was live (allocator
    /// emission; 0 otherwise). [`SceneFile::capacity_check`] predicts it from rate × life.
    pub fn dropped_births(&self) -> u64 {
        self.dropped
    }

    /// Rows that passes must cover: the live rows under a min-heap allocator, else all.
    pub fn active_rows(&self) -> u32 {
        match &self.allocator {
            Some(a) if self.features.live_rows() => a.live_rows(self.width).min(self.height),
            _ => self.height,
        }
    }

    /// Particles the renderer and the sort must consider (whole rows).
    pub fn active_count(&self) -> usize {
        self.active_rows() as usize * self.width as usize
    }

    /// One time step: the stages of its pass list in order (see
    /// [`Simulation::step`](crate::sim::Simulation::step)): allocator births, then the
    /// integration pass, then the swap, then the constraint relaxation (scenes with
    /// `[constraints]`) or the collision stage (scenes with `[collisions]`).
    pub fn step(&mut self) -> Result<()> {
        crate::sim::Simulation::step(self)
    }

    /// Runs `stage` of one step alone (see [`Simulation::run`](crate::sim::Simulation::run)).
    pub fn run(&mut self, stage: crate::sim::Stage) -> Result<()> {
        crate::sim::Simulation::run(self, stage)
    }

    /// The constraint relaxation passes after the Verlet step (scenes with `[constraints]`).
    fn relax(&mut self) {
        if let (Some(r), State::Verlet(ring)) = (&self.relax, &mut self.state) {
            r.run(
                &self.params,
                &self.constants,
                ring,
                &self.pass,
                &self.fields,
                self.time,
            );
        }
    }

    /// The constrained particles' layout (scenes with `[constraints]`).
    pub fn constraint_layout(&self) -> Option<&crate::sim::constraints::Layout> {
        self.relax.as_ref().map(|r| r.layout())
    }

    /// The collision stage (scenes with `[collisions]`).
    pub fn collisions(&self) -> Option<&super::collide::CollisionStage> {
        self.collisions.as_ref()
    }

    /// The collision stage, to change what it records (statistics).
    pub fn collisions_mut(&mut self) -> Option<&mut super::collide::CollisionStage> {
        self.collisions.as_mut()
    }

    /// The SPH stage (scenes with `[fluid]`).
    pub fn fluid(&self) -> Option<&super::fluid::Fluid> {
        self.fluid.as_ref()
    }

    /// Runs the collision stage on the current state (part of [`step`](Self::step)): the
    /// particles' collisions, or the fluid's passes.
    fn collide(&mut self) -> Result<()> {
        if self.fluid.is_some() {
            return self.run_fluid();
        }
        let Some(c) = self.collisions.as_mut() else {
            return Ok(());
        };
        let State::Explicit(pp) = &mut self.state else {
            return Err(Error::InvalidInput(
                "collisions need the explicit integrators".into(),
            ));
        };
        let (fields, params) = (&self.fields, &self.params);
        // The masses come with the scene's constants (glsl/common/mass.glsl): the response
        // weighs each particle by its own mass, as integration does.
        let constants = &self.constants;
        // The stage carries the user states along its sorts (collide/carry.rs).
        let mut none = Vec::new();
        let users = self.user.as_mut().map_or(&mut none, |u| u.states_mut());
        c.hold_states(users, self.time as f32);
        let ran = c.run(
            pp,
            &mut self.statics,
            params.time.dt,
            &fields.textures(),
            constants,
        );
        c.release_states(users);
        ran
    }
}
