//! The parts of [`ParticleSim::new`](super::ParticleSim::new) that build GL objects from the
//! features: the state framebuffers, the field textures and the integration programs.

use super::{custom, state_texture, Emission, Fields, ParticleSim, State};
use crate::error::Result;
use crate::gl::{
    Attachment, Context, Defines, Framebuffer, PingPong, Program, Ring3, TextureFormat,
    FULLSCREEN_VERTEX,
};
use crate::scene::{Integrator, SceneFile, VelocityFormat};
use crate::sim::fields::{DistanceField, FlowField, HeightField};
use crate::sim::state::{POSITION, SPIN, STATIC, VELOCITY};

use super::Features;

/// The state framebuffers: a position ring for Verlet, else position and velocity (and spin)
/// ping-pong, with single-target framebuffers for the separate passes.
pub(super) fn state(
    ctx: &Context,
    features: &Features,
    vel_format: TextureFormat,
    width: u32,
    height: u32,
) -> Result<State> {
    Ok(if features.integrator == Integrator::Verlet {
        State::Verlet(Ring3::new(
            ctx,
            "verlet",
            &[POSITION],
            &[TextureFormat::Rgba32F],
            width,
            height,
        )?)
    } else {
        // Spinning spheres: a third target, (angular velocity, angle), only when asked for.
        let (names, formats): (&[Attachment], &[TextureFormat]) = if features.spin {
            (
                &[POSITION, VELOCITY, SPIN],
                &[TextureFormat::Rgba32F, vel_format, TextureFormat::Rgba32F],
            )
        } else {
            (&[POSITION, VELOCITY], &[TextureFormat::Rgba32F, vel_format])
        };
        let pp = PingPong::new(ctx, "particles", names, formats, width, height)?;
        State::Explicit(if features.separate() {
            pp.with_single_targets(ctx)?
        } else {
            pp
        })
    })
}

/// The wind, height field and distance field textures, with their CPU copies.
pub(super) fn fields(ctx: &Context, scene: &SceneFile) -> Result<Fields> {
    Ok(Fields {
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
    })
}

/// The integration program, or the velocity and position programs of the separate passes.
pub(super) fn integrate_programs(
    ctx: &Context,
    scene: &SceneFile,
    features: &Features,
    defines: &Defines,
) -> Result<(Program, Option<Program>)> {
    let with = |extra: &str| {
        let mut d = defines.clone();
        d.push((extra.to_owned(), "1".to_owned()));
        d
    };
    let root = custom::integrate_root(scene)?;
    let integrate_program = |d: &Defines| {
        Program::new(ctx, FULLSCREEN_VERTEX, &root, d).map_err(|e| custom::user_error(scene, e))
    };
    Ok(if features.separate() {
        let mut position = with("OUT_POSITION");
        if features.position_from_velocity() {
            position.push(("POSITION_FROM_VELOCITY".to_owned(), "1".to_owned()));
        }
        (
            integrate_program(&with("OUT_VELOCITY"))?,
            Some(integrate_program(&position)?),
        )
    } else {
        (integrate_program(defines)?, None)
    })
}

/// The texture format of the velocity state.
pub(super) fn velocity_format(format: VelocityFormat) -> TextureFormat {
    match format {
        VelocityFormat::Rgba32f => TextureFormat::Rgba32F,
        VelocityFormat::Rgba16f => TextureFormat::Rgba16F,
    }
}

/// Verlet's second-order start (previous positions from explicit velocities); none for other
/// integrators.
pub(super) fn verlet_start(
    ctx: &Context,
    verlet: bool,
    defines: &Defines,
) -> Result<Option<Program>> {
    Ok(if verlet {
        Some(Program::new(
            ctx,
            FULLSCREEN_VERTEX,
            "sim/verlet_start.frag",
            defines,
        )?)
    } else {
        None
    })
}

/// The framebuffer of the static texture, one RGBA float texel per particle.
pub(super) fn statics(ctx: &Context, width: u32, height: u32) -> Result<Framebuffer> {
    Framebuffer::named(
        ctx,
        "static",
        vec![(
            STATIC,
            state_texture(ctx, "static", width, height, TextureFormat::Rgba32F)?,
        )],
    )
}

/// The allocator's emission programs into the state, Verlet's previous positions and the static
/// texture; none without the allocator.
pub(super) fn emit_programs(
    ctx: &Context,
    features: &Features,
    defines: &Defines,
) -> Result<(Option<Program>, Option<Program>, Option<Program>)> {
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
    Ok((
        emit("OUT_STATE")?,
        if verlet { emit("OUT_PREVIOUS")? } else { None },
        emit("OUT_STATIC")?,
    ))
}

impl ParticleSim {
    /// Writes the first state and places the constraint layout and the fluid's lattice of
    /// `scene`.
    pub(super) fn start_up(&mut self, scene: &SceneFile) -> Result<()> {
        self.initialise()?;
        self.place_fluid(scene);
        if let (Some(r), State::Verlet(ring)) = (&self.relax, &self.state) {
            r.place(ring)?;
        }
        self.user_state_passes(true);
        self.ctx.check_error("initialising the particle state")?;
        Ok(())
    }
}
