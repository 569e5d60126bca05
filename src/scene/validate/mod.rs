//! Validation of a parsed scene file: the values no run can give a meaning to, each reported as
//! a path into the document that [`super::locate`] turns into a line and column.
//!
//! One function per section, called in file order by [`SceneFile::validate`]; the first failure
//! is reported. Device limits are checked later, once a context exists
//! ([`super::check_limits`]).

mod bursts;
mod children;
pub use children::{ChildCapacityWarning, ChildLayout, ChildRange};
mod colliders;
mod constraints;
mod curves;
pub use curves::has_curves;
mod emitters;
pub use emitters::CapacityWarning;
mod fluid;
pub use fluid::{fluid_cells, FLUID_CFL, FLUID_FORCE, FLUID_VISCOUS, MAX_SMOOTHING_RATIO};
mod forces;
mod lighting;
pub use lighting::{MAX_LIGHT_RESOLUTION, MAX_SLICES};
mod neighbours;
pub use neighbours::MAX_DEM_OMEGA_DT;
mod render;
mod render_options;
mod ribbons;
mod spin;
mod state;
mod type_curves;
pub use state::STATE_INPUTS;

use super::locate::{Invalid, Key};
use super::schema::{
    ColliderKind, Collisions, ForceKind, Integrator, SceneFile, StateModel, UpdatePasses, WindForm,
};

use Key::{Index as I, Name as N};

/// The result of one check: nothing, or where and what.
pub(super) type Check = std::result::Result<(), Invalid>;

/// The most simulation steps one frame may take.
pub const MAX_SUBSTEPS: u32 = 1000;

fn fail(at: Vec<Key>, message: impl Into<String>) -> Check {
    Err(Invalid {
        at,
        message: message.into(),
    })
}

fn path(parts: &[Key]) -> Vec<Key> {
    parts.to_vec()
}

fn nonzero(v: [f32; 3]) -> bool {
    v.iter().any(|x| *x != 0.0)
}

/// Largest coordinate, extent or vector component a scene may give, in metres (or m/s, m/s²):
/// far beyond any scene here, yet its square (a distance², a dot product) stays finite in f32.
pub const MAX_COORDINATE: f32 = 1e6;

/// Smallest largest component of a direction (a direction, normal or axis): below it the
/// squared length underflows and normalising it gives NaN.
pub const MIN_DIRECTION: f32 = 1e-6;

/// Longest time step (s): with every acceleration and velocity within ±[`MAX_COORDINATE`], one
/// step's `a dt` and `v dt` stay within it too. Longer steps overflow the state within a few
/// steps (dt = 1e30 under gravity); use `substeps` to cover more time per frame.
pub const MAX_DT: f32 = 1.0;

/// Longest life, cycle or fire cycle (s): the state stores remaining lives, and with
/// `precision = "fp24"` (at most about 1.8e19) a life of 1e30 is written as infinity.
pub const MAX_TIME: f32 = 1e6;

/// A time within (0, [`MAX_TIME`]] seconds (the lower bound is checked by the caller).
fn duration(at: Vec<Key>, what: &str, t: f32) -> Check {
    if t.is_nan() || t > MAX_TIME {
        return fail(
            at,
            format!(
                "{what} {t} s is above {MAX_TIME:e} s: the state stores it, and 24-bit floats \
                 cannot; give a shorter time"
            ),
        );
    }
    Ok(())
}

/// Range of a particle mass (kg): forces are divided by it (Latta eq. 2), so a tiny mass turns a
/// bounded force into an overflowing acceleration.
pub const MASS_RANGE: [f32; 2] = [1e-6, 1e6];

/// A mass within [`MASS_RANGE`].
fn mass(at: Vec<Key>, m: f32) -> Check {
    let [lo, hi] = MASS_RANGE;
    if !(lo..=hi).contains(&m) {
        return fail(
            at,
            format!(
                "mass {m:e} kg is outside [{lo:e}, {hi:e}]: forces are divided by the mass, so \
                 give a mass in that range"
            ),
        );
    }
    Ok(())
}

/// Every component within ±[`MAX_COORDINATE`], reported at the first one out of range. NaN is
/// out of range too: a file cannot hold one, but a scene changed in code can.
fn bounded(at: Vec<Key>, what: &str, v: &[f32]) -> Check {
    match v
        .iter()
        .position(|x| x.is_nan() || x.abs() > MAX_COORDINATE)
    {
        Some(i) => fail(
            [&at[..], &[I(i)]].concat(),
            format!(
                "{what} component {} is outside [-{MAX_COORDINATE:e}, {MAX_COORDINATE:e}]: \
                 use values of a size the simulation can square",
                v[i]
            ),
        ),
        None => Ok(()),
    }
}

/// A direction (normalised by the shaders): bounded, and not so short that normalising fails.
fn direction(at: Vec<Key>, what: &str, v: [f32; 3]) -> Check {
    bounded(at.clone(), what, &v)?;
    if v.iter().all(|x| x.abs() < MIN_DIRECTION) {
        return fail(
            at,
            format!(
                "{what} is too short to normalise: give a component of at least \
                 {MIN_DIRECTION:e} in magnitude"
            ),
        );
    }
    Ok(())
}

impl SceneFile {
    /// Checks the values a scene cannot give a meaning to (device limits are checked later).
    pub fn validate(&self) -> Check {
        if self.name.trim().is_empty() {
            return fail(path(&[N("name")]), "name must not be empty");
        }
        particles(self)?;
        time(self)?;
        update_passes(self)?;
        stateless(self)?;
        emitters::emitters(self)?;
        bursts::bursts(self)?;
        children::children(self)?;
        forces::forces(self)?;
        colliders::colliders(self)?;
        constraints::orbits(self)?;
        collisions(self)?;
        spin::spin(self)?;
        neighbours::neighbours(self)?;
        fluid::fluid(self)?;
        constraints::constraints(self)?;
        fire(self)?;
        state::state(self)?;
        render::render(self)?;
        ribbons::ribbons(self)?;
        lighting::lighting(self)
    }

    /// Number of particles.
    pub fn particle_count(&self) -> u64 {
        self.particles.size[0] as u64 * self.particles.size[1] as u64
    }
}

/// `[particles]`.
fn particles(s: &SceneFile) -> Check {
    if let Some(i) = s.particles.size.iter().position(|s| *s == 0) {
        return fail(
            path(&[N("particles"), N("size"), I(i)]),
            "both sides of size must be at least 1 texel",
        );
    }
    if s.particles.mass <= 0.0 {
        return fail(
            path(&[N("particles"), N("mass")]),
            format!("mass {} must be above 0 kg", s.particles.mass),
        );
    }
    mass(path(&[N("particles"), N("mass")]), s.particles.mass)
}

/// `[time]`.
fn time(s: &SceneFile) -> Check {
    // Finite already in a parsed file; `render --dt` overrides it after parsing.
    if !(s.time.dt.is_finite() && s.time.dt > 0.0) {
        return fail(
            path(&[N("time"), N("dt")]),
            format!(
                "time step dt {} must be a finite number of seconds above 0",
                s.time.dt
            ),
        );
    }
    if s.time.dt > MAX_DT {
        return fail(
            path(&[N("time"), N("dt")]),
            format!(
                "time step dt {} s is above {MAX_DT} s: longer steps overflow the velocities; \
                 use a shorter dt, and substeps for more time per frame",
                s.time.dt
            ),
        );
    }
    if s.time.substeps == 0 {
        return fail(
            path(&[N("time"), N("substeps")]),
            "substeps must be at least 1",
        );
    }
    // One frame's work is substeps × passes: bounded, so that a signal is answered within a
    // frame and no frame runs without end.
    if s.time.substeps > MAX_SUBSTEPS {
        return fail(
            path(&[N("time"), N("substeps")]),
            format!(
                "substeps {} is more than {MAX_SUBSTEPS} steps per frame: use a larger dt or \
                 more frames",
                s.time.substeps
            ),
        );
    }
    Ok(())
}

/// `passes`: only what writes two state textures can write them in two passes.
fn update_passes(s: &SceneFile) -> Check {
    if s.passes == UpdatePasses::Separate && s.integrator == Integrator::Verlet {
        return fail(
            path(&[N("passes")]),
            "Verlet writes one texture per step (the next position; Latta §3.4.3: no velocity \
             pass), so there is nothing to split: use passes = \"mrt\" or an explicit integrator",
        );
    }
    if s.passes == UpdatePasses::Separate && s.fire.is_some() {
        return fail(
            path(&[N("passes")]),
            "the fire's step is one MRT pass (thesis §3.2): remove passes",
        );
    }
    Ok(())
}

/// Whether a stateless scene may have forces of `kind` (not refused by [`stateless`]).
fn stateless_allows(kind: ForceKind) -> bool {
    match kind {
        // The closed form's (src/sim/particles/stateless.rs).
        ForceKind::Gravity | ForceKind::Damping | ForceKind::Wind => true,
        ForceKind::Attractor | ForceKind::Spring | ForceKind::Vortex | ForceKind::Custom => false,
        // Pair forces need [collisions], which `stateless` refuses.
        ForceKind::Pair => true,
    }
}

/// `simulation = "stateless"`: only motions with a closed form (Latta §2.1).
fn stateless(s: &SceneFile) -> Check {
    if s.simulation != StateModel::Stateless {
        return Ok(());
    }
    let why = "a stateless simulation computes positions from start values and time by a \
               closed form (gravity, damping and a constant wind only)";
    if s.fire.is_some() {
        return fail(
            path(&[N("simulation")]),
            "the fire respawns in its shader step by step (thesis §3.4): remove simulation",
        );
    }
    let f = &s.forces;
    let c = &s.colliders;
    let refused = (ForceKind::ALL.into_iter())
        .filter(|&k| !stateless_allows(k))
        .map(|k| ("forces", k.key(), f.count(k)))
        .chain(ColliderKind::ALL.map(|k| ("colliders", k.key(), c.count(k))));
    for (section, kind, n) in refused {
        if n > 0 {
            return fail(
                path(&[N(section), N(kind), I(0)]),
                format!("{why}: a {kind} has none; remove it or use simulation = \"stateful\""),
            );
        }
    }
    if let Some((i, w)) = f.wind.iter().enumerate().find(|(_, w)| {
        w.turbulence != 0.0 || w.curl != 0.0 || w.field.is_some() || w.form == WindForm::Uberflow
    }) {
        let key = if w.turbulence != 0.0 {
            "turbulence"
        } else if w.curl != 0.0 {
            "curl"
        } else if w.field.is_some() {
            "field"
        } else {
            "form"
        };
        return fail(
            path(&[N("forces"), N("wind"), I(i), N(key)]),
            format!(
                "{why}: the wind must be constant (no turbulence, curl or field) and act through drag \
                 (form = \"drag\" or \"latta\"; UberFlow's v += w is a per-step kick)"
            ),
        );
    }
    if s.collisions.is_some() {
        return fail(
            path(&[N("collisions")]),
            format!("{why}: remove [collisions]"),
        );
    }
    if !s.emitters.allocator.is_empty() {
        return fail(
            path(&[N("emitters"), N("allocator"), I(0)]),
            format!(
                "{why}; the allocator's births are placed by the CPU step by step: use timestamp \
                 or initial emitters"
            ),
        );
    }
    if s.integrator != Integrator::Euler || s.passes != UpdatePasses::Mrt {
        return fail(
            path(&[N(if s.integrator != Integrator::Euler {
                "integrator"
            } else {
                "passes"
            })]),
            format!("{why}, with no integrator and one pass: remove the key"),
        );
    }
    Ok(())
}

/// `[collisions]`, and what it asks of the rest of the scene.
fn collisions(s: &SceneFile) -> Check {
    let Some(c) = &s.collisions else {
        return Ok(());
    };
    collision_keys(c)?;
    collision_lattice(c)?;
    let at = |k| path(&[N("collisions"), N(k)]);
    let [w, h] = s.particles.size;
    if !w.is_power_of_two() || !h.is_power_of_two() {
        return fail(
            path(&[N("particles"), N("size")]),
            "collisions sort the state texture: both sides must be powers of two",
        );
    }
    if let Some(k) = c.rows_only {
        if !k.is_power_of_two() || k > h {
            return fail(
                at("rows_only"),
                format!("rows_only must be a power of two up to the height {h}"),
            );
        }
    }
    if !(1..=16).contains(&c.iterations) {
        return fail(at("iterations"), "iterations must lie in 1..=16");
    }
    if c.detection == crate::scene::schema::Detection::Exact {
        if c.rows_only.is_some() {
            return fail(
                at("rows_only"),
                "exact detection searches the fully sorted keys: remove rows_only (or use \
                 detection = \"uberflow\")",
            );
        }
        if c.cell.is_some_and(|g| g < c.radius) {
            return fail(
                at("cell"),
                format!(
                    "exact detection walks the cells within 2 radius of a particle (the 27 around \
                     its cell from a cell of 2 radius up, trimmed below), so the cell must be at \
                     least radius = {} m (a finer lattice would multiply the runs it walks)",
                    c.radius
                ),
            );
        }
    }
    if s.integrator == Integrator::Verlet {
        return fail(
            path(&[N("integrator")]),
            "collisions exchange momentum through velocities: use euler or uberflow",
        );
    }
    if !s.emitters.allocator.is_empty() {
        return fail(
            path(&[N("emitters"), N("allocator")]),
            "collisions reorder the state every step, which the CPU allocator's indices \
             cannot follow: use timestamp or initial emitters",
        );
    }
    if s.fire.is_some() {
        return fail(path(&[N("collisions")]), "the fire has no collisions");
    }
    Ok(())
}

/// `[collisions]` radius, restitution, neighbours, cell and bounds, each on its own.
fn collision_keys(c: &Collisions) -> Check {
    let at = |k| path(&[N("collisions"), N(k)]);
    if c.radius <= 0.0 {
        return fail(
            at("radius"),
            format!("radius {} m must be above 0", c.radius),
        );
    }
    if !(0.0..=1.0).contains(&c.restitution) {
        return fail(
            at("restitution"),
            format!("restitution {} is outside [0, 1]", c.restitution),
        );
    }
    if !(1..=MAX_NEIGHBOURS).contains(&c.neighbours) {
        return fail(
            at("neighbours"),
            format!("neighbours must lie in 1..={MAX_NEIGHBOURS}"),
        );
    }
    if c.cell.is_some_and(|g| g <= 0.0) {
        return fail(at("cell"), "cell must be above 0 m");
    }
    bounded(at("radius"), "radius", &[c.radius])?;
    if let Some(g) = c.cell {
        bounded(at("cell"), "cell", &[g])?;
    }
    for (i, corner) in c.bounds.iter().enumerate() {
        bounded(
            path(&[N("collisions"), N("bounds"), I(i)]),
            "bounds",
            corner,
        )?;
    }
    if (0..3).any(|k| c.bounds[0][k] >= c.bounds[1][k]) {
        return fail(
            at("bounds"),
            "bounds must be [min corner, max corner] with min < max",
        );
    }
    Ok(())
}

/// `[collisions]`: a cell the exact search can scan, and a lattice whose keys stay exact.
fn collision_lattice(c: &Collisions) -> Check {
    let at = |k| path(&[N("collisions"), N(k)]);
    if c.detection == crate::scene::Detection::Exact {
        let g = c.cell();
        if run_capacity(g, c.radius) > EXACT_SCAN as f64 {
            let largest = largest_exact_cell(c.radius);
            return fail(
                at("cell"),
                format!(
                    "cell {g} m is too large for the exact detection: a run of three cells could \
                     hold more than the {EXACT_SCAN} particles its search walks (spheres of radius \
                     {} m that do not overlap); use a cell of at most {largest:.6} m (down to \
                     the radius)",
                    c.radius
                ),
            );
        }
    }
    let cells = lattice_cells(c);
    if cells > MAX_LATTICE_CELLS {
        return fail(
            if c.cell.is_some() {
                at("cell")
            } else {
                at("radius")
            },
            format!(
                "the collision lattice has {cells} cells; cell keys are exact floats only up to \
                 2^24 = {MAX_LATTICE_CELLS}: use a larger cell (default 2 radius) or smaller \
                 bounds"
            ),
        );
    }
    Ok(())
}

/// Most neighbours per side UberFlow's detection compares (`collisions.neighbours`): the bound
/// its loop is compiled for (`MAX_NEIGHBOURS` in `glsl/collide/detect.frag`).
pub const MAX_NEIGHBOURS: u32 = 32;

/// Most cells of a collision lattice: its cell keys are sorted as floats, exact up to 2^24.
pub const MAX_LATTICE_CELLS: u64 = 1 << 24;

/// Most particles the exact detection walks in a run of three cells along x (its density
/// limit); `sim::collide` compiles its search for it.
pub const EXACT_SCAN: u32 = 64;

/// An upper bound on the spheres of radius `r` with disjoint interiors whose centres lie in a run
/// of cells of side `g` that the exact search walks: three cells (3g × g × g) from a cell of 2r
/// up; below, the trimmed walk's run along x covers x ± 2r, at most 4r + 2g. Each sphere lies
/// inside the run grown by r on every side, so their volumes sum to at most that box's.
pub fn run_capacity(g: f32, r: f32) -> f64 {
    let (g, r) = (g as f64, r as f64);
    let run = if g < 2.0 * r {
        4.0 * r + 2.0 * g
    } else {
        3.0 * g
    };
    (run + 2.0 * r) * (g + 2.0 * r).powi(2) / (4.0 / 3.0 * std::f64::consts::PI * r.powi(3))
}

/// The largest cell whose runs cannot exceed [`EXACT_SCAN`] by [`run_capacity`] (about 2.96 r).
pub fn largest_exact_cell(r: f32) -> f32 {
    let (mut lo, mut hi) = (0.0f32, 10.0 * r);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if run_capacity(mid, r) <= EXACT_SCAN as f64 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

/// Cells of the lattice `[collisions]` describes, counted as the collision stage does
/// (`sim::collide::Lattice`: ceil of extent over cell per axis, at least 1, one more per axis
/// on the staggered lattice), saturating instead of wrapping.
fn lattice_cells(c: &crate::scene::schema::Collisions) -> u64 {
    let g = c.cell();
    let extra = u64::from(c.staggered);
    (0..3)
        .map(|k| {
            let n = ((c.bounds[1][k] - c.bounds[0][k]) / g).ceil().max(1.0);
            // `as` saturates, like the stage's conversion to u32.
            (n as u32) as u64 + extra
        })
        .fold(1u64, |a, n| a.saturating_mul(n))
}

/// `[fire]`, or, without it, that something is born at all.
fn fire(s: &SceneFile) -> Check {
    let Some(f) = &s.fire else {
        if s.emitters.is_empty() && s.constraints.is_none() {
            return fail(
                path(&[N("emitters")]),
                "the scene has no emitter, no [constraints] layout and no [fire] model: nothing \
                 would ever be born",
            );
        }
        return Ok(());
    };
    fire_section(f, s.time.dt)
}

/// The rules of a `[fire]` section run with steps of `dt` seconds: the one owner of them, for
/// scene files and for a [`FireParams`](crate::sim::FireParams) built in code alike.
pub fn fire_section(f: &crate::scene::Fire, dt: f32) -> std::result::Result<(), Invalid> {
    let at = |k| path(&[N("fire"), N(k)]);
    if !(f.life[0] > 0.0 && f.life[0] <= f.life[1] && f.life[1] <= f.max_age) {
        return fail(
            at("life"),
            "life must be [min, max] with 0 < min <= max <= max_age",
        );
    }
    for (key, v) in [
        ("emitter_radius", f.emitter_radius),
        ("damping", f.damping),
        ("turbulence", f.turbulence),
    ] {
        if v < 0.0 {
            return fail(at(key), format!("{key} {v} must not be negative"));
        }
    }
    duration(at("max_age"), "max_age", f.max_age)?;
    // Positions, speeds and accelerations, as for emitters and forces.
    bounded(at("emitter_center"), "emitter_center", &f.emitter_center)?;
    bounded(at("buoyancy"), "buoyancy", &f.buoyancy)?;
    for (key, v) in [
        ("emitter_radius", f.emitter_radius),
        ("speed", f.speed),
        ("spread", f.spread),
        ("converge", f.converge),
        ("turbulence", f.turbulence),
    ] {
        bounded(at(key), key, &[v])?;
    }
    // The fire's damping is a rate like `[[forces.damping]]` (v' = v (1 - damping dt)).
    forces::per_step(dt, at("damping"), "damping", f.damping)
}
