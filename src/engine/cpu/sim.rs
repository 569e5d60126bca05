//! [`CpuSim`]: the particle state in three arrays in main memory, stepped in parallel on every
//! core with rayon; the CPU twin of the GPU's births, steps and deaths (see the module above).

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::scene::{EmitterKind, Integrator, Precision, SceneFile};
use crate::sim::emit::{EmitterUniforms, Rng};
use crate::sim::particles::{Emission, Features};
use crate::sim::reference::Reference;

/// Particles per rayon task: large enough that the split costs nothing next to the work.
pub(super) const CHUNK: usize = 4096;

/// How particles are born (what the CPU twins of the GPU's birth code need).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Birth {
    /// UberFlow §4.1: phase and life in the static data, respawn every cycle.
    Timestamp,
    /// Every particle spawned at the start (with or without a life).
    Initial,
}

/// What the step of one particle needs besides its state.
#[derive(Debug, Clone)]
struct Physics {
    reference: Reference,
    birth: Birth,
    emitters: Vec<EmitterUniforms>,
    cycles: [f32; 4],
    seed: u32,
}

/// The CPU simulation of a scene: the state in main memory, stepped on all cores.
#[derive(Debug, Clone)]
pub struct CpuSim {
    pub(super) scene: SceneFile,
    physics: Physics,
    pub(super) width: u32,
    pub(super) height: u32,
    pub(super) positions: Vec<Vec4>,
    pub(super) velocities: Vec<Vec3>,
    pub(super) statics: Vec<Vec4>,
    step: u64,
    pub(super) time: f64,
    /// Some emitter value is a curve: the emitters are taken at every step's start, as the
    /// GPU's spawn uniforms are.
    animated: bool,
}

pub(super) fn unsupported(scene: &SceneFile, what: &str) -> Error {
    Error::InvalidInput(format!(
        "scene `{}`: the CPU engine (E5) does not cover {what}",
        scene.name
    ))
}

impl CpuSim {
    /// The state of `scene` at step 0, as `ParticleSim::new` draws it for the same `seed` (the
    /// seed is folded with [`crate::engine::shader_seed`], as the GPU engine does).
    pub fn new(scene: &SceneFile, seed: u64) -> Result<Self> {
        scene.check()?;
        let features = Features::of(scene);
        refuse_unsupported(scene, &features)?;
        let birth = match features.emission {
            Emission::Timestamp => Birth::Timestamp,
            Emission::Initial { .. } => Birth::Initial,
            Emission::Allocator(_) => return Err(unsupported(scene, "allocator emission")),
        };
        // The reference refuses time-stamp scenes (their birth needs the spawn streams, done
        // here); it steps them as permanent particles of the same types, and the time-stamp code
        // below decides who is born, alive or dead and what the remaining life is.
        let reference = match birth {
            Birth::Timestamp => {
                let mut s = scene.clone();
                let mut initial = std::mem::take(&mut s.emitters.timestamp);
                for e in &mut initial {
                    // The reference steps them; their spawn is done here, curves and all.
                    *e = e.frozen(0.0);
                    e.cycle = None;
                    e.life = None;
                }
                s.emitters.initial = initial;
                Reference::new(&s)?
            }
            Birth::Initial => Reference::new(scene)?,
        };
        let emitters: Vec<EmitterUniforms> =
            scene.emitters.all().map(EmitterUniforms::new).collect();
        // `u_cycle`, from the integration block the GPU uploads.
        let cycles = crate::sim::params::Integration::of(scene).cycle;
        let [width, height] = scene.particles.size;
        let n = width as usize * height as usize;
        let seed = crate::engine::shader_seed(seed);
        let mut sim = CpuSim {
            scene: scene.clone(),
            physics: Physics {
                reference,
                birth,
                emitters,
                cycles,
                seed,
            },
            width,
            height,
            positions: vec![Vec4::ZERO; n],
            velocities: vec![Vec3::ZERO; n],
            statics: vec![Vec4::ZERO; n],
            step: 0,
            time: 0.0,
            animated: crate::scene::has_curves(scene),
        };
        sim.initialise(features.types, features.life());
        Ok(sim)
    }

    /// The twin of `glsl/sim/init.frag`.
    fn initialise(&mut self, types: usize, life: bool) {
        let (birth, seed) = (self.physics.birth, self.physics.seed);
        let (emitters, cycles) = (&self.physics.emitters, self.physics.cycles);
        self.positions
            .par_iter_mut()
            .zip(self.velocities.par_iter_mut())
            .zip(self.statics.par_iter_mut())
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(i, ((p, v), st))| {
                let ty = i % types;
                let em = &emitters[ty];
                // Stream 0xffffffff is the initial one; time-stamp generations use 0, 1, 2, ...
                let mut rng = Rng::new(i as u32, u32::MAX, seed);
                *p = Vec4::new(f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0);
                *v = Vec3::ZERO;
                *st = Vec4::new(0.0, ty as f32, 0.0, 0.0);
                match birth {
                    Birth::Initial => {
                        let x = em.position(&mut rng);
                        *v = em.velocity(&mut rng);
                        p.w = if life {
                            st.z = em.life(&mut rng);
                            st.z
                        } else {
                            1.0
                        };
                        *p = x.extend(p.w);
                    }
                    Birth::Timestamp => {
                        st.x = rng.uniform() * cycles[ty];
                        st.z = em.life(&mut rng);
                        p.w = -1.0;
                        if st.x <= 0.0 {
                            // A cycle that begins at time 0 is born here (init.frag).
                            let mut born = Rng::new(i as u32, 0, seed);
                            *p = em.position(&mut born).extend(st.z);
                            *v = em.velocity(&mut born);
                        }
                    }
                }
                st.w = rng.uniform();
            });
        self.step = 0;
        self.time = 0.0;
    }

    /// One time step of every particle, in parallel on all cores: the twin of one
    /// `sim/integrate.frag` pass and its swap.
    pub fn step(&mut self) {
        // The two clocks the GPU pass gets: u_time and u_time_next, the next step's u_time
        // bit for bit.
        let dt = self.scene.time.dt as f64;
        let clock = [self.time as f32, ((self.step + 1) as f64 * dt) as f32];
        if self.animated {
            let at = |e| EmitterUniforms::at(e, clock[0]);
            self.physics.emitters = self.scene.emitters.all().map(at).collect();
        }
        let physics = &self.physics;
        let statics = &self.statics;
        self.positions
            .par_iter_mut()
            .zip(self.velocities.par_iter_mut())
            .enumerate()
            .with_min_len(CHUNK)
            .for_each(|(i, (p, v))| physics.step(i as u32, p, v, statics[i], clock));
        self.step += 1;
        self.time = self.step as f64 * self.scene.time.dt as f64;
    }

    /// Advances one frame: the scene's `substeps` steps.
    pub fn advance_frame(&mut self) {
        for _ in 0..self.scene.time.substeps {
            self.step();
        }
    }

    /// Positions (xyz, remaining life) of every particle, in index order (texel order of the GPU
    /// state). Dead and unborn particles: xyz = +inf, life <= 0.
    pub fn positions(&self) -> &[Vec4] {
        &self.positions
    }

    /// Velocities, in index order (zero for dead and unborn particles).
    pub fn velocities(&self) -> &[Vec3] {
        &self.velocities
    }

    /// Static data (birth time or phase, type, total life, random number), in index order.
    pub fn statics(&self) -> &[Vec4] {
        &self.statics
    }

    /// Whether particle `i` is drawn: a finite position and a remaining life above 0 (the test of
    /// `render/particle.vert`).
    pub fn is_live(&self, i: usize) -> bool {
        live(self.positions[i])
    }

    /// Particles drawn now.
    pub fn live_count(&self) -> usize {
        self.positions.par_iter().filter(|p| live(**p)).count()
    }

    /// The scene.
    pub fn scene(&self) -> &SceneFile {
        &self.scene
    }

    /// State size (particles = width × height).
    pub fn size(&self) -> [u32; 2] {
        [self.width, self.height]
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// Simulation time in seconds.
    pub fn time(&self) -> f64 {
        self.time
    }
}

impl Physics {
    /// One particle's step; `[u_time, u_time_next]` are the simulation times at the start and
    /// the end of the step, as the shader's uniforms get them.
    fn step(&self, index: u32, p: &mut Vec4, v: &mut Vec3, st: Vec4, clock: [f32; 2]) {
        let [u_time, u_time_next] = clock;
        let ty = (st.y as i32).clamp(0, 3) as usize;
        let dt = self.reference.dt();
        match self.birth {
            Birth::Initial => {
                let (x, vn, life) = self.reference.step_explicit(p.truncate(), *v, p.w, ty);
                *p = x.extend(life);
                *v = vn;
            }
            Birth::Timestamp => {
                // The TIMESTAMP block of sim/integrate.frag (timestamp_step), operation for
                // operation: a cycle begins in the step whose start and end lie in different
                // cycles.
                let cycle = self.cycles[ty];
                let (rel0, rel1) = (u_time - st.x, u_time_next - st.x);
                let (g0, generation) = ((rel0 / cycle).floor(), (rel1 / cycle).floor());
                if generation < 0.0 {
                    *p = Vec4::new(f32::INFINITY, f32::INFINITY, f32::INFINITY, -1.0);
                    *v = Vec3::ZERO;
                    return;
                }
                let begins = rel1 >= 0.0 && generation > g0;
                let end_age = rel1 - generation * cycle;
                let age = if begins {
                    end_age.clamp(0.0, dt)
                } else {
                    end_age
                };
                if age >= st.z {
                    *p = Vec4::new(f32::INFINITY, f32::INFINITY, f32::INFINITY, 0.0);
                    *v = Vec3::ZERO;
                    return;
                }
                let mut rng = Rng::new(index, generation as u32, self.seed);
                if begins {
                    let em = &self.emitters[ty];
                    let x0 = em.position(&mut rng);
                    *v = em.velocity(&mut rng);
                    *p = x0.extend(st.z - age);
                    return;
                }
                let life = st.z - age;
                let (x, vn, _) = self.reference.step_explicit(p.truncate(), *v, life, ty);
                *p = x.extend(life);
                *v = vn;
            }
        }
    }
}

pub(super) fn live(p: Vec4) -> bool {
    crate::sim::particle_live(p.to_array())
}

/// What the CPU engine does not twin, refused with a message that names it (before any work).
fn refuse_unsupported(scene: &SceneFile, features: &Features) -> Result<()> {
    if scene.fire.is_some() {
        return Err(unsupported(scene, "the thesis's fire"));
    }
    if scene.integrator == Integrator::Verlet {
        return Err(unsupported(scene, "Verlet integration"));
    }
    if scene.simulation == crate::scene::StateModel::Stateless {
        return Err(unsupported(scene, "the stateless simulation"));
    }
    if scene.particles.precision == Precision::Fp24 {
        return Err(unsupported(scene, "fp24 precision"));
    }
    if scene.collisions.is_some() {
        return Err(unsupported(scene, "collisions between particles"));
    }
    if scene.fluid.is_some() {
        return Err(unsupported(scene, "the fluid ([fluid])"));
    }
    if features.emitter_forces {
        return Err(unsupported(
            scene,
            "forces per emitter ([[emitters.*.forces.*]]): give them in [[forces.*]], \
         or run the scene on the GPU engine",
        ));
    }
    for kind in EmitterKind::ALL {
        let refused = match kind {
            EmitterKind::Child => Some("child emitters"),
            // Allocator births are refused with the other births (`CpuSim::new`).
            EmitterKind::Allocator | EmitterKind::Timestamp | EmitterKind::Initial => None,
        };
        if let Some(what) = refused.filter(|_| !scene.emitters.of_kind(kind).is_empty()) {
            return Err(unsupported(scene, what));
        }
    }
    if scene.emitters.all().any(|e| !e.bursts.is_empty()) {
        return Err(unsupported(scene, "bursts"));
    }
    let r = &scene.render;
    if !scene.state.is_empty() || r.color.is_some() || r.size.is_some() || r.rotation.is_some() {
        return Err(unsupported(
            scene,
            "user state, render.color, render.size and render.rotation ([[state]]: GLSL \
             expressions run by the GPU's passes); run the scene on the GPU engine",
        ));
    }
    Ok(())
}
