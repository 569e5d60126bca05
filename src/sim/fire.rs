//! The fire of the GLSL thesis (§3-4, Listings 1-2): a position texture (xyz, remaining life) and
//! a velocity texture (xyz, remaining wait), both written by one pass per step through MRT.

use glam::Vec3;

use crate::error::{Error, Result};
use crate::gl::{
    Context, Defines, FullscreenPass, PingPong, Program, Texture, TextureFormat, Uniform,
    FULLSCREEN_VERTEX,
};

/// Parameters of the fire pass (see `glsl/sim/fire.frag`). Units: metres, seconds.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FireParams {
    /// Centre of the emitter disc (in the xz plane).
    pub emitter_center: Vec3,
    /// Radius of the emitter disc.
    pub emitter_radius: f32,
    /// Mean upward speed at birth (each particle gets 0.75 to 1.25 times it).
    pub speed: f32,
    /// Radius of the random sideways velocity at birth.
    pub spread: f32,
    /// Sideways velocity towards the axis per metre off the axis, which shapes the flame.
    pub converge: f32,
    /// Buoyancy: the thesis's negative gravity, an acceleration.
    pub buoyancy: Vec3,
    /// Amplitude of the random acceleration per step (turbulence).
    pub turbulence: f32,
    /// Linear damping rate (1/s).
    pub damping: f32,
    /// Shortest life.
    pub life_min: f32,
    /// Longest life.
    pub life_max: f32,
    /// Length of every particle's cycle (life plus wait); emission rate is N / max_age.
    pub max_age: f32,
}

impl Default for FireParams {
    fn default() -> Self {
        FireParams {
            emitter_center: Vec3::ZERO,
            emitter_radius: 0.3,
            speed: 0.8,
            spread: 0.15,
            converge: 1.1,
            buoyancy: Vec3::new(0.0, 2.5, 0.0),
            turbulence: 4.0,
            damping: 0.7,
            life_min: 0.6,
            life_max: 1.4,
            max_age: 1.6,
        }
    }
}

impl From<&crate::scene::Fire> for FireParams {
    fn from(f: &crate::scene::Fire) -> FireParams {
        FireParams {
            emitter_center: Vec3::from(f.emitter_center),
            emitter_radius: f.emitter_radius,
            speed: f.speed,
            spread: f.spread,
            converge: f.converge,
            buoyancy: Vec3::from(f.buoyancy),
            turbulence: f.turbulence,
            damping: f.damping,
            life_min: f.life[0],
            life_max: f.life[1],
            max_age: f.max_age,
        }
    }
}

impl From<&FireParams> for crate::scene::Fire {
    fn from(p: &FireParams) -> crate::scene::Fire {
        crate::scene::Fire {
            emitter_center: p.emitter_center.to_array(),
            emitter_radius: p.emitter_radius,
            speed: p.speed,
            spread: p.spread,
            converge: p.converge,
            buoyancy: p.buoyancy.to_array(),
            turbulence: p.turbulence,
            damping: p.damping,
            life: [p.life_min, p.life_max],
            max_age: p.max_age,
        }
    }
}

impl FireParams {
    /// Rejects values the pass cannot give a meaning to at steps of `dt` seconds: the rules of
    /// a scene's `[fire]` section ([`crate::scene::fire_section`]), named by their keys.
    pub fn validate(&self, dt: f32) -> Result<()> {
        crate::scene::fire_section(&self.into(), dt).map_err(|e| {
            Error::InvalidInput(format!("fire parameters: {}: {}", e.key(), e.message))
        })
    }

    /// The fraction of particles alive in the steady state: mean life over cycle length.
    pub fn expected_live_fraction(&self) -> f64 {
        0.5 * (self.life_min as f64 + self.life_max as f64) / self.max_age as f64
    }
}

/// The fire simulation: its ping-pong state and its two programs.
#[derive(Debug)]
pub struct FireSim {
    state: PingPong,
    init: Program,
    physics: Program,
    pass: FullscreenPass,
    params: FireParams,
    seed: u32,
    step: u64,
    dt: f32,
    substeps: u32,
}

/// The fire's state attachments: position (xyz, remaining life) and velocity (xyz, remaining
/// wait), by the names the particle state uses.
pub use super::state::{POSITION, VELOCITY};

impl FireSim {
    /// Makes a `width`×`height` state (one particle per texel) and draws the initial state.
    /// It steps by 1/60 s, once a frame, until [`set_time_step`](Self::set_time_step).
    pub fn new(
        ctx: &Context,
        width: u32,
        height: u32,
        params: FireParams,
        seed: u32,
    ) -> Result<Self> {
        let dt = 1.0 / 60.0;
        params.validate(dt)?;
        crate::gl::check_size(ctx, "particle texture", width, height)?;
        let state = PingPong::new(
            ctx,
            "fire",
            &[POSITION, VELOCITY],
            &[TextureFormat::Rgba32F, TextureFormat::Rgba32F],
            width,
            height,
        )?;
        let none = Defines::new();
        let mut sim = FireSim {
            state,
            init: Program::new(ctx, FULLSCREEN_VERTEX, "sim/fire_init.frag", &none)?,
            physics: Program::new(ctx, FULLSCREEN_VERTEX, "sim/fire.frag", &none)?,
            pass: FullscreenPass::new(ctx)?,
            params,
            seed,
            step: 0,
            dt,
            substeps: 1,
        };
        sim.reset();
        ctx.check_error("initialising the fire state")?;
        Ok(sim)
    }

    /// Steps of `dt` seconds from now on, `substeps` of them a frame (the parameters are
    /// checked again: the damping is a rate per step).
    pub fn set_time_step(&mut self, dt: f32, substeps: u32) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) || substeps == 0 {
            return Err(Error::InvalidInput(format!(
                "the fire steps by dt = {dt} s, {substeps} a frame: dt must be above 0 and \
                 substeps at least 1"
            )));
        }
        self.params.validate(dt)?;
        self.dt = dt;
        self.substeps = substeps;
        Ok(())
    }

    /// Draws the initial state (all dead, waits spread over one cycle) and restarts the clock.
    pub fn reset(&mut self) {
        let uniforms = [
            ("u_seed", Uniform::U32(self.seed)),
            ("u_width", Uniform::I32(self.state.width() as i32)),
            ("u_max_age", Uniform::F32(self.params.max_age)),
        ];
        self.pass
            .draw(&self.init, &[], &uniforms, self.state.back());
        self.state.swap();
        self.step = 0;
    }

    /// The physics program's uniforms for the step numbered `step`: the fire's parameters and
    /// the step, all given in the draw.
    fn step_uniforms(&self, step: u64) -> [(&'static str, Uniform); 15] {
        let q = &self.params;
        [
            ("u_width", Uniform::I32(self.state.width() as i32)),
            ("u_dt", Uniform::F32(self.dt)),
            ("u_seed", Uniform::U32(self.seed)),
            ("u_step", Uniform::U32(step as u32)),
            ("u_emitter_center", Uniform::Vec3(q.emitter_center)),
            ("u_emitter_radius", Uniform::F32(q.emitter_radius)),
            ("u_speed", Uniform::F32(q.speed)),
            ("u_spread", Uniform::F32(q.spread)),
            ("u_converge", Uniform::F32(q.converge)),
            ("u_buoyancy", Uniform::Vec3(q.buoyancy)),
            ("u_turbulence", Uniform::F32(q.turbulence)),
            ("u_damping", Uniform::F32(q.damping)),
            ("u_life_min", Uniform::F32(q.life_min)),
            ("u_life_max", Uniform::F32(q.life_max)),
            ("u_max_age", Uniform::F32(q.max_age)),
        ]
    }

    /// The ping-pong state.
    pub fn state(&self) -> &PingPong {
        &self.state
    }

    /// The current positions (xyz, remaining life).
    pub fn positions(&self) -> &Texture {
        self.state.front().texture(POSITION)
    }

    /// The current velocities (xyz, remaining wait).
    pub fn velocities(&self) -> &Texture {
        self.state.front().texture(VELOCITY)
    }

    /// Number of particles (texels).
    pub fn particle_count(&self) -> usize {
        self.positions().texels()
    }

    /// The parameters.
    pub fn params(&self) -> &FireParams {
        &self.params
    }
}

impl super::Simulation for FireSim {
    fn from_scene(ctx: &Context, scene: &crate::scene::SceneFile, seed: u32) -> Result<Self> {
        let Some(fire) = &scene.fire else {
            return Err(Error::InvalidInput(format!(
                "scene `{}` has no [fire] section: it runs through the particle pipeline",
                scene.name
            )));
        };
        // The one validation of the section, at its line and column.
        scene.check()?;
        let [w, h] = scene.particles.size;
        crate::gl::check_size(ctx, "particle texture (particles.size)", w, h)?;
        let mut sim = FireSim::new(ctx, w, h, fire.into(), seed)?;
        sim.set_time_step(scene.time.dt, scene.time.substeps)?;
        Ok(sim)
    }

    /// The one physics pass: reads the front, writes the back (MRT), swaps.
    fn run(&mut self, stage: super::Stage) -> Result<()> {
        if stage != super::Stage::Integrate {
            return Err(Error::InvalidInput(format!(
                "the fire has one pass a step, no {stage:?} stage"
            )));
        }
        let front = self.state.front();
        let textures = [
            ("u_position", front.texture(POSITION).into()),
            ("u_velocity", front.texture(VELOCITY).into()),
        ];
        self.pass.draw(
            &self.physics,
            &textures,
            &self.step_uniforms(self.step),
            self.state.back(),
        );
        self.state.swap();
        self.step += 1;
        Ok(())
    }

    fn steps(&self) -> u64 {
        self.step
    }

    fn time(&self) -> f64 {
        self.step as f64 * self.dt as f64
    }

    fn time_step(&self) -> f32 {
        self.dt
    }

    fn substeps(&self) -> u32 {
        self.substeps
    }

    fn size(&self) -> [u32; 2] {
        [self.state.width(), self.state.height()]
    }

    /// The velocities stand in for the statics: their w is the wait, from which the renderer's
    /// fire ramp derives each particle's total life and age.
    fn drawn(&self) -> super::DrawnState<'_> {
        super::DrawnState {
            positions: self.positions(),
            statics: self.velocities(),
            velocities: Some(self.velocities()),
            previous: None,
            spins: None,
            count: self.particle_count(),
        }
    }

    fn read_state(&self) -> Result<(Vec<f32>, Vec<f32>)> {
        Ok((self.positions().read_f32()?, self.velocities().read_f32()?))
    }

    fn pass_list(&self) -> Vec<crate::gl::PassInfo> {
        (self.passes().into_iter())
            .map(|p| crate::gl::PassInfo::new("integrate", p.name).draws(&self.physics, 1))
            .collect()
    }

    fn passes(&self) -> Vec<super::Pass> {
        vec![super::Pass {
            stage: super::Stage::Integrate,
            name: "fire (thesis §3-4, Listings 1-2): physics, in-shader respawn after the \
                   wait, damping, turbulence [position + velocity through MRT]"
                .into(),
        }]
    }

    fn state_target(&self) -> &crate::gl::Framebuffer {
        self.state.front()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parameters built in code meet the rules of a scene's `[fire]` section, named by key.
    #[test]
    fn fire_parameters_follow_the_scene_sections_rules() {
        let dt = 1.0 / 60.0;
        FireParams::default().validate(dt).unwrap();
        let bad = |change: &dyn Fn(&mut FireParams), key: &str| {
            let mut p = FireParams::default();
            change(&mut p);
            let e = p.validate(dt).unwrap_err().to_string();
            assert!(e.contains(key), "{key}: {e}");
        };
        bad(&|p| p.life_max = p.max_age * 2.0, "fire.life");
        bad(&|p| p.life_min = 0.0, "fire.life");
        bad(&|p| p.damping = -1.0, "fire.damping");
        bad(&|p| p.buoyancy.y = f32::NAN, "fire.buoyancy");
        bad(
            &|p| p.emitter_center.x = f32::INFINITY,
            "fire.emitter_center",
        );
        // The damping is a rate per step: fine at 1/60 s, refused where it would reverse v.
        let p = FireParams {
            damping: 50.0,
            ..FireParams::default()
        };
        assert!(p.validate(1.0 / 600.0).is_ok());
        assert!(p
            .validate(0.1)
            .unwrap_err()
            .to_string()
            .contains("fire.damping"));
    }
}
