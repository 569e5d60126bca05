//! `[fluid]`: weakly compressible SPH (src/scene/schema/fluid.rs) and what it asks of the rest of
//! the scene: its own neighbour lattice (so no `[collisions]`), a cubic lattice of particles in
//! initial box emitters, and a time step within the CFL, viscous and force conditions.

use super::{bounded, fail, path, Check, MASS_RANGE, MAX_LATTICE_CELLS};
use crate::scene::locate::Key;
use crate::scene::schema::{Fluid, Initial, Integrator, Resort, SceneFile, StateModel, Wall};

use Key::{Index as I, Name as N};

/// Courant number of the CFL condition dt ≤ λ h / c (Becker & Teschner 2007, §3.4: 0.4).
pub const FLUID_CFL: f32 = 0.4;
/// The viscous condition dt ≤ λ h² / ν (Monaghan 1992: 0.125), with the kinematic viscosity of
/// Monaghan's artificial viscosity ν = α h c / 10 (3-D, Monaghan 2005 §5.3).
pub const FLUID_VISCOUS: f32 = 0.125;
/// The force condition dt ≤ λ sqrt(h / |g|) (Becker & Teschner 2007, §3.4: 0.25).
pub const FLUID_FORCE: f32 = 0.25;
/// Largest smoothing length over spacing: a run of the fluid's search then holds at rest about
/// 3 (2h/Δx)³ = 81 particles on cells of 2h (three cells), 5 (h/Δx)³ = 17 on cells of h (at most
/// five), within the search's bound of 128 (room for the compression a splash makes).
pub const MAX_SMOOTHING_RATIO: f32 = 1.5;

/// `[fluid]`, if the scene has one.
pub(super) fn fluid(s: &SceneFile) -> Check {
    no_slip_planes(s)?;
    let Some(f) = &s.fluid else {
        return Ok(());
    };
    keys(f)?;
    lattice(s)?;
    if s.collisions.is_some() {
        return fail(
            path(&[N("collisions")]),
            "[fluid] sets up its own exact neighbour search (a lattice of cell 2 smoothing over \
             fluid.bounds): remove [collisions]",
        );
    }
    if s.constraints.is_some() || s.fire.is_some() {
        let k = if s.fire.is_some() {
            "fire"
        } else {
            "constraints"
        };
        return fail(path(&[N(k)]), format!("[fluid] has no [{k}]: remove one"));
    }
    if s.integrator == Integrator::Verlet || s.simulation == StateModel::Stateless {
        let k = if s.integrator == Integrator::Verlet {
            "integrator"
        } else {
            "simulation"
        };
        return fail(
            path(&[N(k)]),
            "the fluid's pressure and viscosity change velocities step by step: use an \
             explicit integrator (euler) and a stateful simulation",
        );
    }
    let [w, h] = s.particles.size;
    if !w.is_power_of_two() || !h.is_power_of_two() {
        return fail(
            path(&[N("particles"), N("size")]),
            "[fluid] sorts the state texture: both sides must be powers of two",
        );
    }
    resort(f, w, w * h)?;
    start(s, f)?;
    emitters(s)?;
    time_step(s, f)
}

/// `colliders.plane.wall = "no_slip"` is made by the fluid's ghosts: it needs `[fluid]` with its
/// wall treatment.
fn no_slip_planes(s: &SceneFile) -> Check {
    let ghosts = s.fluid.as_ref().is_some_and(|f| f.wall_correction);
    match (s.colliders.plane.iter()).position(|p| p.wall == Wall::NoSlip) {
        Some(i) if !ghosts => fail(
            path(&[N("colliders"), N("plane"), I(i), N("wall")]),
            "wall = \"no_slip\" sets the velocity of the fluid's ghost particles in the plane: \
             it needs [fluid] with wall_correction = true; remove wall",
        ),
        _ => {
            // The shader takes the no-slip planes as the bits of one int.
            let last = (s.colliders.plane.iter()).rposition(|p| p.wall == Wall::NoSlip);
            match last {
                Some(i) if i >= MAX_NO_SLIP => fail(
                    path(&[N("colliders"), N("plane"), I(i), N("wall")]),
                    format!(
                        "wall = \"no_slip\" is taken by the first {MAX_NO_SLIP} planes only; \
                         list this plane among them"
                    ),
                ),
                _ => Ok(()),
            }
        }
    }
}

/// Planes that may be no-slip walls: the first 31 (bits of a GLSL `int`).
const MAX_NO_SLIP: usize = 31;

/// `initial = "hydrostatic"` needs gravity along −y (the axis the lattice stacks its layers on).
fn start(s: &SceneFile, f: &Fluid) -> Check {
    if f.initial == Initial::Hydrostatic {
        let g = (s.forces.gravity.iter()).fold([0.0f32; 3], |a, g| {
            [0, 1, 2].map(|k| a[k] + g.acceleration[k])
        });
        if !(g[1] < 0.0 && g[0] == 0.0 && g[2] == 0.0) {
            return fail(
                path(&[N("fluid"), N("initial")]),
                format!(
                    "initial = \"hydrostatic\" stacks the lattice's layers along y and needs \
                     gravity along −y, not {g:?}: add [[forces.gravity]] acceleration = \
                     [0, −g, 0] or use initial = \"uniform\""
                ),
            );
        }
    }
    Ok(())
}

/// `resort_block`: a power of two of whole rows, at most half the entries, for the coherent
/// re-sort only.
fn resort(f: &Fluid, width: u32, entries: u32) -> Check {
    let Some(b) = f.resort_block else {
        return Ok(());
    };
    let at = path(&[N("fluid"), N("resort_block")]);
    if f.resort != Resort::Coherent {
        return fail(
            at,
            "resort_block sets the coherent re-sort's blocks: add resort = \"coherent\" or \
             remove it",
        );
    }
    if !b.is_power_of_two() || b < width || 2 * b > entries {
        return fail(
            at,
            format!(
                "resort_block {b}: use a power of two from the particle texture's width \
                 ({width}) to half its entries ({})",
                entries / 2
            ),
        );
    }
    Ok(())
}

/// The fluid's own keys, each on its own, and a lattice whose keys stay exact.
fn keys(f: &Fluid) -> Check {
    let at = |k| path(&[N("fluid"), N(k)]);
    for (k, v) in [
        ("rest_density", f.rest_density),
        ("speed_of_sound", f.speed_of_sound),
        ("spacing", f.spacing),
    ] {
        bounded(at(k), k, &[v])?;
        if v <= 0.0 {
            return fail(at(k), format!("{k} {v} must be above 0"));
        }
    }
    if !(1.0..=1e5).contains(&f.rest_density) {
        return fail(
            at("rest_density"),
            format!(
                "rest_density {} kg/m³ is outside [1, 1e5]: water is 1000",
                f.rest_density
            ),
        );
    }
    let [lo, hi] = MASS_RANGE;
    if !(lo..=hi).contains(&f.mass()) {
        return fail(
            at("spacing"),
            format!(
                "a particle weighs rest_density × spacing³ = {:e} kg, outside [{lo:e}, {hi:e}]: \
                 give a spacing of a size the forces can divide by",
                f.mass()
            ),
        );
    }
    material(f)?;
    for (i, corner) in f.bounds.iter().enumerate() {
        bounded(path(&[N("fluid"), N("bounds"), I(i)]), "bounds", corner)?;
    }
    if (0..3).any(|k| f.bounds[0][k] >= f.bounds[1][k]) {
        return fail(
            at("bounds"),
            "bounds must be [min corner, max corner] with min < max",
        );
    }
    Ok(())
}

/// Tait's exponent, the viscosity and the smoothing length.
fn material(f: &Fluid) -> Check {
    let at = |k| path(&[N("fluid"), N(k)]);
    if !(1.0..=7.0).contains(&f.gamma) {
        return fail(
            at("gamma"),
            format!(
                "gamma {} is outside [1, 7]: 7 is Tait's exponent for water, 1 the linear \
                 p = c² (ρ − ρ0)",
                f.gamma
            ),
        );
    }
    if !(0.0..=10.0).contains(&f.viscosity) {
        return fail(
            at("viscosity"),
            format!(
                "viscosity {} is outside [0, 10]: Monaghan's α is typically 0.01 to 0.5",
                f.viscosity
            ),
        );
    }
    if let Some(h) = f.smoothing {
        let ratio = h / f.spacing;
        if !(1.0..=MAX_SMOOTHING_RATIO).contains(&ratio) {
            return fail(
                at("smoothing"),
                format!(
                    "smoothing {h} m is {ratio:.3} spacing: give 1 to {MAX_SMOOTHING_RATIO} \
                     spacing ({} to {} m): fewer neighbours make the density estimate noisy, \
                     more overflow the neighbour search",
                    f.spacing,
                    MAX_SMOOTHING_RATIO * f.spacing
                ),
            );
        }
    }
    Ok(())
}

/// The fluid's lattice holds at most [`MAX_LATTICE_CELLS`] cells.
fn lattice(s: &SceneFile) -> Check {
    let Some(f) = &s.fluid else {
        return Ok(());
    };
    let at = |k| path(&[N("fluid"), N(k)]);
    let cells = fluid_cells(s);
    if cells > MAX_LATTICE_CELLS {
        let n = crate::scene::fluid_particles(s);
        let g = f.cell_size(n);
        let coarser = match f.fine_cell(n) {
            true => ", or cell = \"2h\" (8 times fewer cells)",
            false => "",
        };
        return fail(
            at("bounds"),
            format!(
                "the fluid's neighbour lattice has {cells} cells of {g} m; cell keys are exact \
                 floats only up to 2^24 = {MAX_LATTICE_CELLS}: use smaller bounds{coarser}"
            ),
        );
    }
    Ok(())
}

/// Cells of the neighbour lattice of the scene's fluid (`fluid.cell` over `bounds`), saturating.
pub fn fluid_cells(s: &SceneFile) -> u64 {
    let Some(f) = &s.fluid else {
        return 0;
    };
    let g = f.cell_size(crate::scene::fluid_particles(s));
    (f.lattice_dims(g).iter()).fold(1u64, |a, &n| a.saturating_mul(n as u64))
}

/// Fluid particles are placed on a lattice in initial box emitters, live for ever and weigh
/// ρ0 Δx³.
fn emitters(s: &SceneFile) -> Check {
    let em = &s.emitters;
    for (kind, n) in [
        ("allocator", em.allocator.len()),
        ("timestamp", em.timestamp.len()),
        ("child", em.child.len()),
    ] {
        if n > 0 {
            return fail(
                path(&[N("emitters"), N(kind), I(0)]),
                "[fluid] places its particles on a lattice of spacing once, at the start: use \
                 [[emitters.initial]] with shape = \"box\"",
            );
        }
    }
    for (i, e) in em.initial.iter().enumerate() {
        let at = |k| path(&[N("emitters"), N("initial"), I(i), N(k)]);
        if e.shape != crate::scene::Shape::Box {
            return fail(
                at("shape"),
                "[fluid] fills initial emitters on a cubic lattice of spacing: use shape = \"box\"",
            );
        }
        if e.life.is_some() {
            return fail(at("life"), "fluid particles live for ever: remove life");
        }
        if e.mass.is_some() || e.mass_range.is_some() {
            let k = if e.mass.is_some() {
                "mass"
            } else {
                "mass_range"
            };
            return fail(
                at(k),
                "every fluid particle weighs rest_density × spacing³: remove it",
            );
        }
    }
    Ok(())
}

/// The steps SPH stays stable in: CFL, viscous and force conditions, each refused past its bound.
fn time_step(s: &SceneFile, f: &Fluid) -> Check {
    let dt = s.time.dt;
    let h = f.h();
    let c = f.speed_of_sound;
    let at = path(&[N("time"), N("dt")]);
    let cfl = FLUID_CFL * h / c;
    if dt > cfl {
        return fail(
            at,
            format!(
                "dt {dt} s breaks the CFL condition of [fluid]: dt ≤ {FLUID_CFL} h / c = \
                 {cfl:.3e} s (h {h} m, c {c} m/s); use a shorter dt (and more substeps)"
            ),
        );
    }
    let nu = f.viscosity * h * c / 10.0;
    if nu > 0.0 && dt > FLUID_VISCOUS * h * h / nu {
        let limit = FLUID_VISCOUS * h * h / nu;
        return fail(
            at,
            format!(
                "dt {dt} s breaks the viscous condition of [fluid]: dt ≤ {FLUID_VISCOUS} h² / ν \
                 = {limit:.3e} s (ν = α h c / 10 = {nu:.3e} m²/s); use a shorter dt or a lower \
                 viscosity"
            ),
        );
    }
    let g: f32 = (s.forces.gravity.iter())
        .map(|g| glam::Vec3::from(g.acceleration).length())
        .sum();
    if g > 0.0 && dt > FLUID_FORCE * (h / g).sqrt() {
        let limit = FLUID_FORCE * (h / g).sqrt();
        return fail(
            at,
            format!(
                "dt {dt} s breaks the force condition of [fluid]: dt ≤ {FLUID_FORCE} \
                 sqrt(h / |g|) = {limit:.3e} s; use a shorter dt"
            ),
        );
    }
    Ok(())
}
