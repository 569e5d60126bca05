//! The stateless simulation (Latta §2.1, thesis §2.2.5; `simulation = "stateless"`): every step
//! draws `glsl/sim/stateless.frag`, which computes positions and velocities from start values
//! and time by the closed form of [`ClosedForm`], and never reads the last step's state. The start
//! values of initial emitters are drawn once at reset into a framebuffer of their own; time-stamp
//! emitters redraw them from the emitter's random stream at every step.

use glam::{DVec3, Vec3};

use crate::error::Result;
use crate::gl::{Context, Defines, Framebuffer, Program, Texture, TextureDesc, TextureFormat};
use crate::gl::{FullscreenPass, UniformList, FULLSCREEN_VERTEX};
use crate::scene::{SceneFile, WindForm};
use crate::sim::state::{POSITION, VELOCITY};

/// The motion a stateless scene may have, `a = A - lambda v` with `A = g + k w` and
/// `lambda = c + k` (gravity g, damping rate c, a constant wind w with drag k; for Latta's form
/// of the wind, k / m in both), and its solution from (x0, v0).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedForm {
    /// Acceleration independent of the mass: gravity, plus k w for the drag form.
    pub accel: DVec3,
    /// k w for Latta's form, to be multiplied by the inverse mass; 0 otherwise.
    pub wind: DVec3,
    /// The rate independent of the mass (c, plus k for the drag form), and k for Latta's form.
    pub rate: [f64; 2],
}

impl ClosedForm {
    /// The closed form of a scene's forces (gravity, damping, the first wind's mean velocity).
    pub fn of(scene: &SceneFile) -> Self {
        let f = &scene.forces;
        let d3 = |a: [f32; 3]| Vec3::from(a).as_dvec3();
        let mut c = ClosedForm {
            accel: f.gravity.iter().map(|g| d3(g.acceleration)).sum(),
            wind: DVec3::ZERO,
            rate: [f.damping.iter().map(|d| d.rate as f64).sum(), 0.0],
        };
        if let Some(w) = f.wind.first() {
            let (k, mean) = (w.drag as f64, d3(w.velocity));
            match w.form {
                WindForm::Latta => {
                    c.wind = k * mean;
                    c.rate[1] = k;
                }
                WindForm::Drag | WindForm::Uberflow => {
                    c.accel += k * mean;
                    c.rate[0] += k;
                }
            }
        }
        c
    }

    /// Position and velocity `tau` seconds after (x0, v0), for a particle of inverse mass `im`.
    pub fn at(&self, x0: DVec3, v0: DVec3, tau: f64, im: f64) -> (DVec3, DVec3) {
        let a = self.accel + self.wind * im;
        let lambda = self.rate[0] + self.rate[1] * im;
        if lambda == 0.0 {
            return (x0 + v0 * tau + 0.5 * a * tau * tau, v0 + a * tau);
        }
        let decay = (-lambda * tau).exp();
        let e1 = -(-lambda * tau).exp_m1() / lambda;
        let e2 = (tau - e1) / lambda;
        (x0 + v0 * e1 + a * e2, v0 * decay + a * e1)
    }
}

/// The stateless pass and the start values it reads.
pub(super) struct Stateless {
    pub(super) program: Program,
    pub(super) start: Framebuffer,
    /// The closed form's constants: summed acceleration, wind, drag rates.
    own: UniformList,
}

impl Stateless {
    /// The closed-form pass of a stateless scene (`simulation = "stateless"`), else `None`.
    pub fn of(
        ctx: &Context,
        scene: &SceneFile,
        defines: &Defines,
        size: [u32; 2],
    ) -> Result<Option<Self>> {
        match scene.simulation {
            crate::scene::StateModel::Stateless => Ok(Some(Self::new(ctx, scene, defines, size)?)),
            crate::scene::StateModel::Stateful => Ok(None),
        }
    }

    pub(super) fn new(
        ctx: &Context,
        scene: &SceneFile,
        defines: &Defines,
        size: [u32; 2],
    ) -> Result<Self> {
        let program = Program::new(ctx, FULLSCREEN_VERTEX, "sim/stateless.frag", defines)?;
        let c = ClosedForm::of(scene);
        let mut own = UniformList::new();
        own.vec3("u_closed_accel", c.accel.as_vec3());
        own.vec3("u_closed_wind", c.wind.as_vec3());
        own.vec2(
            "u_closed_rate",
            glam::Vec2::new(c.rate[0] as f32, c.rate[1] as f32),
        );
        let texture = |label: &str| {
            Texture::new(
                ctx,
                TextureDesc {
                    width: size[0],
                    height: size[1],
                    format: TextureFormat::Rgba32F,
                    label,
                },
            )
        };
        let start = Framebuffer::named(
            ctx,
            "start",
            vec![
                (POSITION, texture("start position")?),
                (VELOCITY, texture("start velocity")?),
            ],
        )?;
        Ok(Stateless {
            program,
            start,
            own,
        })
    }

    /// One step: the state at the end of the step from `time` to `time_next` (the next step's
    /// `time`, bit for bit: time stamps take their age from it, as the stateful pass does),
    /// into `target`, with the run's `constants`.
    pub(super) fn draw(
        &self,
        constants: &UniformList,
        pass: &FullscreenPass,
        target: &Framebuffer,
        statics: &Texture,
        [time, time_next]: [f32; 2],
        rows: u32,
    ) {
        let p = &self.program;
        let clock =
            super::integrate::clock_uniforms([("u_time", time), ("u_time_next", time_next)]);
        let clock = constants.for_draw(p, self.own.values().iter().cloned().chain(clock));
        let own = [
            ("u_position", self.start.texture(POSITION).into()),
            ("u_velocity", self.start.texture(VELOCITY).into()),
            ("u_static", statics.into()),
        ];
        let own: Vec<_> = own.into_iter().filter(|(n, _)| p.declares(n)).collect();
        if rows > 0 {
            pass.draw_rows(p, &own, &clock, target, 0, rows);
        }
    }
}
