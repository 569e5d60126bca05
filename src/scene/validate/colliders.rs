//! `[colliders]`: planes, spheres, boxes, the height field and the distance field.

use super::{bounded, direction, fail, nonzero, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{
    BoxCollider, Collider, ColliderKind, HeightFieldCollider, PlaneCollider, SceneFile,
    SdfCollider, SphereCollider,
};

use Key::{Index as I, Name as N};

/// `[colliders]` and its `[[colliders.*]]` kinds.
pub(super) fn colliders(s: &SceneFile) -> Check {
    let c = &s.colliders;
    for kind in ColliderKind::ALL.into_iter().filter(|k| k.single()) {
        if c.count(kind) > 1 {
            let kind = kind.key();
            return fail(
                path(&[N("colliders"), N(kind), I(1)]),
                format!("one {kind} per scene (it is one texture)"),
            );
        }
    }
    if c.slow_speed < 0.0 {
        return fail(
            path(&[N("colliders"), N("slow_speed")]),
            "slow_speed must not be negative",
        );
    }
    bounded(
        path(&[N("colliders"), N("slow_speed")]),
        "slow_speed",
        &[c.slow_speed],
    )?;
    for (i, collider) in c.indexed() {
        match collider {
            Collider::Plane(p) => plane(i, p)?,
            Collider::Sphere(s) => sphere(i, s)?,
            Collider::Box(b) => aabb(i, b)?,
            Collider::HeightField(hf) => heightfield(i, hf)?,
            Collider::Sdf(sdf) if sdf.field.is_some() => sdf_file(i, sdf)?,
            Collider::Sdf(sdf) => sdf_shapes(i, sdf)?,
        }
    }
    Ok(())
}

/// `[[colliders.plane]]` number `i`.
fn plane(i: usize, p: &PlaneCollider) -> Check {
    if !nonzero(p.normal) {
        return fail(
            path(&[N("colliders"), N("plane"), I(i), N("normal")]),
            "normal must not be zero",
        );
    }
    let at = |k| path(&[N("colliders"), N("plane"), I(i), N(k)]);
    direction(at("normal"), "normal", p.normal)?;
    bounded(at("point"), "point", &p.point)?;
    check_response(
        path(&[N("colliders"), N("plane"), I(i)]),
        p.friction,
        p.resilience,
    )
}

/// `[[colliders.sphere]]` number `i`.
fn sphere(i: usize, s: &SphereCollider) -> Check {
    let at = |k| path(&[N("colliders"), N("sphere"), I(i), N(k)]);
    bounded(at("center"), "center", &s.center)?;
    bounded(at("radius"), "radius", &[s.radius])?;
    if s.radius <= 0.0 {
        return fail(
            path(&[N("colliders"), N("sphere"), I(i), N("radius")]),
            "radius must be above 0",
        );
    }
    check_response(
        path(&[N("colliders"), N("sphere"), I(i)]),
        s.friction,
        s.resilience,
    )
}

/// `[[colliders.box]]` number `i`.
fn aabb(i: usize, b: &BoxCollider) -> Check {
    let at = |k| path(&[N("colliders"), N("box"), I(i), N(k)]);
    bounded(at("min"), "min", &b.min)?;
    bounded(at("max"), "max", &b.max)?;
    if (0..3).any(|k| b.min[k] >= b.max[k]) {
        return fail(
            path(&[N("colliders"), N("box"), I(i), N("max")]),
            "max must exceed min on every axis",
        );
    }
    check_response(
        path(&[N("colliders"), N("box"), I(i)]),
        b.friction,
        b.resilience,
    )
}

/// `[[colliders.heightfield]]` number `i`: procedural hills or heights from a file.
fn heightfield(i: usize, hf: &HeightFieldCollider) -> Check {
    let at = |k| path(&[N("colliders"), N("heightfield"), I(i), N(k)]);
    // Heights and extents are coordinates; the frequency (1/m) multiplies one inside a sine.
    bounded(at("extent"), "extent", &hf.extent)?;
    bounded(at("base"), "base", &[hf.base])?;
    bounded(at("amplitude"), "amplitude", &[hf.amplitude])?;
    bounded(at("frequency"), "frequency", &[hf.frequency])?;
    match (&hf.image, &hf.npy) {
        (Some(_), Some(_)) => {
            return fail(
                at("npy"),
                "a height field is an image or an npy file: remove one",
            );
        }
        (None, None) => {
            if !(2..=4096).contains(&hf.resolution) {
                return fail(at("resolution"), "resolution must lie in 2..=4096");
            }
            if hf.frequency <= 0.0 {
                return fail(
                    at("frequency"),
                    "procedural hills need a frequency above 0 (1/m), or give image or npy",
                );
            }
        }
        _ if hf.resolution != 0 || hf.frequency != 0.0 => {
            return fail(
                at(if hf.resolution != 0 {
                    "resolution"
                } else {
                    "frequency"
                }),
                "a height field from a file takes its resolution from the file and has no \
                 frequency: remove the key",
            );
        }
        _ => {}
    }
    if hf.extent[0] >= hf.extent[2] || hf.extent[1] >= hf.extent[3] {
        return fail(
            path(&[N("colliders"), N("heightfield"), I(i), N("extent")]),
            "extent must be [min x, min z, max x, max z] with min < max",
        );
    }
    check_response(
        path(&[N("colliders"), N("heightfield"), I(i)]),
        hf.friction,
        hf.resilience,
    )
}

/// `[[colliders.sdf]]` number `i` read from a `field` file: no shapes, no resolution.
fn sdf_file(i: usize, sdf: &SdfCollider) -> Check {
    let at = |k| path(&[N("colliders"), N("sdf"), I(i), N(k)]);
    if sdf.resolution != 0 || sdf.mesh.is_some() {
        return fail(
            at(if sdf.resolution != 0 {
                "resolution"
            } else {
                "mesh"
            }),
            "a distance field from a file takes its resolution and shape from the file: \
             remove the key",
        );
    }
    if !(sdf.spheres.is_empty() && sdf.boxes.is_empty()) {
        return fail(
            at("field"),
            "a distance field is a file or spheres and boxes: remove one",
        );
    }
    sdf_bounds(i, sdf)?;
    check_response(
        path(&[N("colliders"), N("sdf"), I(i)]),
        sdf.friction,
        sdf.resilience,
    )
}

/// `[[colliders.sdf]]` number `i` baked from spheres and boxes, or from a mesh.
fn sdf_shapes(i: usize, sdf: &SdfCollider) -> Check {
    if !(2..=256).contains(&sdf.resolution) {
        return fail(
            path(&[N("colliders"), N("sdf"), I(i), N("resolution")]),
            "resolution must lie in 2..=256",
        );
    }
    sdf_bounds(i, sdf)?;
    let at = |k| path(&[N("colliders"), N("sdf"), I(i), N(k)]);
    for (k, sphere) in sdf.spheres.iter().enumerate() {
        bounded([&at("spheres")[..], &[I(k)]].concat(), "sphere", sphere)?;
    }
    for (k, b) in sdf.boxes.iter().enumerate() {
        bounded([&at("boxes")[..], &[I(k)]].concat(), "box", b)?;
    }
    let shapes = !(sdf.spheres.is_empty() && sdf.boxes.is_empty());
    match &sdf.mesh {
        None if !shapes => {
            return fail(
                path(&[N("colliders"), N("sdf"), I(i)]),
                "a distance field needs at least one sphere or box, or a mesh",
            );
        }
        Some(_) if shapes => {
            return fail(
                path(&[N("colliders"), N("sdf"), I(i), N("mesh")]),
                "a distance field is either a mesh or spheres and boxes: remove one",
            );
        }
        Some(m) if m.trim().is_empty() => {
            return fail(
                path(&[N("colliders"), N("sdf"), I(i), N("mesh")]),
                "mesh must name an OBJ file (relative to the scene file)",
            );
        }
        _ => {}
    }
    check_response(
        path(&[N("colliders"), N("sdf"), I(i)]),
        sdf.friction,
        sdf.resilience,
    )
}

/// The corners of `[[colliders.sdf]]` number `i`'s `bounds`.
fn sdf_bounds(i: usize, sdf: &SdfCollider) -> Check {
    for (c, corner) in sdf.bounds.iter().enumerate() {
        bounded(
            path(&[N("colliders"), N("sdf"), I(i), N("bounds"), I(c)]),
            "bounds",
            corner,
        )?;
    }
    Ok(())
}

/// Friction and resilience (Latta eq. 5), both in [0, 1].
fn check_response(at: Vec<Key>, friction: f32, resilience: f32) -> Check {
    if !(0.0..=1.0).contains(&friction) {
        let mut p = at.clone();
        p.push(N("friction"));
        return fail(p, format!("friction {friction} is outside [0, 1]"));
    }
    if !(0.0..=1.0).contains(&resilience) {
        let mut p = at;
        p.push(N("resilience"));
        return fail(p, format!("resilience {resilience} is outside [0, 1]"));
    }
    Ok(())
}
