//! The constraint relaxation on the GPU (Latta §3.4.3): `iterations` passes of
//! `glsl/sim/constrain.frag` after each Verlet step, each reading the current positions and
//! writing the ring's free side, which then becomes the current (the previous positions stay, so
//! the next step's implied velocity includes what the constraints moved). Also moves orbiting
//! spheres, which the Verlet step and the relaxation both read.

use super::{bind_textures, Fields};
use crate::error::Result;
use crate::gl::{
    Context, Defines, FullscreenPass, Program, Ring3, Texture, TextureDesc, TextureFormat,
    FULLSCREEN_VERTEX,
};
use crate::scene::{ConstraintKind, SceneFile};
use crate::sim::constraints::{pin_offset, sphere_centres, Layout};
use crate::sim::state::POSITION;

/// The relaxation passes of a scene with `[constraints]`.
pub(super) struct Relaxation {
    program: Program,
    rest: Texture,
    layout: Layout,
    iterations: u32,
}

impl Relaxation {
    /// The program (with the simulation's `defines`) and the rest texture of `scene`'s layout.
    pub(super) fn new(ctx: &Context, scene: &SceneFile, defines: &Defines) -> Result<Option<Self>> {
        let (Some(c), Some(layout)) = (&scene.constraints, Layout::of(scene)) else {
            return Ok(None);
        };
        let mut d = defines.clone();
        let kind = match c.kind {
            ConstraintKind::Cloth => "CLOTH",
            ConstraintKind::Hair => "HAIR",
        };
        d.push((kind.to_owned(), "1".to_owned()));
        let program = Program::new(ctx, FULLSCREEN_VERTEX, "sim/constrain.frag", &d)?;
        let [w, h] = layout.size;
        let rest = Texture::new(
            ctx,
            TextureDesc {
                width: w,
                height: h,
                format: TextureFormat::Rgba32F,
                label: "rest",
            },
        )?;
        rest.upload_f32(&layout.rest_floats())?;
        program.bind();
        program.set_f32("u_stiffness", c.stiffness);
        Ok(Some(Relaxation {
            program,
            rest,
            layout,
            iterations: c.iterations,
        }))
    }

    /// The program, for the scene's constant uniforms.
    pub(super) fn program(&self) -> &Program {
        &self.program
    }

    /// The layout.
    pub(super) fn layout(&self) -> &Layout {
        &self.layout
    }

    /// Writes the layout into every side of the ring: every particle at rest, so the first step
    /// starts with no velocity.
    pub(super) fn place(&self, ring: &Ring3) -> Result<()> {
        let x = self.layout.initial_positions();
        for side in ring.roles() {
            side.texture(POSITION).upload_f32(&x)?;
        }
        Ok(())
    }

    /// `iterations` passes at simulation time `t` (the end of the step just taken).
    pub(super) fn run(
        &self,
        scene: &SceneFile,
        ring: &mut Ring3,
        pass: &FullscreenPass,
        fields: &Fields,
        t: f64,
    ) {
        let p = &self.program;
        p.bind();
        p.set_vec3("u_pin_offset", pin_offset(scene, t));
        move_spheres(p, scene, t);
        for _ in 0..self.iterations {
            let own = [
                ("u_position", ring.current().texture(POSITION).into()),
                ("u_rest", (&self.rest).into()),
            ];
            bind_textures(p, &own, fields);
            pass.draw(p, ring.next());
            ring.swap_current_next();
        }
    }
}

/// Sets `u_sphere[i]` to each orbiting sphere's place at time `t` (static ones keep the value
/// the scene's constants gave).
pub(super) fn move_spheres(p: &Program, scene: &SceneFile, t: f64) {
    let centres = sphere_centres(scene, t);
    for (i, (s, c)) in scene.colliders.sphere.iter().zip(centres).enumerate() {
        if s.orbit.is_some() {
            p.set_vec4(&format!("u_sphere[{i}]"), c.extend(s.radius));
        }
    }
}
