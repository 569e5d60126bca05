//! The state textures, and reading the state back and replacing it (tests, experiments, dumps).

use super::{draw_textures, state_texture, ParticleSim, State};
use crate::error::{Error, Result};
use crate::gl::{Framebuffer, Texture, TextureFormat};
use crate::sim::fields::{DistanceField, HeightField};
use crate::sim::state::{POSITION, SPIN, STATIC, VELOCITY};

impl ParticleSim {
    /// The current positions (xyz, remaining life).
    pub fn positions(&self) -> &Texture {
        match &self.state {
            State::Explicit(pp) => pp.front().texture(POSITION),
            State::Verlet(ring) => ring.current().texture(POSITION),
        }
    }

    /// The current velocities (explicit integrators only).
    pub fn velocities(&self) -> Option<&Texture> {
        match &self.state {
            State::Explicit(pp) => Some(pp.front().texture(VELOCITY)),
            State::Verlet { .. } => None,
        }
    }

    /// The current spins of spinning spheres (`collisions.spin`): angular velocity (rad/s) and
    /// the angle about z (rad, in (-π, π]).
    pub fn spins(&self) -> Option<&Texture> {
        match &self.state {
            State::Explicit(pp) if self.features.spin => Some(pp.front().texture(SPIN)),
            _ => None,
        }
    }

    /// Reads the current spins back (4 floats per texel; see [`spins`](Self::spins)).
    pub fn read_spins(&self) -> Result<Vec<f32>> {
        self.spins()
            .ok_or_else(|| Error::InvalidInput("the scene has no `collisions.spin`".into()))?
            .read_f32()
    }

    /// Replaces the spins (4 floats per texel: angular velocity, angle), for tests and
    /// experiments; [`set_state`](Self::set_state) leaves them as they are.
    pub fn set_spins(&mut self, spins: &[f32]) -> Result<()> {
        let n = self.width as usize * self.height as usize * 4;
        if spins.len() != n {
            return Err(Error::InvalidInput(format!(
                "set_spins needs {n} floats ({}x{} texels, 4 each)",
                self.width, self.height
            )));
        }
        self.spins()
            .ok_or_else(|| Error::InvalidInput("the scene has no `collisions.spin`".into()))?
            .upload_f32(spins)?;
        self.ctx.check_error("setting the spins")
    }

    /// The previous positions (Verlet only).
    pub fn previous(&self) -> Option<&Texture> {
        match &self.state {
            State::Explicit(_) => None,
            State::Verlet(ring) => Some(ring.previous().texture(POSITION)),
        }
    }

    /// The height field the colliders pass samples (the scene's first), with its nodes.
    pub fn height_field(&self) -> Option<&HeightField> {
        self.fields.height.as_ref().map(|(_, h)| h)
    }

    /// The distance field, if the scene has one.
    pub fn distance_field(&self) -> Option<&DistanceField> {
        self.fields.sdf.as_ref().map(|(_, f)| f)
    }

    /// The static texture (birth time or phase, type, total life, random number).
    pub fn statics(&self) -> &Texture {
        self.statics.texture(STATIC)
    }

    /// The state framebuffer being read now (positions and, for explicit integrators,
    /// velocities).
    pub fn front(&self) -> &Framebuffer {
        match &self.state {
            State::Explicit(pp) => pp.front(),
            State::Verlet(ring) => ring.current(),
        }
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
                let dt = self.params.time.dt;
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
        self.statics.texture(STATIC).upload_f32(statics)?;
        if let Some(sl) = &self.stateless {
            // The start values a stateless step computes from.
            sl.start.texture(POSITION).upload_f32(positions)?;
            sl.start.texture(VELOCITY).upload_f32(velocities)?;
        }
        match &self.state {
            State::Explicit(pp) => {
                pp.front().texture(POSITION).upload_f32(positions)?;
                pp.front().texture(VELOCITY).upload_f32(velocities)?;
            }
            State::Verlet(ring) => {
                ring.current().texture(POSITION).upload_f32(positions)?;
                let v = state_texture(
                    &self.ctx,
                    "start velocity",
                    self.width,
                    self.height,
                    TextureFormat::Rgba32F,
                )?;
                v.upload_f32(velocities)?;
                let p = self.start.as_ref().expect("Verlet has a start program");
                let own = [
                    ("u_position", ring.current().texture(POSITION).into()),
                    ("u_velocity", (&v).into()),
                    ("u_static", self.statics.texture(STATIC).into()),
                ];
                let t = draw_textures(p, &own, &self.fields);
                self.pass
                    .draw(p, &t, &self.uniforms(p, []), ring.previous());
            }
        }
        self.ctx.check_error("setting the particle state")
    }
}

impl crate::sim::Simulation for ParticleSim {
    fn from_scene(
        ctx: &crate::gl::Context,
        scene: &crate::scene::SceneFile,
        seed: u32,
    ) -> Result<Self> {
        ParticleSim::new(ctx, scene, seed)
    }

    fn run(&mut self, stage: crate::sim::Stage) -> Result<()> {
        use crate::sim::Stage;
        if !self.stages.contains(&stage) {
            return Err(Error::InvalidInput(format!(
                "scene `{}` has no {stage:?} stage: its step runs {:?}",
                self.name, self.stages
            )));
        }
        match stage {
            Stage::Births => self.emit(),
            Stage::Integrate => {
                self.integrate_pass()?;
                self.user_state_passes(false);
                Ok(())
            }
            Stage::Relax => {
                self.relax();
                Ok(())
            }
            Stage::Collide => self.collide(),
        }
    }

    fn stages(&self) -> Vec<crate::sim::Stage> {
        self.stages.clone()
    }

    fn steps(&self) -> u64 {
        ParticleSim::steps(self)
    }

    fn time(&self) -> f64 {
        ParticleSim::time(self)
    }

    fn time_step(&self) -> f32 {
        self.params.time.dt
    }

    fn substeps(&self) -> u32 {
        self.params.time.substeps
    }

    fn size(&self) -> [u32; 2] {
        [self.width, self.height]
    }

    fn drawn(&self) -> crate::sim::DrawnState<'_> {
        crate::sim::DrawnState {
            positions: self.positions(),
            statics: self.statics(),
            velocities: self.velocities(),
            previous: self.previous(),
            spins: self.spins(),
            count: self.active_count(),
        }
    }

    fn read_state(&self) -> Result<(Vec<f32>, Vec<f32>)> {
        Ok((self.read_positions()?, self.read_velocities()?))
    }

    fn read_more(&self) -> Result<Vec<(&'static str, Vec<f32>)>> {
        let mut v = vec![("statics", self.statics().read_f32()?)];
        if let Some(t) = self.previous() {
            v.push(("previous", t.read_f32()?));
        }
        if let Some(t) = self.spins() {
            v.push(("spins", t.read_f32()?));
        }
        v.extend(self.read_user_states()?);
        Ok(v)
    }

    fn dropped_births(&self) -> u64 {
        ParticleSim::dropped_births(self)
    }

    fn non_finite(
        &self,
        counter: &crate::sim::nonfinite::NonFiniteCounter,
    ) -> Result<crate::sim::nonfinite::NonFiniteCount> {
        let motion = self.velocities().or(self.previous());
        counter.count_with(self.positions(), motion, &self.user_states())
    }

    fn user_states(&self) -> Vec<&Texture> {
        (self.state_names.iter())
            .filter_map(|s| self.user_state(s))
            .collect()
    }

    fn dropped_child_births(&self) -> Result<u64> {
        ParticleSim::dropped_child_births(self)
    }

    fn truncated_searches(&self) -> Result<u64> {
        let fluid = self.fluid_truncated()?;
        Ok(fluid
            + self
                .collisions()
                .map_or(Ok(0), |c| c.truncated_searches())?)
    }

    fn stretched(&self) -> Result<Option<crate::sim::Stretched>> {
        let (Some(layout), Some(c)) = (self.constraint_layout(), &self.params.constraints) else {
            return Ok(None);
        };
        let x = self.read_positions()?;
        Ok(Some(crate::sim::Stretched {
            edges: layout.stretched(&x, c.stretch_bound),
            constraints: layout.edges().len() as u64,
            bound: c.stretch_bound,
        }))
    }

    fn truncated_bounces(&self) -> Result<u64> {
        ParticleSim::truncated_bounces(self)
    }

    fn fluid_stats(&self) -> Result<Option<crate::sim::fluid::FluidStats>> {
        ParticleSim::fluid_stats(self)
    }

    fn height_field(&self) -> Option<&HeightField> {
        ParticleSim::height_field(self)
    }

    fn distance_field(&self) -> Option<&DistanceField> {
        ParticleSim::distance_field(self)
    }

    fn census(&self) -> Result<Option<crate::sim::collide::PairCensus>> {
        self.collisions().map(|c| c.census()).transpose()
    }

    fn passes(&self) -> Vec<crate::sim::Pass> {
        self.features.step_passes()
    }

    fn state_target(&self) -> &Framebuffer {
        self.front()
    }

    fn collision_stage(&self) -> Option<&crate::sim::collide::CollisionStage> {
        self.collisions()
    }

    fn pass_list(&self) -> Vec<crate::gl::PassInfo> {
        ParticleSim::pass_list(self)
    }
}
