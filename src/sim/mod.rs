//! Particle simulation passes: state in RGBA float textures, updated by full-screen fragment
//! passes into ping-pong framebuffers.

pub mod allocator;
pub mod collide;
pub mod constraints;
pub mod emit;
pub mod fields;
pub mod fire;
pub mod fluid;
pub mod nonfinite;
pub mod params;
pub mod particles;
pub mod reference;
mod simulation;
pub mod state;
mod user_glsl;

pub use fields::{DistanceField, FlowField, HeightField};

/// A live particle (docs/pipeline.md): life `w > 0` and a finite position (dead particles are
/// parked at +inf). The twin of `particle_live` in `glsl/common/state.glsl`.
pub fn particle_live(p: [f32; 4]) -> bool {
    p[3] > 0.0 && p[..3].iter().all(|c| c.is_finite())
}
pub use constraints::Stretched;
/// Bounces at planes, spheres and boxes per particle and step after Latta's response
/// (`MAX_BOUNCES` in `glsl/sim/colliders.glsl`; the twin's `Reference::bounce_on`).
pub const MAX_BOUNCES: usize = 16;

pub use fire::{FireParams, FireSim};
pub use particles::{ClosedForm, Features, ParticleSim, BIRTH_VERTEX_BYTES};
pub use simulation::{stages_of, DrawnState, Pass, Simulation, Stage};

#[cfg(test)]
mod tests {
    /// The shader's bound on bounces is this one: the twin, the warning and the pass agree.
    #[test]
    fn the_shader_bounds_bounces_as_the_twin_does() {
        let src = crate::gl::source::embedded("sim/colliders.glsl").expect("embedded");
        let line = format!("const int MAX_BOUNCES = {};", super::MAX_BOUNCES);
        assert!(
            src.contains(&line),
            "glsl/sim/colliders.glsl lacks `{line}`"
        );
    }
}
