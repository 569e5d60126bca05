//! Warnings that `render` and `view` print alike.

use texflow::scene::SceneFile;

/// The warning for the first frame after which births were dropped because the state texture
/// was full, with the size that would hold them when the scene's rates predict one.
pub fn births_dropped(s: &SceneFile, index: u64, total: u64) -> String {
    let hint = match s.capacity_check() {
        Some(w) => format!(
            "; a {0}x{0} state texture (--particles {0}) would hold them",
            w.side
        ),
        None => String::new(),
    };
    format!(
        "warning: frame {index}: the state texture ({}x{}) is full: {total} birth(s) \
         dropped{hint}",
        s.particles.size[0], s.particles.size[1]
    )
}

/// The warning for births that child emitters' texels could not take (their children still
/// lived), printed once, at the end of a run.
pub fn child_births_dropped(s: &SceneFile, total: u64) -> String {
    let hint = match s.child_capacity_check().first() {
        Some(w) => format!(
            "; per_parent = {} would hold child emitter {}'s trail",
            w.per_parent, w.emitter
        ),
        None => String::new(),
    };
    format!(
        "warning: {total} child birth(s) dropped: a parent asked for a child while the texel \
         reserved for it still held one; raise per_parent of [[emitters.child]] (the scene's \
         {} texels then hold fewer parents) or lower trail_rate or life{hint}",
        s.particle_count()
    )
}

/// The warning for exact collision searches that hit their bound over a run.
pub fn searches_truncated(s: &SceneFile, total: u64, steps: u64) -> String {
    if let Some(f) = &s.fluid {
        return format!(
            "warning: {total} fluid neighbour search(es) over {steps} step(s) met a run of three \
             cells holding more than {} particles and walked only that many: neighbours past \
             them were missed (the fluid compressed far past its rest density); a higher \
             fluid.speed_of_sound (now {} m/s) keeps it closer to rest density",
            texflow::sim::fluid::FLUID_SCAN,
            f.speed_of_sound
        );
    }
    let cell = (s.collisions.as_ref()).map_or(0.0, |c| c.cell());
    format!(
        "warning: {total} exact collision search(es) over {steps} step(s) met a run of three \
         cells holding more than {} particles and walked only that many: partners past them were \
         missed (a cluster denser than spheres that do not overlap); a smaller collisions.cell \
         (now {cell} m) or more iterations separate it sooner",
        texflow::scene::EXACT_SCAN
    )
}

/// The colliders' bound on bounces per step was reached (`MAX_BOUNCES` in
/// glsl/sim/colliders.glsl).
pub fn bounces_truncated(total: u64, steps: u64) -> String {
    format!(
        "warning: {total} particle step(s) over {steps} step(s) still met a collider after {} \
         bounces in one step: the rest of each such path was projected onto the surface and lost \
         its speed into it; a shorter time.dt (fewer walls crossed per step) keeps it",
        texflow::sim::MAX_BOUNCES
    )
}

/// A window-system error without the source location winit puts in front of it
/// (`os error at /path/to/winit/src/...rs:123: reason`): the reason is what the user needs.
pub fn window_reason(e: &dyn std::fmt::Display) -> String {
    let text = e.to_string();
    match text.strip_prefix("os error at ") {
        Some(rest) => rest
            .split_once(": ")
            .map_or(text.clone(), |(_, reason)| reason.to_owned()),
        None => text,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_reason_drops_the_source_path() {
        let e = "os error at /root/.cargo/registry/src/winit-0.30.12/src/platform_impl/linux/mod.rs:765: neither WAYLAND_DISPLAY nor DISPLAY is set";
        assert_eq!(
            window_reason(&e),
            "neither WAYLAND_DISPLAY nor DISPLAY is set"
        );
        assert_eq!(window_reason(&"plain"), "plain");
    }
}
