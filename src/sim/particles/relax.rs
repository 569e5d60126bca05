//! The constraint relaxation on the GPU (Latta §3.4.3): `iterations` times per Verlet step, the
//! scheme's edge passes (`glsl/sim/constrain.frag` once for Jacobi, `glsl/sim/constrain_set.frag`
//! once per set of constraints that share no particle for Gauss-Seidel), then with long-range
//! attachments `glsl/sim/attach.frag`. Each pass reads the current positions and writes the
//! ring's free side, which then becomes the current (the previous positions stay, so the next
//! step's implied velocity includes what the constraints moved). Also moves orbiting spheres,
//! which the Verlet step and the relaxation both read.

use glam::Vec3;

use super::{draw_textures, Fields};
use crate::error::Result;
use crate::gl::{
    Context, Defines, FullscreenPass, Program, Ring3, Texture, TextureDesc, TextureFormat, Uniform,
    UniformList, FULLSCREEN_VERTEX,
};
use crate::scene::{ConstraintKind, RelaxScheme, SceneFile};
use crate::sim::constraints::{set_count, Layout};
use crate::sim::params::{self, Params};
use crate::sim::state::POSITION;

/// The relaxation passes of a scene with `[constraints]`.
pub(super) struct Relaxation {
    /// The scheme's edge pass: Jacobi's, or one Gauss-Seidel set's (`u_set`).
    edges: Program,
    /// The long-range attachments' pass, when the scene asks for them.
    attach: Option<Program>,
    rest: Texture,
    /// Cloth: the pinned texels' rest positions (the attachments' pins).
    pins: Texture,
    layout: Layout,
    iterations: u32,
    scheme: RelaxScheme,
    /// The relaxation's own constants: stiffness, pin count.
    own: UniformList,
}

/// An RGBA32F texture of `w`×`h` holding `data`.
fn texture(ctx: &Context, label: &str, [w, h]: [u32; 2], data: &[f32]) -> Result<Texture> {
    let t = Texture::new(
        ctx,
        TextureDesc {
            width: w,
            height: h,
            format: TextureFormat::Rgba32F,
            label,
        },
    )?;
    t.upload_f32(data)?;
    Ok(t)
}

impl Relaxation {
    /// The programs (with the simulation's `defines`) of the constraints block `c` and the rest
    /// texture of `scene`'s layout.
    pub(super) fn new(
        ctx: &Context,
        scene: &SceneFile,
        c: Option<&params::Constraints>,
        defines: &Defines,
    ) -> Result<Option<Self>> {
        let (Some(c), Some(layout)) = (c, Layout::of(scene)) else {
            return Ok(None);
        };
        let mut d = defines.clone();
        let kind = match c.kind {
            ConstraintKind::Cloth => "CLOTH",
            ConstraintKind::Hair => "HAIR",
        };
        d.push((kind.to_owned(), "1".to_owned()));
        let edges = Program::new(
            ctx,
            FULLSCREEN_VERTEX,
            match c.scheme {
                RelaxScheme::Jacobi => "sim/constrain.frag",
                RelaxScheme::GaussSeidel => "sim/constrain_set.frag",
            },
            &d,
        )?;
        let attach = c
            .attachments
            .then(|| Program::new(ctx, FULLSCREEN_VERTEX, "sim/attach.frag", &d))
            .transpose()?;
        let rest = texture(ctx, "rest", layout.size, &layout.rest_floats())?;
        // Pin k at texel (k % width, k / width): any count fits a state-sized texture.
        let pins = layout.pins();
        let w = layout.size[0];
        let rows = (pins.len() as u32).div_ceil(w).max(1);
        let mut data = vec![0.0; 4 * (w * rows) as usize];
        for (i, &k) in pins.iter().enumerate() {
            data[4 * i..4 * i + 4].copy_from_slice(&layout.rest[k]);
        }
        let pin_texture = texture(ctx, "pins", [w, rows], &data)?;
        let mut own = UniformList::new();
        own.f32("u_stiffness", c.stiffness);
        own.i32("u_pin_count", pins.len() as i32);
        Ok(Some(Relaxation {
            edges,
            attach,
            rest,
            pins: pin_texture,
            iterations: c.iterations,
            scheme: c.scheme,
            layout,
            own,
        }))
    }

    /// The draws of one step, for the pass list's lines (`features/names.rs`).
    pub(super) fn pass_draws(&self) -> Vec<crate::gl::PassDraw> {
        use crate::gl::PassDraw;
        let n = self.iterations as u64;
        let mut out: Vec<PassDraw> = match self.scheme {
            RelaxScheme::Jacobi => vec![PassDraw::of("constrain:", &self.edges, n)],
            RelaxScheme::GaussSeidel => (0..set_count(self.layout.kind))
                .map(|i| PassDraw::of(format!("constrain set {i} "), &self.edges, n))
                .collect(),
        };
        out.extend(self.attach.iter().map(|p| PassDraw::of("attach:", p, n)));
        out
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

    /// `iterations` iterations at simulation time `t` (the end of the step just taken), every
    /// draw with the run's `constants`.
    pub(super) fn run(
        &self,
        params: &Params,
        constants: &UniformList,
        ring: &mut Ring3,
        pass: &FullscreenPass,
        fields: &Fields,
        t: f64,
    ) {
        let offset = (params.constraints.as_ref()).map_or(Vec3::ZERO, |c| c.pin_offset(t));
        // The run's constants, the relaxation's, then this step's pins and spheres (after the
        // constants' spheres, which they override): every draw takes those its program reads.
        let mut step: Vec<_> = self.own.values().to_vec();
        step.push(("u_pin_offset", Uniform::Vec3(offset)));
        step.extend(moved_spheres(&params.colliders, t));
        let ctx = (constants, pass, fields);
        let sets = match self.scheme {
            RelaxScheme::Jacobi => None,
            RelaxScheme::GaussSeidel => Some(set_count(self.layout.kind)),
        };
        for _ in 0..self.iterations {
            for set in 0..sets.unwrap_or(1) {
                let mut u = step.clone();
                if sets.is_some() {
                    u.push(("u_set", Uniform::I32(set as i32)));
                }
                self.draw(&self.edges, &u, ring, ctx);
            }
            if let Some(p) = &self.attach {
                self.draw(p, &step, ring, ctx);
            }
        }
    }

    /// One pass of `p` from the current positions into the ring's free side, then swapped, with
    /// the run's constants and the uniforms of `u` that `p` declares.
    fn draw(
        &self,
        p: &Program,
        u: &[(&'static str, Uniform)],
        ring: &mut Ring3,
        (constants, pass, fields): (&UniformList, &FullscreenPass, &Fields),
    ) {
        let own = [
            ("u_position", ring.current().texture(POSITION).into()),
            ("u_rest", (&self.rest).into()),
            ("u_pins", (&self.pins).into()),
        ];
        let own: Vec<_> = own.into_iter().filter(|(n, _)| p.declares(n)).collect();
        let t = draw_textures(p, &own, fields);
        let u = constants.for_draw(p, u.iter().cloned());
        pass.draw(p, &t, &u, ring.next());
        ring.swap_current_next();
    }
}

/// `u_sphere` with the spheres' places at time `t` if any orbits, as a draw's uniform (else
/// nothing: a static sphere's place is the value the scene's constants gave).
pub(super) fn moved_spheres(
    colliders: &params::Colliders,
    t: f64,
) -> Option<(&'static str, Uniform)> {
    match colliders.moving_spheres.is_empty() {
        true => None,
        false => Some(("u_sphere", Uniform::Vec4s(colliders.spheres_at(t).into()))),
    }
}
