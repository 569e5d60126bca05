//! `[[state]]` with `pass = "integrate"`: the state's `update` evaluated inside the integration
//! pass and written as one more render target of it (Latta §3.1's multiple render targets), so
//! the step draws no pass of its own for it and reads position and velocity once.
//!
//! The integration root (src/sim/particles/custom.rs) defines `USER_STATE_OUTPUTS` before
//! `sim/integrate.frag` and splices [`integrate_tail`] after it: the expressions' inputs, the
//! states' samplers' macros around the user's texts, `init` and `update` as functions, one
//! output per such state after the pass's own (position, velocity, spin), and
//! `user_states_write`, which `write_state` calls with the position and velocity the pass stores
//! (the velocity cut to half floats as an `rgba16f` texture stores it). It sets the inputs
//! with `sim/user_state_step.glsl`, as the own pass does, from the same texels: the expressions
//! read the same values in both modes. The values at the start still come from each state's own
//! pass (`init` everywhere), and every state is swapped once all have been drawn, after the own
//! passes: each update reads the previous step's values of every state, whichever pass runs it.

use super::{declarations, fetch, helper_count, user_sources, UserStates};
use crate::error::Result;
use crate::gl::source::add_runtime_source;
use crate::gl::{Context, Framebuffer};
use crate::scene::{SceneFile, StatePassKind, VelocityFormat};
use std::rc::Rc;

/// The states of `scene` whose update runs in the integration pass.
pub(in crate::sim::particles) fn integrated(scene: &SceneFile) -> Vec<usize> {
    (0..scene.state.len())
        .filter(|&i| scene.state[i].pass == StatePassKind::Integrate)
        .collect()
}

/// The text after `#include "sim/integrate.frag"` in the integration root of a scene with
/// states of `pass = "integrate"`; returns it with the keys of the user sources it includes.
pub(in crate::sim::particles) fn integrate_tail(scene: &SceneFile) -> Result<(String, String)> {
    let on = integrated(scene);
    let sources = user_sources(scene)?;
    for (key, _, text) in &sources {
        add_runtime_source(key, text);
    }
    let helpers = helper_count(scene, &sources);
    let (_, define, undef) = declarations(scene);
    let spin = scene.collisions.as_ref().is_some_and(|c| c.spin);
    let first = 2 + spin as usize;
    let mut tail = String::from(
        "// The user states updated in this pass (src/sim/particles/user_state_mrt.rs).\n\
         #include \"common/rng.glsl\"\n#include \"sim/user_state_step.glsl\"\n\
         uniform float u_user_time;   // the time at the end of the step\n",
    );
    tail += &define;
    for (key, _, _) in &sources[..helpers] {
        tail += &format!("#include \"{key}\"\n");
    }
    let mut keys = Vec::new();
    let mut write = String::new();
    for (j, &i) in on.iter().enumerate() {
        let init = &sources[helpers + 2 * i].0;
        let update = &sources[helpers + 2 * i + 1].0;
        tail += &format!(
            "vec4 user_init_{j}() {{\n    return vec4(\n#include \"{init}\"\n    );\n}}\n\
             vec4 user_update_{j}() {{\n    return vec4(\n#include \"{update}\"\n    );\n}}\n"
        );
        write += &format!(
            "    o_user_{j} = s == USER_INIT ? user_init_{j}() : (s == USER_UPDATE ? \
             user_update_{j}() : {});\n",
            fetch(i)
        );
        keys.push(format!("{init}+{update}"));
    }
    tail += &undef;
    for j in 0..on.len() {
        tail += &format!("layout(location = {}) out vec4 o_user_{j};\n", first + j);
    }
    let round = match scene.particles.velocity_format {
        VelocityFormat::Rgba16f => {
            "    velocity = vec3(user_half(velocity.x), user_half(velocity.y), \
                                    user_half(velocity.z));\n"
        }
        VelocityFormat::Rgba32f => "",
    };
    tail += HALF;
    tail += &format!(
        "void user_states_write(vec4 position, vec3 velocity) {{\n\
         \x20   ivec2 t = ivec2(gl_FragCoord.xy);\n{round}\
         \x20   int s = user_state_step(t, position, texelFetch(u_position, t, 0),\n\
         \x20                           texelFetch(u_static, t, 0), velocity, u_user_time);\n\
         {write}}}\n"
    );
    Ok((tail, keys.join("+")))
}

/// A float cut to the 10 mantissa bits of a half float, as an `rgba16f` velocity texture stores
/// it. OpenGL leaves the rounding of a float written to a half-float target to the
/// implementation; llvmpipe rounds toward zero, as here (a driver that rounds to nearest gives
/// the two modes velocities one half-float step apart at most). The half range's overflow and
/// subnormals (below 6e-5 m/s) are not modelled.
const HALF: &str = "float user_half(float f) {\n\
    \x20   uint u = floatBitsToUint(f);\n\
    \x20   u = u & ~0x1fffu;\n\
    \x20   return uintBitsToFloat(u);\n\
    }\n";

/// Framebuffers over the particles' and the integrated states' textures, kept by the addresses
/// of the framebuffers they view: the sides of the ping-pongs swap every step (and the states'
/// more often, with a fluid or collisions carrying them), so a handful of combinations recur.
/// Making one per step would check its completeness and the GL error every step.
#[derive(Default)]
pub(super) struct Views(std::cell::RefCell<Vec<(Vec<usize>, Rc<Framebuffer>)>>);

impl UserStates {
    /// The target of the integration pass when it updates states: the attachments of the
    /// particles' `back`, then each such state's next value; `None` when no state asks.
    pub(in crate::sim::particles) fn integration_target(
        &self,
        ctx: &Context,
        back: &Framebuffer,
    ) -> Result<Option<Rc<Framebuffer>>> {
        if self.integrated.is_empty() {
            return Ok(None);
        }
        let mut sources: Vec<(&Framebuffer, usize)> =
            (0..back.attachments()).map(|k| (back, k)).collect();
        sources.extend(self.integrated.iter().map(|&i| (self.states[i].back(), 0)));
        let key: Vec<usize> = (sources.iter())
            .map(|(fb, _)| std::ptr::from_ref(*fb) as usize)
            .collect();
        let mut views = self.views.0.borrow_mut();
        if let Some((_, fb)) = views.iter().find(|(k, _)| *k == key) {
            return Ok(Some(fb.clone()));
        }
        let fb = Rc::new(Framebuffer::views(
            ctx,
            "integration and user states",
            &sources,
        )?);
        views.push((key, fb.clone()));
        Ok(Some(fb))
    }
}
