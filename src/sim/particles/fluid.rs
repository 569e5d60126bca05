//! The SPH stage of a scene with `[fluid]` (src/sim/fluid/) in the particle pipeline: the
//! particles placed on their lattice at the start, the fluid's passes as the collision stage,
//! its counts and per-frame figures.
//!
//! The fluid writes the state in cell order every step, so the user states (`[[state]]`)
//! follow: after the fluid's passes each is gathered in the same order (a pass each, by the
//! fluid's sorted keys), and each state with `pair` then exchanges with its neighbours over the
//! fluid's sorted layout and search (`glsl/collide/exchange.frag`, as the collision stage's
//! exchange: src/sim/collide/carry.rs). Every exchange reads the values before any of them.

use super::{ParticleSim, State};
use crate::error::{Error, Result};
use crate::gl::{Program, Sampled, Uniform};
use crate::scene::SceneFile;
use crate::sim::fluid::FluidStats;
use crate::sim::state::{POSITION, STATIC, VELOCITY};

/// The exchange passes (`pair`) of a scene with `[fluid]`, each with its state's index and
/// `radius`; none without `[fluid]` (the collision stage has its own).
pub(super) fn exchange_programs(
    ctx: &crate::gl::Context,
    scene: &SceneFile,
    defines: &crate::gl::Defines,
) -> Result<Vec<(usize, Program, f32)>> {
    match &scene.fluid {
        Some(_) => Ok(super::user_state::exchange_programs(ctx, scene, defines)?
            .into_iter()
            .map(|(i, p)| (i, p, scene.state[i].radius.unwrap_or(0.0)))
            .collect()),
        None => Ok(Vec::new()),
    }
}

/// The passes that carry `states` user states along the fluid's sort and exchange those named in
/// `exchanges`, as `texflow scene passes` lists them (after the fluid's passes).
pub(super) fn fluid_carry_passes(states: usize, exchanges: &[String]) -> Vec<String> {
    let mut out = Vec::new();
    if states > 0 {
        out.push(format!(
            "carry {states} user state(s): gathered in the fluid's cell order (a pass each)"
        ));
    }
    out.extend(exchanges.iter().map(|name| {
        format!(
            "exchange {name} (after the fluid's sort): {name} += the sum of `pair` over the live \
             neighbours within its radius (the fluid's search, of the cells that can hold them) \
             [swapped in after every exchange is drawn]"
        )
    }));
    out
}

impl ParticleSim {
    /// Places the fluid's particles on the lattice of their box emitters (after the initial
    /// state is drawn).
    pub(super) fn place_fluid(&mut self, scene: &SceneFile) {
        if let (Some(f), State::Explicit(pp)) = (&self.fluid, &mut self.state) {
            f.place(scene, pp);
        }
    }

    /// One step of the fluid's passes on the integrated state.
    pub(super) fn run_fluid(&mut self) -> Result<()> {
        let (Some(f), State::Explicit(pp)) = (self.fluid.as_mut(), &mut self.state) else {
            return Err(Error::InvalidInput(
                "[fluid] needs an explicit integrator".into(),
            ));
        };
        f.run(pp, &mut self.statics, self.params.time.dt, &self.constants)?;
        self.carry_fluid_states()
    }

    /// The user states gathered in the fluid's new order, then the exchanges (`pair`).
    fn carry_fluid_states(&mut self) -> Result<()> {
        let (Some(f), Some(user)) = (&self.fluid, self.user.as_mut()) else {
            return Ok(());
        };
        for pp in user.states_mut().iter_mut() {
            f.gather_sorted(&[pp.front().only_texture()], pp.back())?;
            pp.swap();
        }
        let samplers = user.samplers();
        let l = f.layout();
        for (i, p, radius) in &self.fluid_exchange {
            let clock = self.constants.for_draw(
                p,
                f.search().uniforms().into_iter().chain([
                    ("u_pair_radius", Uniform::F32(*radius)),
                    ("u_search_radius", Uniform::F32(*radius)),
                    ("u_dt", Uniform::F32(self.params.time.dt)),
                    ("u_time", Uniform::F32(self.time as f32)),
                ]),
            );
            let mut textures: Vec<(&str, Sampled)> = f.search().textures(f.sorted_keys());
            textures.extend([
                ("u_position", l.texture(POSITION).into()),
                ("u_velocity", l.texture(VELOCITY).into()),
                // The layout's statics were handed to the state by the fluid's step.
                ("u_static", self.statics.texture(STATIC).into()),
            ]);
            textures.extend(samplers.iter().map(|(n, t)| (n.as_str(), (*t).into())));
            self.pass.draw(p, &textures, &clock, user.back(*i));
        }
        for (i, ..) in &self.fluid_exchange {
            user.swap(*i);
        }
        Ok(())
    }

    /// The draws of the user states' carry and exchanges after the fluid's passes, for the
    /// lines of [`fluid_carry_passes`].
    pub(super) fn fluid_carry_draws(&self) -> Vec<crate::gl::PassDraw> {
        use crate::gl::PassDraw;
        let states = self.state_names.len() as u64;
        let mut out = Vec::new();
        if self.fluid.is_some() && states > 0 {
            let gather = crate::sort::Sorter::gather_program();
            out.push(PassDraw::new("carry", gather, states));
        }
        for (i, p, _) in &self.fluid_exchange {
            let name = &self.state_names[*i];
            out.push(PassDraw::of(format!("exchange {name} ("), p, 1));
        }
        out
    }

    /// Fluid searches that hit their bound, over the run (one read-back).
    pub(super) fn fluid_truncated(&self) -> Result<u64> {
        self.fluid
            .as_ref()
            .map_or(Ok(0), |f| f.truncated_searches())
    }

    /// The fluid's density error and energy now (scenes with `[fluid]`; read-backs of the state
    /// and the last density pass).
    pub fn fluid_stats(&self) -> Result<Option<FluidStats>> {
        let (Some(f), State::Explicit(pp)) = (&self.fluid, &self.state) else {
            return Ok(None);
        };
        let front = pp.front();
        f.stats(front.texture(POSITION), front.texture(VELOCITY))
            .map(Some)
    }
}
