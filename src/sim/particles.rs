//! The general particle system of Latta (§3.3-3.4) and UberFlow (§4.1-4.2, 4.6): state in
//! RGBA float textures, one full-screen integration pass per step, birth by a CPU allocator or by
//! time stamps, forces and colliders compiled into the pass only when the scene has them.
//!
//! The state layout, the integrators and the collision response are described in
//! `glsl/sim/integrate.frag` and `glsl/sim/colliders.glsl`; [`Features`] decides what is compiled
//! and which passes run, and is also what `texflow scene passes` prints.

use glam::{UVec2, Vec3, Vec4};
use glow::HasContext;

use super::allocator::{Allocator, AllocatorKind};
use super::emit::{EmitterUniforms, Rng};
use super::fields::{DistanceField, FlowField, HeightField};
use crate::error::{Error, Result};
use crate::gl::{
    Attribute, Buffer, Context, Defines, Framebuffer, FullscreenPass, PingPong, Program, Texture,
    Texture3D, TextureDesc, TextureFormat, VertexArray, FULLSCREEN_VERTEX,
};
use crate::scene::{self, Integrator, Precision, SceneFile, VelocityFormat};

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

/// What a scene's simulation compiles and runs: derived from the scene file alone.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Features {
    /// Integrator.
    pub integrator: Integrator,
    /// Birth and death.
    pub emission: Emission,
    /// Number of particle types (emitters).
    pub types: usize,
    /// Any gravity.
    pub gravity: bool,
    /// Point attractors and repulsors.
    pub attractors: usize,
    /// Springs.
    pub springs: usize,
    /// Vortices.
    pub vortices: usize,
    /// Any damping.
    pub damping: bool,
    /// A wind flow field.
    pub wind: bool,
    /// Plane colliders.
    pub planes: usize,
    /// Sphere colliders.
    pub spheres: usize,
    /// Box colliders.
    pub boxes: usize,
    /// A height field.
    pub heightfield: bool,
    /// A distance field.
    pub sdf: bool,
    /// Velocity storage.
    pub velocity_format: VelocityFormat,
    /// Precision of what the passes write.
    pub precision: Precision,
    /// Collisions between particles: (neighbours, staggered, rows_only).
    pub collisions: Option<(u32, bool, Option<u32>)>,
}

impl Features {
    /// Reads what a (non-fire) scene needs.
    pub fn of(scene: &SceneFile) -> Self {
        let em = &scene.emitters;
        let emission = if let Some(e) = em.allocator.first() {
            Emission::Allocator(match e.allocator.unwrap_or_default() {
                scene::AllocatorKind::Stack => AllocatorKind::Stack,
                scene::AllocatorKind::MinHeap => AllocatorKind::MinHeap,
            })
        } else if !em.timestamp.is_empty() {
            Emission::Timestamp
        } else {
            Emission::Initial {
                life: em.initial.iter().any(|e| e.life.is_some()),
            }
        };
        let f = &scene.forces;
        let c = &scene.colliders;
        Features {
            integrator: scene.integrator,
            emission,
            types: em.len().max(1),
            gravity: !f.gravity.is_empty(),
            attractors: f.attractor.len(),
            springs: f.spring.len(),
            vortices: f.vortex.len(),
            damping: !f.damping.is_empty(),
            wind: !f.wind.is_empty(),
            planes: c.plane.len(),
            spheres: c.sphere.len(),
            boxes: c.boxes.len(),
            heightfield: !c.heightfield.is_empty(),
            sdf: !c.sdf.is_empty(),
            velocity_format: scene.particles.velocity_format,
            precision: scene.particles.precision,
            collisions: scene
                .collisions
                .as_ref()
                .map(|c| (c.neighbours, c.staggered, c.rows_only)),
        }
    }

    /// Whether the scene has any collider.
    pub fn colliders(&self) -> bool {
        self.planes + self.spheres + self.boxes > 0 || self.heightfield || self.sdf
    }

    /// Whether particles have a life (and the pass counts it down).
    pub fn life(&self) -> bool {
        !matches!(self.emission, Emission::Initial { life: false })
    }

    /// Whether passes can be limited to the rows that hold live particles (the min-heap keeps
    /// them packed at the start, Latta §3.4.1).
    pub fn live_rows(&self) -> bool {
        self.emission == Emission::Allocator(AllocatorKind::MinHeap)
    }

    /// The `#define`s of the simulation programs.
    pub fn defines(&self) -> Defines {
        let mut d: Defines = Vec::new();
        let mut def = |k: &str, v: String| d.push((k.to_owned(), v));
        match self.integrator {
            Integrator::Euler => def("EULER", "1".into()),
            Integrator::Uberflow => def("UBERFLOW", "1".into()),
            Integrator::Verlet => def("VERLET", "1".into()),
        }
        match self.emission {
            Emission::Allocator(_) => {
                def("ALLOCATOR", "1".into());
                def("LIFE", "1".into());
            }
            Emission::Timestamp => def("TIMESTAMP", "1".into()),
            Emission::Initial { life } => {
                def("INITIAL", "1".into());
                if life {
                    def("LIFE", "1".into());
                }
            }
        }
        if self.gravity {
            def("GRAVITY", "1".into());
        }
        if self.damping {
            def("DAMPING", "1".into());
        }
        if self.wind {
            def("WIND", "1".into());
        }
        def("N_ATTRACTORS", self.attractors.to_string());
        def("N_SPRINGS", self.springs.to_string());
        def("N_VORTICES", self.vortices.to_string());
        def("N_PLANES", self.planes.to_string());
        def("N_SPHERES", self.spheres.to_string());
        def("N_BOXES", self.boxes.to_string());
        if self.heightfield {
            def("HEIGHTFIELD", "1".into());
        }
        if self.sdf {
            def("SDF", "1".into());
        }
        def("HAS_COLLIDERS", (self.colliders() as u8).to_string());
        if self.precision == Precision::Fp24 {
            let f = crate::sort::precision::R300;
            def("EMULATE_FLOAT", "1".into());
            def("FLOAT_MANTISSA", f.mantissa_bits.to_string());
            def("FLOAT_EXPONENT", f.exponent_bits.to_string());
        }
        d
    }

    /// The simulation passes of one step, in order, for `texflow scene passes`.
    pub fn step_passes(&self) -> Vec<String> {
        let mut out = Vec::new();
        let verlet = self.integrator == Integrator::Verlet;
        let targets = if verlet {
            "previous and current position textures in, next position out".to_owned()
        } else {
            format!(
                "position + velocity ({}) through MRT",
                match self.velocity_format {
                    VelocityFormat::Rgba32f => "rgba32f",
                    VelocityFormat::Rgba16f => "rgba16f",
                }
            )
        };
        if let Emission::Allocator(kind) = self.emission {
            out.push(format!(
                "emit: new particles drawn as single pixels into {} and static (CPU {} allocator)",
                if verlet {
                    "current and previous positions"
                } else {
                    "position and velocity"
                },
                match kind {
                    AllocatorKind::Stack => "stack",
                    AllocatorKind::MinHeap => "min-heap",
                }
            ));
        }
        let mut what = vec![match self.integrator {
            Integrator::Euler => "Latta's Euler (eq. 3, 8)".to_owned(),
            Integrator::Uberflow => "UberFlow's velocity-averaged update (eq. 1-2)".to_owned(),
            Integrator::Verlet => "Verlet (Latta eq. 9)".to_owned(),
        }];
        let mut forces = Vec::new();
        if self.gravity {
            forces.push("gravity".to_owned());
        }
        if self.attractors > 0 {
            forces.push(format!("{} attractor(s)", self.attractors));
        }
        if self.springs > 0 {
            forces.push(format!("{} spring(s)", self.springs));
        }
        if self.vortices > 0 {
            forces.push(format!("{} vortex(es)", self.vortices));
        }
        if self.damping {
            forces.push("damping".to_owned());
        }
        if self.wind {
            forces.push("wind (flow-field texture, Stokes drag)".to_owned());
        }
        if !forces.is_empty() {
            what.push(format!("forces: {}", forces.join(", ")));
        }
        let mut colliders = Vec::new();
        for (n, name) in [
            (self.planes, "plane"),
            (self.spheres, "sphere"),
            (self.boxes, "box"),
            (self.heightfield as usize, "height field"),
            (self.sdf as usize, "distance field"),
        ] {
            if n > 0 {
                colliders.push(format!("{n} {name}"));
            }
        }
        if !colliders.is_empty() {
            what.push(format!(
                "colliders: {}{}",
                colliders.join(", "),
                if verlet {
                    " (position constraints)"
                } else {
                    ""
                }
            ));
        }
        match self.emission {
            Emission::Allocator(_) | Emission::Initial { life: true } => {
                what.push("death by age (moved to infinity)".into())
            }
            Emission::Timestamp => what.push("time-stamp birth, respawn and death".into()),
            Emission::Initial { life: false } => {}
        }
        if self.precision == Precision::Fp24 {
            what.push("24-bit float emulation".into());
        }
        let integrate = format!(
            "integrate{}: {} [{}]",
            if self.live_rows() {
                " (live rows only)"
            } else {
                ""
            },
            what.join("; "),
            targets
        );
        out.push(integrate);
        if let Some((k, staggered, rows)) = self.collisions {
            let sort = match rows {
                Some(1) => "rows-only bitonic sort (GP/FP packed)".to_owned(),
                Some(r) => format!("bitonic sort within sets of {r} rows (GP/FP packed)"),
                None => "full bitonic sort (GP/FP packed)".to_owned(),
            };
            let lattices: &[&str] = if staggered {
                &["lattice", "staggered lattice"]
            } else {
                &["lattice"]
            };
            for l in lattices {
                out.push(format!("collision keys: cell index in the {l} (z, y, x)"));
                out.push(format!("collision sort: {sort}"));
                out.push(format!(
                    "gather position, velocity, static{} in cell order",
                    if *l == "staggered lattice" {
                        " and the first detection"
                    } else {
                        ""
                    }
                ));
                out.push(format!(
                    "collision detection: closest of {k} neighbours each side in the row; \
                     mutual check"
                ));
            }
            out.push(format!(
                "collision response: back-tracking to contact, momentum exchange{}",
                if self.colliders() {
                    "; boundary conditions (colliders)"
                } else {
                    ""
                }
            ));
            out.push("copy static texture in the new order".into());
        }
        out
    }
}

enum State {
    Explicit(PingPong),
    Verlet {
        ring: [Framebuffer; 3],
        current: usize,
    },
}

struct Fields {
    flow: Option<(Texture3D, FlowField)>,
    height: Option<(Texture, HeightField)>,
    sdf: Option<(Texture3D, DistanceField)>,
}

/// Texture units of the simulation programs.
mod unit {
    pub const POSITION: u32 = 0;
    pub const VELOCITY: u32 = 1;
    pub const STATIC: u32 = 2;
    pub const FLOW: u32 = 3;
    pub const HEIGHT: u32 = 4;
    pub const SDF: u32 = 5;
}

/// Floats per emitted vertex: index, position + life, velocity, static.
const EMIT_FLOATS: usize = 13;

/// The particle simulation of a scene.
pub struct ParticleSim {
    ctx: Context,
    scene: SceneFile,
    features: Features,
    width: u32,
    height: u32,
    state: State,
    statics: Framebuffer,
    integrate: Program,
    emit_state: Option<Program>,
    emit_previous: Option<Program>,
    emit_static: Option<Program>,
    start: Option<Program>,
    collisions: Option<super::collide::Collisions>,
    pass: FullscreenPass,
    fields: Fields,
    emitters: Vec<EmitterUniforms>,
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
            self.scene.name, self.width, self.height
        )
    }
}

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from(a)
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
        scene
            .validate()
            .map_err(|e| Error::InvalidInput(e.message))?;
        let [width, height] = scene.particles.size;
        crate::gl::check_size(ctx, "particle texture (particles.size)", width, height)?;
        let features = Features::of(scene);
        let vel_format = match features.velocity_format {
            VelocityFormat::Rgba32f => TextureFormat::Rgba32F,
            VelocityFormat::Rgba16f => TextureFormat::Rgba16F,
        };
        let state = if features.integrator == Integrator::Verlet {
            let fb = |i: usize| -> Result<Framebuffer> {
                let t = state_texture(
                    ctx,
                    &format!("position:{i}"),
                    width,
                    height,
                    TextureFormat::Rgba32F,
                )?;
                Framebuffer::new(ctx, &format!("verlet:{i}"), vec![t])
            };
            State::Verlet {
                ring: [fb(0)?, fb(1)?, fb(2)?],
                current: 1,
            }
        } else {
            State::Explicit(PingPong::new(
                ctx,
                "particles",
                &["position", "velocity"],
                &[TextureFormat::Rgba32F, vel_format],
                width,
                height,
            )?)
        };
        let statics = Framebuffer::new(
            ctx,
            "static",
            vec![state_texture(
                ctx,
                "static",
                width,
                height,
                TextureFormat::Rgba32F,
            )?],
        )?;
        let fields = Fields {
            flow: match scene.forces.wind.first() {
                Some(w) => {
                    let f = FlowField::new(w)?;
                    Some((f.upload(ctx)?, f))
                }
                None => None,
            },
            height: match scene.colliders.heightfield.first() {
                Some(h) => {
                    let f = HeightField::new(h)?;
                    Some((f.upload(ctx)?, f))
                }
                None => None,
            },
            sdf: match scene.colliders.sdf.first() {
                Some(s) => {
                    let f = DistanceField::new(s)?;
                    Some((f.upload(ctx)?, f))
                }
                None => None,
            },
        };
        let defines = features.defines();
        let with = |extra: &str| {
            let mut d = defines.clone();
            d.push((extra.to_owned(), "1".to_owned()));
            d
        };
        let verlet = features.integrator == Integrator::Verlet;
        let allocator = matches!(features.emission, Emission::Allocator(_));
        let emit = |out: &str| -> Result<Option<Program>> {
            Ok(if allocator {
                Some(Program::new(
                    ctx,
                    "sim/emit.vert",
                    "sim/emit.frag",
                    &with(out),
                )?)
            } else {
                None
            })
        };
        let emitters: Vec<EmitterUniforms> =
            scene.emitters.all().map(EmitterUniforms::new).collect();
        let mut sim = ParticleSim {
            integrate: Program::new(ctx, FULLSCREEN_VERTEX, "sim/integrate.frag", &defines)?,
            emit_state: emit("OUT_STATE")?,
            emit_previous: if verlet { emit("OUT_PREVIOUS")? } else { None },
            emit_static: emit("OUT_STATIC")?,
            start: if verlet {
                Some(Program::new(
                    ctx,
                    FULLSCREEN_VERTEX,
                    "sim/verlet_start.frag",
                    &defines,
                )?)
            } else {
                None
            },
            collisions: match &scene.collisions {
                Some(_) => Some(super::collide::Collisions::new(
                    ctx, scene, &defines, vel_format,
                )?),
                None => None,
            },
            pass: FullscreenPass::new(ctx)?,
            allocator: match features.emission {
                Emission::Allocator(kind) => Some(Allocator::new(kind, width * height)),
                _ => None,
            },
            owed: vec![0.0; emitters.len()],
            emitters,
            emitted: 0,
            dropped: 0,
            ctx: ctx.clone(),
            scene: scene.clone(),
            features,
            width,
            height,
            state,
            statics,
            fields,
            seed,
            step: 0,
            time: 0.0,
        };
        for p in [
            Some(&sim.integrate),
            sim.emit_state.as_ref(),
            sim.emit_previous.as_ref(),
            sim.emit_static.as_ref(),
            sim.start.as_ref(),
        ]
        .into_iter()
        .flatten()
        {
            sim.set_constants(p);
        }
        sim.initialise()?;
        ctx.check_error("initialising the particle state")?;
        Ok(sim)
    }

    /// Uniforms that do not change during a run: emitters, masses, forces, colliders, samplers.
    fn set_constants(&self, p: &Program) {
        set_constants_for(
            p,
            &self.scene,
            &self.fields,
            [self.width, self.height],
            self.seed,
            self.features.types,
        );
    }

    fn bind_fields(&self) {
        if let Some((t, _)) = &self.fields.flow {
            t.bind(unit::FLOW);
        }
        if let Some((t, _)) = &self.fields.height {
            t.bind(unit::HEIGHT);
        }
        if let Some((t, _)) = &self.fields.sdf {
            t.bind(unit::SDF);
        }
    }

    /// Draws the initial state with `sim/init.frag` (one pass per target) and restarts the clock.
    fn initialise(&mut self) -> Result<()> {
        let mut defines = self.features.defines();
        let program = |out: &str, d: &mut Defines| -> Result<Program> {
            let mut d = d.clone();
            d.push((out.to_owned(), "1".to_owned()));
            let p = Program::new(&self.ctx, FULLSCREEN_VERTEX, "sim/init.frag", &d)?;
            self.set_constants(&p);
            Ok(p)
        };
        let state = program("OUT_STATE", &mut defines)?;
        let statics = program("OUT_STATIC", &mut defines)?;
        self.bind_fields();
        self.pass.draw(&statics, &self.statics);
        match &self.state {
            State::Explicit(pp) => {
                // Both sides, so rows a live-row restricted pass never touches are dead too.
                self.pass.draw(&state, pp.front());
                self.pass.draw(&state, pp.back());
            }
            State::Verlet { ring, current } => {
                let previous = program("OUT_PREVIOUS", &mut defines)?;
                for (i, fb) in ring.iter().enumerate() {
                    let p = if i == (current + 2) % 3 {
                        &previous
                    } else {
                        &state
                    };
                    self.pass.draw(p, fb);
                }
            }
        }
        self.step = 0;
        self.time = 0.0;
        Ok(())
    }

    /// The current positions (xyz, remaining life).
    pub fn positions(&self) -> &Texture {
        match &self.state {
            State::Explicit(pp) => pp.front().texture(0),
            State::Verlet { ring, current } => ring[*current].texture(0),
        }
    }

    /// The current velocities (explicit integrators only).
    pub fn velocities(&self) -> Option<&Texture> {
        match &self.state {
            State::Explicit(pp) => Some(pp.front().texture(1)),
            State::Verlet { .. } => None,
        }
    }

    /// The previous positions (Verlet only).
    pub fn previous(&self) -> Option<&Texture> {
        match &self.state {
            State::Explicit(_) => None,
            State::Verlet { ring, current } => Some(ring[(current + 2) % 3].texture(0)),
        }
    }

    /// The static texture (birth time or phase, type, total life, random number).
    pub fn statics(&self) -> &Texture {
        self.statics.texture(0)
    }

    /// The state framebuffer being read now (positions and, for explicit integrators,
    /// velocities).
    pub fn front(&self) -> &Framebuffer {
        match &self.state {
            State::Explicit(pp) => pp.front(),
            State::Verlet { ring, current } => &ring[*current],
        }
    }

    /// What the scene compiles and runs.
    pub fn features(&self) -> &Features {
        &self.features
    }

    /// The scene.
    pub fn scene(&self) -> &SceneFile {
        &self.scene
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

    /// One time step: allocator births, then the integration pass, then the swap, then the
    /// collision stage (scenes with `[collisions]`).
    pub fn step(&mut self) -> Result<()> {
        self.step_without_collisions()?;
        self.collide()
    }

    /// [`step`](Self::step) without the collision stage: the collisionless motion. For warming a
    /// benchmark up quickly: the collision stage's sorts and detection are data-oblivious, so
    /// what they cost later does not depend on whether earlier steps resolved collisions.
    pub fn step_without_collisions(&mut self) -> Result<()> {
        if self.allocator.is_some() {
            self.emit()?;
        }
        self.integrate_only();
        Ok(())
    }

    /// The collision stage (scenes with `[collisions]`).
    pub fn collisions(&self) -> Option<&super::collide::Collisions> {
        self.collisions.as_ref()
    }

    /// Runs the collision stage on the current state (part of [`step`](Self::step); public for
    /// benchmarks, which time it alone).
    pub fn collide(&mut self) -> Result<()> {
        if self.collisions.is_none() {
            return Ok(());
        }
        self.bind_fields();
        let Some(c) = self.collisions.as_mut() else {
            return Ok(());
        };
        let State::Explicit(pp) = &mut self.state else {
            return Err(Error::InvalidInput(
                "collisions need the explicit integrators".into(),
            ));
        };
        let mut inv_mass = [1.0 / self.scene.particles.mass; 4];
        for (k, e) in self.scene.emitters.all().enumerate() {
            inv_mass[k] = 1.0 / e.mass.unwrap_or(self.scene.particles.mass);
        }
        let fields = &self.fields;
        let scene = &self.scene;
        let (size, seed, types) = ([self.width, self.height], self.seed, self.features.types);
        let set = |p: &Program| set_constants_for(p, scene, fields, size, seed, types);
        c.run(
            pp,
            &self.statics,
            self.scene.time.dt,
            Vec4::from(inv_mass),
            set,
        )?;
        Ok(())
    }

    /// The integration pass alone (also what benchmarks time), then the swap.
    pub fn integrate_only(&mut self) {
        let rows = self.active_rows();
        let p = &self.integrate;
        p.bind();
        p.set_f32("u_time", self.time as f32);
        self.statics.texture(0).bind(unit::STATIC);
        self.bind_fields();
        match &mut self.state {
            State::Explicit(pp) => {
                pp.front().texture(0).bind(unit::POSITION);
                pp.front().texture(1).bind(unit::VELOCITY);
                if rows > 0 {
                    self.pass.draw_rows(p, pp.back(), 0, rows);
                }
                pp.swap();
            }
            State::Verlet { ring, current } => {
                let (prev, next) = ((*current + 2) % 3, (*current + 1) % 3);
                ring[*current].texture(0).bind(unit::POSITION);
                ring[prev].texture(0).bind(unit::VELOCITY);
                if rows > 0 {
                    self.pass.draw_rows(p, &ring[next], 0, rows);
                }
                *current = next;
            }
        }
        self.step += 1;
        self.time = self.step as f64 * self.scene.time.dt as f64;
    }

    /// Latta §3.4.1: frees the indices of particles that died (on the CPU's clock, a few steps
    /// late so that both sides of the ping-pong hold them dead), allocates indices for this
    /// step's births and draws them as points.
    fn emit(&mut self) -> Result<()> {
        let dt = self.scene.time.dt as f64;
        let now = self.time;
        let Some(alloc) = self.allocator.as_mut() else {
            return Ok(());
        };
        alloc.reclaim(now - 3.0 * dt);
        let mut data: Vec<f32> = Vec::new();
        for (k, e) in self.scene.emitters.allocator.iter().enumerate() {
            self.owed[k] += e.rate.unwrap_or(0.0) as f64 * dt;
            let n = self.owed[k].floor();
            self.owed[k] -= n;
            let u = &self.emitters[k];
            for _ in 0..n as u64 {
                let mut rng = Rng::new(self.emitted as u32, self.step as u32, self.seed);
                self.emitted += 1;
                let life = u.life(&mut rng);
                let Some(index) = alloc
                    .allocate_with_lifetime(now, life as f64)
                    .map_err(|e| Error::InvalidInput(e.to_string()))?
                else {
                    self.dropped += 1;
                    continue;
                };
                let x = u.position(&mut rng);
                let v = u.velocity(&mut rng);
                data.push(index as f32);
                data.extend_from_slice(&x.extend(life).to_array());
                data.extend_from_slice(&v.extend(0.0).to_array());
                data.extend_from_slice(&[now as f32, k as f32, life, rng.uniform()]);
            }
        }
        if data.is_empty() {
            return Ok(());
        }
        let buffer = Buffer::with_data(
            &self.ctx,
            "births",
            glow::ARRAY_BUFFER,
            bytemuck::cast_slice(&data),
            glow::STREAM_DRAW,
        )?;
        let stride = (EMIT_FLOATS * 4) as i32;
        let attr = |location: u32, components: i32, offset: i32| Attribute {
            buffer: &buffer,
            location,
            components,
            stride,
            offset: offset * 4,
        };
        let vao = VertexArray::with_attributes(
            &self.ctx,
            "births",
            &[attr(0, 1, 0), attr(1, 4, 1), attr(2, 4, 5), attr(3, 4, 9)],
        )?;
        let count = (data.len() / EMIT_FLOATS) as i32;
        let draw = |p: &Program, fb: &Framebuffer| {
            p.bind();
            fb.bind();
            vao.bind();
            // SAFETY: program, framebuffer and vertex array are bound and alive.
            unsafe {
                self.ctx.disable(glow::BLEND);
                self.ctx.draw_arrays(glow::POINTS, 0, count);
            }
        };
        self.bind_fields();
        if let Some(p) = &self.emit_static {
            draw(p, &self.statics);
        }
        if let Some(p) = &self.emit_state {
            draw(p, self.front());
        }
        if let (Some(p), State::Verlet { ring, current }) = (&self.emit_previous, &self.state) {
            draw(p, &ring[(current + 2) % 3]);
        }
        Ok(())
    }

    /// Reads the current positions back (4 floats per texel).
    pub fn read_positions(&self) -> Result<Vec<f32>> {
        self.positions().read_f32()
    }

    /// Reads the current velocities back; for Verlet, the implied (x - x_prev) / dt.
    pub fn read_velocities(&self) -> Result<Vec<f32>> {
        match self.velocities() {
            Some(t) => t.read_f32(),
            None => {
                let x = self.read_positions()?;
                let xp = self.previous().map(|t| t.read_f32()).transpose()?;
                let xp = xp.unwrap_or_else(|| x.clone());
                let dt = self.scene.time.dt;
                Ok(x.chunks(4)
                    .zip(xp.chunks(4))
                    .flat_map(|(a, b)| {
                        [
                            (a[0] - b[0]) / dt,
                            (a[1] - b[1]) / dt,
                            (a[2] - b[2]) / dt,
                            0.0,
                        ]
                    })
                    .collect())
            }
        }
    }

    /// Replaces the whole state (for tests and experiments): 4 floats per texel each, positions
    /// (xyz, life), velocities (xyz, 0) and statics (birth, type, total life, random). Verlet
    /// derives the previous positions on the GPU with the second-order start
    /// x_prev = x - v dt + a dt^2 / 2.
    pub fn set_state(
        &mut self,
        positions: &[f32],
        velocities: &[f32],
        statics: &[f32],
    ) -> Result<()> {
        let n = self.width as usize * self.height as usize * 4;
        if positions.len() != n || velocities.len() != n || statics.len() != n {
            return Err(Error::InvalidInput(format!(
                "set_state needs {n} floats per texture ({}x{} texels, 4 each)",
                self.width, self.height
            )));
        }
        self.statics.texture(0).upload_f32(statics)?;
        match &self.state {
            State::Explicit(pp) => {
                pp.front().texture(0).upload_f32(positions)?;
                pp.front().texture(1).upload_f32(velocities)?;
            }
            State::Verlet { ring, current } => {
                ring[*current].texture(0).upload_f32(positions)?;
                let v = state_texture(
                    &self.ctx,
                    "start velocity",
                    self.width,
                    self.height,
                    TextureFormat::Rgba32F,
                )?;
                v.upload_f32(velocities)?;
                let p = self.start.as_ref().expect("Verlet has a start program");
                p.bind();
                ring[*current].texture(0).bind(unit::POSITION);
                v.bind(unit::VELOCITY);
                self.statics.texture(0).bind(unit::STATIC);
                self.bind_fields();
                self.pass.draw(p, &ring[(current + 2) % 3]);
            }
        }
        self.ctx.check_error("setting the particle state")
    }
}

/// Sets the uniforms that do not change during a run (emitters, masses, forces, colliders,
/// samplers) on `p`; uniforms the program lacks are skipped.
fn set_constants_for(
    p: &Program,
    s: &SceneFile,
    fields: &Fields,
    size: [u32; 2],
    seed: u32,
    types: usize,
) {
    p.bind();
    p.set_i32("u_position", unit::POSITION as i32);
    p.set_i32("u_velocity", unit::VELOCITY as i32);
    p.set_i32("u_previous", unit::VELOCITY as i32);
    p.set_i32("u_static", unit::STATIC as i32);
    p.set_i32("u_flow", unit::FLOW as i32);
    p.set_i32("u_height", unit::HEIGHT as i32);
    p.set_i32("u_sdf", unit::SDF as i32);
    p.set_i32("u_width", size[0] as i32);
    p.set_ivec2("u_size", size[0] as i32, size[1] as i32);
    p.set_u32("u_seed", seed);
    p.set_f32("u_dt", s.time.dt);
    p.set_i32("u_emitters", types as i32);
    let mut inv_mass = [1.0 / s.particles.mass; 4];
    let mut cycle = [1.0f32; 4];
    for (k, e) in s.emitters.all().enumerate() {
        inv_mass[k] = 1.0 / e.mass.unwrap_or(s.particles.mass);
        cycle[k] = e.cycle.unwrap_or(1.0);
    }
    p.set_vec4("u_inv_mass", Vec4::from(inv_mass));
    p.set_vec4("u_cycle", Vec4::from(cycle));
    for (k, e) in s.emitters.all().map(EmitterUniforms::new).enumerate() {
        p.set_vec4(&format!("u_em_center[{k}]"), e.center);
        p.set_vec4(&format!("u_em_size[{k}]"), e.size);
        p.set_vec4(&format!("u_em_normal[{k}]"), e.normal);
        p.set_vec4(&format!("u_em_dir[{k}]"), e.dir);
        p.set_vec4(&format!("u_em_range[{k}]"), e.range);
    }
    let f = &s.forces;
    let gravity: Vec3 = f.gravity.iter().map(|g| v3(g.acceleration)).sum();
    p.set_vec3("u_gravity", gravity);
    p.set_f32("u_damping", f.damping.iter().map(|d| d.rate).sum());
    for (i, a) in f.attractor.iter().enumerate() {
        p.set_vec4(
            &format!("u_attractor[{i}]"),
            v3(a.position).extend(a.strength),
        );
        p.set_vec4(
            &format!("u_attractor_shape[{i}]"),
            Vec4::new(
                (a.falloff == scene::Falloff::Constant) as u8 as f32,
                a.max_distance.unwrap_or(-1.0),
                a.softening,
                0.0,
            ),
        );
    }
    for (i, sp) in f.spring.iter().enumerate() {
        p.set_vec4(
            &format!("u_spring[{i}]"),
            v3(sp.anchor).extend(sp.stiffness),
        );
    }
    for (i, v) in f.vortex.iter().enumerate() {
        p.set_vec4(&format!("u_vortex[{i}]"), v3(v.point).extend(v.strength));
        p.set_vec3(&format!("u_vortex_axis[{i}]"), v3(v.axis).normalize());
    }
    if let (Some(w), Some((_, field))) = (f.wind.first(), &fields.flow) {
        p.set_vec3("u_flow_min", v3(w.bounds[0]));
        p.set_vec3("u_flow_max", v3(w.bounds[1]));
        let [rx, ry, rz] = field.resolution().map(|r| r as i32);
        p.set_ivec3("u_flow_res", rx, ry, rz);
        p.set_f32("u_drag", w.drag);
    }
    let c = &s.colliders;
    p.set_f32("u_slow_speed", c.slow_speed);
    let resp = |mu: f32, eps: f32| glam::Vec2::new(mu, eps);
    for (i, pl) in c.plane.iter().enumerate() {
        let n = v3(pl.normal).normalize();
        p.set_vec4(&format!("u_plane[{i}]"), n.extend(n.dot(v3(pl.point))));
        p.set_vec2(
            &format!("u_plane_resp[{i}]"),
            resp(pl.friction, pl.resilience),
        );
    }
    for (i, sp) in c.sphere.iter().enumerate() {
        p.set_vec4(&format!("u_sphere[{i}]"), v3(sp.center).extend(sp.radius));
        p.set_vec2(
            &format!("u_sphere_resp[{i}]"),
            resp(sp.friction, sp.resilience),
        );
    }
    for (i, b) in c.boxes.iter().enumerate() {
        p.set_vec3(&format!("u_box_min[{i}]"), v3(b.min));
        p.set_vec3(&format!("u_box_max[{i}]"), v3(b.max));
        p.set_vec2(&format!("u_box_resp[{i}]"), resp(b.friction, b.resilience));
    }
    if let Some(h) = c.heightfield.first() {
        p.set_vec4("u_height_extent", Vec4::from(h.extent));
        p.set_ivec2("u_height_res", h.resolution as i32, h.resolution as i32);
        p.set_vec2("u_height_resp", resp(h.friction, h.resilience));
    }
    if let Some(d) = c.sdf.first() {
        p.set_vec3("u_sdf_min", v3(d.bounds[0]));
        p.set_vec3("u_sdf_max", v3(d.bounds[1]));
        let r = d.resolution as i32;
        p.set_ivec3("u_sdf_res", r, r, r);
        p.set_vec2("u_sdf_resp", resp(d.friction, d.resilience));
    }
}
