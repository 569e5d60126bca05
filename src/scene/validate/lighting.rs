//! `render.lighting`, `render.slices`, `render.light`: half-angle slicing (Kniss et al. 2003;
//! Green 2008) lights alpha-blended particles, and draws them in its own passes, so the keys it
//! cannot honour are refused where they are.

use super::{fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{
    Blending, DrawMode, DrawPrimitive, Lighting, Render, RenderPath, Rotate, SceneFile, SortEntries,
};

use Key::Name as N;

/// The most slices one frame may be drawn in.
pub const MAX_SLICES: u32 = 1024;

/// The widest light buffer, in texels a side.
pub const MAX_LIGHT_RESOLUTION: u32 = 4096;

/// The lighting keys: a light only for `lighting = "half_angle"`, which needs alpha blending,
/// sorted by distance, drawn as points or quads by texture fetch.
pub(super) fn lighting(s: &SceneFile) -> Check {
    let r = &s.render;
    let d = Render::default();
    if r.lighting == Lighting::None {
        let given = [
            ("slices", r.slices != d.slices),
            ("light", r.light != d.light),
        ];
        if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
            return fail(
                path(&[N("render"), N(key)]),
                format!(
                    "{key} is for lit particles: add lighting = \"half_angle\", or remove {key}"
                ),
            );
        }
        return Ok(());
    }
    let here = path(&[N("render"), N("lighting")]);
    let why = "half-angle slicing draws alpha-blended particles in slices along the half-angle \
               vector (Kniss et al. 2003)";
    if s.fire.is_some() {
        return fail(
            here,
            format!("the [fire] draws additive points: {why}; remove lighting"),
        );
    }
    if r.blending != Blending::Alpha {
        return fail(
            here,
            format!("{why}: set blending = \"alpha\", or remove lighting"),
        );
    }
    let refused = [
        ("mode", r.mode == DrawMode::Surface, "points or sprites"),
        (
            "primitive",
            !matches!(r.primitive, DrawPrimitive::Points | DrawPrimitive::Quads),
            "points or quads (both drawn as quads)",
        ),
        ("path", r.path != RenderPath::TextureFetch, "texture_fetch"),
        ("rotate", r.rotate != Rotate::Age, "age"),
        ("geometry", r.geometry, "false (no colliders drawn)"),
        (
            "lookup",
            r.lookup == crate::scene::Lookup::Index,
            "gather (the slices read the gathered state)",
        ),
    ];
    if let Some((key, _, want)) = refused.iter().find(|(_, bad, _)| *bad) {
        return fail(
            path(&[N("render"), N(key)]),
            format!("lighting = \"half_angle\" draws with {key} = {want}: change {key}, or remove lighting"),
        );
    }
    let sort = |key: &'static str| path(&[N("render"), N("sort"), N(key)]);
    if r.sort.key != d.sort.key {
        return fail(
            sort("key"),
            "lit particles are sorted along the half-angle vector, not by this key: remove key",
        );
    }
    if r.sort.entries == Some(SortEntries::Compact) {
        return fail(
            sort("entries"),
            "compact entries quantise the viewer distance, and lit particles are sorted along \
             the half-angle vector: remove entries",
        );
    }
    if r.sort.passes_per_frame.is_some() {
        return fail(
            sort("passes_per_frame"),
            "the half-angle vector turns with the camera and the light, and every slice needs \
             the whole order: remove passes_per_frame",
        );
    }
    light(r)
}

/// `slices` and `[render.light]`.
fn light(r: &Render) -> Check {
    if !(1..=MAX_SLICES).contains(&r.slices) {
        return fail(
            path(&[N("render"), N("slices")]),
            format!(
                "slices = {} must lie in 1 to {MAX_SLICES} (Green draws 32 to 128)",
                r.slices
            ),
        );
    }
    let l = &r.light;
    let at = |key: &'static str| path(&[N("render"), N("light"), N(key)]);
    let largest = l.direction.iter().fold(0.0f32, |m, x| m.max(x.abs()));
    let finite = l.direction.iter().all(|x| x.is_finite());
    if !(finite && (super::MIN_DIRECTION..=super::MAX_COORDINATE).contains(&largest)) {
        return fail(
            at("direction"),
            format!(
                "direction must have a component of at least {} and none above {}: the way \
                 the light travels, e.g. [0, -1, 0] from straight above",
                super::MIN_DIRECTION,
                super::MAX_COORDINATE
            ),
        );
    }
    for (key, c) in [("colour", l.colour), ("ambient", l.ambient)] {
        if !c.iter().all(|x| (0.0..=100.0).contains(x)) {
            return fail(at(key), format!("{key} channels must lie in [0, 100]"));
        }
    }
    if !(0.0..=100.0).contains(&l.density) {
        return fail(
            at("density"),
            format!(
                "density = {} must lie in [0, 100] (a scale of the opacity)",
                l.density
            ),
        );
    }
    if !(1..=MAX_LIGHT_RESOLUTION).contains(&l.resolution) {
        return fail(
            at("resolution"),
            format!(
                "resolution = {} must lie in 1 to {MAX_LIGHT_RESOLUTION} texels a side",
                l.resolution
            ),
        );
    }
    if let Some(e) = l.extent {
        if !(e > 0.0 && e <= super::MAX_COORDINATE) {
            return fail(
                at("extent"),
                format!(
                    "extent = {e} must lie in (0, {}] scene units (half the side of the square \
                     the light buffer covers)",
                    super::MAX_COORDINATE
                ),
            );
        }
    }
    Ok(())
}
