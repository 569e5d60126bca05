//! The fluid scenes of tests/fluid.rs and tests/fluid_scenes.rs: a tank of plane colliders
//! with a box of fluid on the lattice.

/// A tank [0, w] × [0, ∞) × [0, d] of plane colliders, a box of fluid `block` = (centre, size)
/// filled on the lattice, and `fluid` extra keys.
pub fn tank(
    size: [u32; 2],
    tank: [f32; 2],
    block: ([f32; 3], [f32; 3]),
    dt: f32,
    fluid: &str,
) -> String {
    let ([cx, cy, cz], [sx, sy, sz]) = block;
    let [w, d] = tank;
    format!(
        r#"
name = "fluid"
integrator = "euler"
[particles]
size = [{}, {}]
[time]
dt = {dt}
[[emitters.initial]]
shape = "box"
center = [{cx}, {cy}, {cz}]
size = [{sx}, {sy}, {sz}]
direction = [0.0, -1.0, 0.0]
speed = [0.0, 0.0]
[[forces.gravity]]
acceleration = [0.0, -9.81, 0.0]
[[colliders.plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 1.0, 0.0]
resilience = 0.0
[[colliders.plane]]
point = [0.0, 0.0, 0.0]
normal = [1.0, 0.0, 0.0]
resilience = 0.0
[[colliders.plane]]
point = [{w}, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
resilience = 0.0
[[colliders.plane]]
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]
resilience = 0.0
[[colliders.plane]]
point = [0.0, 0.0, {d}]
normal = [0.0, 0.0, -1.0]
resilience = 0.0
[fluid]
{fluid}
bounds = [[0.0, 0.0, 0.0], [{w}, 1.0, {d}]]
"#,
        size[0], size[1]
    )
}

/// The fluid of tests/fluid.rs's twin: 216 particles (6³ on a lattice of 2 cm) in the corner of
/// a 24 cm × 12 cm tank, in 256 texels (40 dead), h = 1.2 Δx.
pub fn twin_scene_source() -> String {
    let fluid = "speed_of_sound = 10.0\nviscosity = 0.2\nspacing = 0.02\nsmoothing = 0.024";
    twin_tank(5e-4, fluid)
}

/// The twin's tank and column with `fluid` keys and time step `dt`.
pub fn twin_tank(dt: f32, fluid: &str) -> String {
    tank(
        [16, 16],
        [0.24, 0.12],
        ([0.06, 0.06, 0.06], [0.12; 3]),
        dt,
        fluid,
    )
}
