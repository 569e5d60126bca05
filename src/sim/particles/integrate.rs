//! The integration pass (Latta §3.1-3.3, UberFlow §4.1): the step's one full-screen update of
//! position and velocity (or its velocity and position halves, or the closed form), its clock,
//! and the lines that name it in the pass list, next to the code that draws it.

use super::{draw_textures, relax, uniforms, user_state, Emission, Features, ParticleSim, State};
use crate::error::Result;
use crate::gl::{PassDraw, PingPong, Program, Sampled, Uniform};
use crate::scene::{self, Integrator, Precision, VelocityFormat};
use crate::sim::state::{POSITION, SPIN, STATIC, VELOCITY};

impl Features {
    /// The integration stage's lines: the integration pass (or its halves, or the closed form),
    /// then the user states' own passes.
    pub(super) fn integration_lines(&self) -> Vec<String> {
        let verlet = self.integrator == Integrator::Verlet;
        let what = self.integration_terms(verlet);
        let mut out = Vec::new();
        self.integrate_passes(&what, verlet, &mut out);
        let own: Vec<_> = (self.user_states.iter())
            .filter(|(n, _)| !self.integrated_states.contains(n))
            .cloned()
            .collect();
        out.extend(user_state::passes(&own));
        out
    }

    /// What the integration pass does: the integrator first, then forces, colliders, death,
    /// children and the float emulation.
    fn integration_terms(&self, verlet: bool) -> Vec<String> {
        let mut what = vec![match self.integrator {
            Integrator::Euler => "Latta's Euler (eq. 3, 8)".to_owned(),
            Integrator::Uberflow => "UberFlow's velocity-averaged update (eq. 1-2)".to_owned(),
            Integrator::Verlet => "Verlet (Latta eq. 9)".to_owned(),
            Integrator::Heun => {
                "Heun's predictor-corrector (thesis §2.1; 2 force stages)".to_owned()
            }
            Integrator::Rk4 => {
                "classical Runge-Kutta (thesis §2.1; 4 force stages in registers)".to_owned()
            }
            Integrator::Leapfrog => {
                "leapfrog kick-drift-kick (thesis §2.1; 2 force stages)".to_owned()
            }
        }];
        let forces = self.force_names();
        if !forces.is_empty() {
            what.push(format!("forces: {}", forces.join(", ")));
        }
        let mut colliders = Vec::new();
        for kind in scene::ColliderKind::ALL {
            let (n, name) = (self.collider_counts.get(kind), kind.noun());
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
        if self.children > 0 {
            what.push(format!(
                "{} child emitter(s): a dead child texel reads its parent texel and is born on \
                 its trail or at its death (thesis §2)",
                self.children
            ));
        }
        if !self.integrated_states.is_empty() {
            what.push(format!(
                "user state(s) {} (pass = \"integrate\"): `init` at birth, else `update` from \
                 the previous step's states and the position and velocity this pass writes, \
                 each one more MRT target",
                self.integrated_states.join(", ")
            ));
        }
        if self.precision == Precision::Fp24 {
            what.push("24-bit float emulation".into());
        }
        what
    }

    fn integrate_passes(&self, what: &[String], verlet: bool, out: &mut Vec<String>) {
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
        let rows = if self.live_rows() {
            " (live rows only)"
        } else {
            ""
        };
        if self.stateless {
            out.push(format!(
                "stateless{rows}: closed form from start values and time (Latta §2.1, thesis \
                 §2.2.5); {} [position + velocity through MRT; the last state is not read]",
                what[1..].join("; ")
            ));
        } else if self.separate() {
            let vel = match self.velocity_format {
                VelocityFormat::Rgba32f => "rgba32f",
                VelocityFormat::Rgba16f => "rgba16f",
            };
            out.push(format!(
                "integrate velocity{rows}: {} [velocity ({vel}) only, no MRT]",
                what.join("; ")
            ));
            out.push(format!(
                "integrate position{rows}: {} [position only, no MRT]",
                if self.position_from_velocity() {
                    "from the new velocity texture (Latta §3.1)".to_owned()
                } else {
                    format!("{} again, position written", what[0])
                }
            ));
        } else {
            out.push(format!(
                "integrate{rows}: {} [{}]",
                what.join("; "),
                targets
            ));
        }
    }
}

impl ParticleSim {
    /// The integration pass alone, then the swap.
    pub(super) fn integrate_pass(&mut self) -> Result<()> {
        let rows = self.active_rows();
        let p = &self.integrate;
        let (next, clock) = self.step_uniforms(p);
        let statics = ("u_static", self.statics.texture(STATIC).into());
        // Custom forces read the user states by name (user_state.rs).
        let user = self.user.as_ref().map(|u| u.samplers()).unwrap_or_default();
        let user = |p: &Program| user_state::declared(p, &user);
        match &self.state {
            State::Explicit(pp) if self.stateless.is_some() => {
                if let Some(sl) = &self.stateless {
                    sl.draw(
                        &self.constants,
                        &self.pass,
                        pp.back(),
                        self.statics.texture(STATIC),
                        [self.time as f32, next],
                        rows,
                    );
                }
            }
            State::Explicit(pp) => {
                let mut own = vec![
                    ("u_position", pp.front().texture(POSITION).into()),
                    ("u_velocity", pp.front().texture(VELOCITY).into()),
                    statics,
                ];
                let spin = self.features.spin.then(|| pp.front().texture(SPIN));
                own.extend(spin.map(|t| ("u_spin", t.into())));
                own.extend(user(p));
                let t = draw_textures(p, &own, &self.fields);
                match &self.integrate_position {
                    None if rows > 0 => {
                        // States updated in this pass: further targets (user_state_mrt.rs).
                        let user = self.user.as_ref();
                        let mrt = user.map(|u| u.integration_target(&self.ctx, pp.back()));
                        let mrt = mrt.transpose()?.flatten();
                        let target = mrt.as_deref().unwrap_or(pp.back());
                        self.pass.draw_rows(p, &t, &clock, target, 0, rows)
                    }
                    Some(q) if rows > 0 => self.integrate_separate(q, pp, &t, &clock, next, rows),
                    _ => {}
                }
            }
            State::Verlet(ring) => {
                let mut own = vec![
                    ("u_position", ring.current().texture(POSITION).into()),
                    ("u_previous", ring.previous().texture(POSITION).into()),
                    statics,
                ];
                own.extend(user(p));
                let t = draw_textures(p, &own, &self.fields);
                if rows > 0 {
                    self.pass.draw_rows(p, &t, &clock, ring.next(), 0, rows);
                }
            }
        }
        match &mut self.state {
            State::Explicit(pp) => pp.swap(),
            State::Verlet(ring) => ring.rotate(),
        }
        if rows > 0 && self.stateless.is_none() && matches!(self.state, State::Explicit(_)) {
            self.count_bounce_flags(rows);
        }
        self.step += 1;
        self.time = self.step as f64 * self.params.time.dt as f64;
        Ok(())
    }

    /// Latta §3.1 without MRT (`passes = "separate"`): the velocity pass `integrate` (with the
    /// textures and clock the one-pass update would draw with) into the back's velocity, then
    /// the position pass `q` into its position.
    fn integrate_separate(
        &self,
        q: &Program,
        pp: &PingPong,
        t: &[(&str, Sampled)],
        clock: &[(&str, Uniform)],
        next: f32,
        rows: u32,
    ) {
        let p = &self.integrate;
        let user = self.user.as_ref().map(|u| u.samplers()).unwrap_or_default();
        let user = |p: &Program| user_state::declared(p, &user);
        let statics = ("u_static", self.statics.texture(STATIC).into());
        let (v, x) = (pp.back_single(VELOCITY), pp.back_single(POSITION));
        self.pass.draw_rows(p, t, clock, v, 0, rows);
        let mut q_clock = clock_uniforms([("u_time", self.time as f32), ("u_time_next", next)]);
        q_clock.extend(self.step_arrays(self.time));
        let q_clock = self.uniforms(q, q_clock);
        let own: Vec<_> = [
            ("u_position", pp.front().texture(POSITION).into()),
            ("u_velocity", pp.front().texture(VELOCITY).into()),
            ("u_new_velocity", pp.back().texture(VELOCITY).into()),
            statics,
        ]
        .into_iter()
        .filter(|(n, _)| q.declares(n))
        .chain(user(q))
        .collect();
        let t = draw_textures(q, &own, &self.fields);
        self.pass.draw_rows(q, &t, &q_clock, x, 0, rows);
    }

    /// The integration draw's uniforms: the run's constants, the orbiting spheres where they
    /// are at the step's end (and the animated emitters' values), and this step's clock:
    /// `u_time`, the next step's (time stamps' cycles and child trails end one step's interval
    /// where the next begins, glsl/sim/integrate.frag) and the last step's (Verlet's time
    /// stamps; -dt before the first step), each exactly, those `p` declares. Returns the next
    /// step's time and the uniforms.
    fn step_uniforms(&self, p: &Program) -> (f32, Vec<(&'static str, Uniform)>) {
        let dt = self.params.time.dt as f64;
        let next = ((self.step + 1) as f64 * dt) as f32;
        let prev = ((self.step as f64 - 1.0) * dt) as f32;
        let now = self.time as f32;
        let clock = [
            ("u_time", now),
            ("u_time_next", next),
            ("u_user_time", next),
            ("u_time_prev", prev),
        ];
        let mut clock = clock_uniforms(clock);
        clock.extend(self.step_arrays(self.time));
        (next, self.uniforms(p, clock))
    }

    /// This step's arrays, for a draw's uniforms: the orbiting spheres where they are at the
    /// step's end and, for emitters with curves, their values at the step's start `t` (the
    /// draw takes those its program declares).
    fn step_arrays(&self, t: f64) -> Vec<(&'static str, Uniform)> {
        let dt = self.params.time.dt as f64;
        let e = &self.params.emitters;
        let spawn = match e.animated {
            true => uniforms::spawn_uniforms(&e.spawn_at(t as f32)).to_vec(),
            false => Vec::new(),
        };
        (relax::moved_spheres(&self.params.colliders, t + dt).into_iter())
            .chain(spawn)
            .collect()
    }

    /// The integration (or its halves, or the closed form), the user states, the bounce tally.
    pub(super) fn integration_draws(&self) -> Vec<PassDraw> {
        let mut out = Vec::new();
        match (&self.stateless, &self.integrate_position) {
            (Some(s), _) => out.push(PassDraw::of("stateless", &s.program, 1)),
            (None, Some(position)) => {
                out.push(PassDraw::of("integrate velocity", &self.integrate, 1));
                out.push(PassDraw::of("integrate position", position, 1));
            }
            (None, None) => {
                // "integrate: …" or "integrate (live rows only): …".
                out.push(PassDraw::of("integrate:", &self.integrate, 1));
                out.push(PassDraw::of("integrate (", &self.integrate, 1));
            }
        }
        if let Some(u) = &self.user {
            out.extend(u.pass_draws());
        }
        if let (Some(t), State::Explicit(_)) = (&self.bounces, &self.state) {
            out.push(PassDraw::of("bounce tally", t.program(), t.draws()));
        }
        out
    }
}

/// The clock uniforms of a draw (its uniform list keeps those the program declares: a variant
/// without time stamps or children reads no next time).
pub(super) fn clock_uniforms<const N: usize>(
    clock: [(&'static str, f32); N],
) -> Vec<(&'static str, Uniform)> {
    (clock.into_iter())
        .map(|(n, v)| (n, Uniform::F32(v)))
        .collect()
}
