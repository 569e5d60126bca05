//! `[render]`: frame, camera, keyframes and sort.

use super::{fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{
    Blending, DrawMode, DrawPrimitive, Emitter, Keyframe, Precision, Render, RenderPath, SceneFile,
    SortEntries, SortKey, Variant,
};

use Key::{Index as I, Name as N};

/// `[render]`, `[render.camera]`, `[[render.keyframes]]`, `[render.sort]`, and the sprite keys of
/// every emitter (rotation speed, size over life, keyframes per type).
pub(super) fn render(s: &SceneFile) -> Check {
    let r = &s.render;
    frame_and_camera(r)?;
    super::render_options::options(s)?;
    keyframes(&[N("render"), N("keyframes")], &r.keyframes)?;
    if s.fire.is_some() {
        fire_render(r)?;
    }
    if r.mode == DrawMode::Surface {
        surface(s, r)?;
    }
    if r.primitive != DrawPrimitive::Points && r.path != RenderPath::TextureFetch {
        return fail(
            path(&[N("render"), N("primitive")]),
            format!(
                "primitive = \"{}\" replicates each particle's vertex by fetching its texel \
                 (gl_VertexID / 3 or / 6, Latta §3.4.5): use path = \"texture_fetch\", or primitive = \
                 \"points\" with the vertex buffer",
                primitive_name(r.primitive)
            ),
        );
    }
    if !(r.stretch >= 0.0 && r.stretch <= 10.0) {
        return fail(
            path(&[N("render"), N("stretch")]),
            format!(
                "stretch {} must lie in [0, 10] seconds (the exposure of stretched quads)",
                r.stretch
            ),
        );
    }
    if r.geometry && s.colliders.is_empty() {
        return fail(
            path(&[N("render"), N("geometry")]),
            "geometry = true draws the scene's colliders, and this scene has none: add a \
             [[colliders.*]] table, or remove the key",
        );
    }
    for (kind, i, e) in s.emitters.by_kind() {
        emitter_look(&[N("emitters"), N(kind.key()), I(i)], e)?;
    }
    sort(s, r)
}

/// `mode = "surface"`: connected geometry over a constraint layout, drawn opaque; the keys it
/// would ignore are refused.
fn surface(s: &SceneFile, r: &Render) -> Check {
    let at = path(&[N("render"), N("mode")]);
    if s.constraints.is_none() {
        return fail(
            at,
            "mode = \"surface\" draws the cloth sheet or hair strands of a [constraints] layout, \
             and this scene has none: use mode = \"points\" or \"sprites\", or add \
             [constraints]",
        );
    }
    let d = Render::default();
    let ignored = [
        ("primitive", r.primitive != d.primitive),
        ("path", r.path != d.path),
        ("blending", r.blending != d.blending),
        ("order", r.order != d.order),
        ("sort", r.sort != d.sort),
    ];
    match ignored.iter().find(|(_, differs)| *differs) {
        Some((key, _)) => fail(
            path(&[N("render"), N(key)]),
            format!(
                "{key} is not honoured with mode = \"surface\", which draws the layout opaque by \
                 texture fetch over an index buffer: remove {key}, or use mode = \"points\""
            ),
        ),
        None => Ok(()),
    }
}

/// `[render]` resolution, point size and intensity, and `[render.camera]`.
fn frame_and_camera(r: &Render) -> Check {
    if let Some(i) = r.resolution.iter().position(|s| *s == 0) {
        return fail(
            path(&[N("render"), N("resolution"), I(i)]),
            "both sides of resolution must be at least 1 pixel",
        );
    }
    if r.point_size <= 0.0 {
        return fail(
            path(&[N("render"), N("point_size")]),
            format!("point_size {} must be above 0 pixels", r.point_size),
        );
    }
    if r.intensity < 0.0 {
        return fail(
            path(&[N("render"), N("intensity")]),
            format!("intensity {} must not be negative", r.intensity),
        );
    }
    if !(r.camera.fov > 0.0 && r.camera.fov < 180.0) {
        return fail(
            path(&[N("render"), N("camera"), N("fov")]),
            format!("fov {} must lie in (0, 180) degrees", r.camera.fov),
        );
    }
    if r.camera.distance <= 0.0 {
        return fail(
            path(&[N("render"), N("camera"), N("distance")]),
            format!("distance {} must be above 0", r.camera.distance),
        );
    }
    Ok(())
}

/// `[render.sort]`: what each key, entry layout and spread over frames needs.
fn sort(s: &SceneFile, r: &Render) -> Check {
    if r.sort.key != SortKey::Distance && r.blending != Blending::Alpha {
        return fail(
            path(&[N("render"), N("sort"), N("key")]),
            format!(
                "key = \"{}\" orders the drawing of alpha blending, and blending = \"{}\" \
                 draws in any order: set blending = \"alpha\", or remove the key",
                r.sort.key.name(),
                blending_name(r.blending)
            ),
        );
    }
    let blocked = r.sort.variant == Some(Variant::Blocked);
    if r.sort.entries == Some(SortEntries::Compact) && !blocked {
        return fail(
            path(&[N("render"), N("sort"), N("entries")]),
            "compact entries are the blocked sort's: set render.sort.variant = \"blocked\", or \
             remove entries",
        );
    }
    if r.sort.entries == Some(SortEntries::Compact) && r.sort.key != SortKey::Distance {
        return fail(
            path(&[N("render"), N("sort"), N("entries")]),
            "compact entries quantise the depth over the camera's range: sort by key = \
             \"distance\", or remove entries",
        );
    }
    if blocked && r.blending == Blending::Alpha && r.sort.passes_per_frame.is_some() {
        return fail(
            path(&[N("render"), N("sort"), N("passes_per_frame")]),
            "the blocked sort runs whole sorts (its layout changes from pass to pass): remove \
             passes_per_frame, or use variant = \"oddeven\" to spread a sort over frames",
        );
    }
    if r.sort.passes_per_frame == Some(0) {
        return fail(
            path(&[N("render"), N("sort"), N("passes_per_frame")]),
            "passes_per_frame must be at least 1",
        );
    }
    if r.blending == Blending::Alpha
        && r.sort.passes_per_frame.is_some()
        && s.particles.precision == Precision::Fp24
    {
        // The engine would refuse it at the second frame, without a location.
        return fail(
            path(&[N("render"), N("sort"), N("passes_per_frame")]),
            "a sort spread over frames refreshes its keys in place (Latta §3.4.4), which the \
             identifier table of precision = \"fp24\" (UberFlow §4.3.1) cannot follow: remove \
             passes_per_frame, or use precision = \"fp32\"",
        );
    }
    Ok(())
}

/// The keys of `[render]` the fire's point renderer (the thesis, Listing 3) does not honour:
/// each given with a value other than its default is refused, so that no key is silently
/// ignored. It honours resolution, camera, point_size, intensity and background.
fn fire_render(r: &Render) -> Check {
    let d = Render::default();
    let why = "the fire draws additive points or soft sprites (`mode`) of one size coloured by \
               its own age ramp (the thesis, Listing 3)";
    let ignored = [
        ("path", r.path != d.path),
        ("primitive", r.primitive != d.primitive),
        ("stretch", r.stretch != d.stretch),
        ("blending", r.blending != d.blending),
        ("order", r.order != d.order),
        ("keyframes", r.keyframes != d.keyframes),
        ("sort", r.sort != d.sort),
        ("geometry", r.geometry != d.geometry),
    ];
    match ignored.iter().find(|(_, differs)| *differs) {
        Some((key, _)) => fail(
            path(&[N("render"), N(key)]),
            format!(
                "{key} is not honoured in a [fire] scene: {why}; remove it, or describe the \
                 scene with emitters and forces (the particle pipeline), which honours it"
            ),
        ),
        None => Ok(()),
    }
}

fn blending_name(b: Blending) -> &'static str {
    match b {
        Blending::Additive => "additive",
        Blending::Multiplicative => "multiplicative",
        Blending::Alpha => "alpha",
    }
}

fn primitive_name(p: DrawPrimitive) -> &'static str {
    match p {
        DrawPrimitive::Points => "points",
        DrawPrimitive::Quads => "quads",
        DrawPrimitive::Stretched => "stretched",
        DrawPrimitive::Triangles => "triangles",
    }
}

fn at(base: &[Key], more: &[Key]) -> Vec<Key> {
    [base, more].concat()
}

/// Empty, or 1 to 8 keyframes with ages ascending within [0, 1] and no negative colour.
fn keyframes(base: &[Key], keys: &[Keyframe]) -> Check {
    let max = crate::scene::MAX_KEYFRAMES;
    if keys.is_empty() {
        return Ok(());
    }
    if keys.len() > max {
        return fail(
            at(base, &[I(max)]),
            format!(
                "{} keyframes are too many: give 1 to {max} (linear between them; Latta \
                 §3.4.6 uses 4)",
                keys.len()
            ),
        );
    }
    let ages: Vec<f32> = keys.iter().map(|k| k.age).collect();
    let bad_age = (0..keys.len())
        .find(|&i| !(0.0..=1.0).contains(&ages[i]) || (i > 0 && ages[i] < ages[i - 1]));
    if let Some(i) = bad_age {
        return fail(
            at(base, &[I(i), N("age")]),
            format!(
                "keyframe ages must ascend within [0, 1] (relative age; the colour is held \
                 before the first and after the last); keyframe {} has age {}",
                i + 1,
                ages[i]
            ),
        );
    }
    for (i, k) in keys.iter().enumerate() {
        if let Some(c) = k.rgba.iter().position(|v| *v < 0.0) {
            return fail(
                at(base, &[I(i), N("rgba"), I(c)]),
                "keyframe colours and opacities must not be negative",
            );
        }
    }
    Ok(())
}

/// An emitter's sprite keys: `rotation_speed`, `size_over_life`, `keyframes`.
fn emitter_look(base: &[Key], e: &Emitter) -> Check {
    if let Some([lo, hi]) = e.rotation_speed {
        if !(lo.is_finite() && hi.is_finite() && lo <= hi && lo.abs().max(hi.abs()) <= 1e5) {
            return fail(
                at(base, &[N("rotation_speed")]),
                format!(
                    "rotation_speed [{lo}, {hi}] must be [min, max] degrees per second with \
                     min <= max, both within ±100000"
                ),
            );
        }
    }
    size_curve(base, &e.size_over_life)?;
    if let Some([lo, hi]) = e.size_range {
        if !(lo > 0.0 && lo <= hi && hi <= 1e3) {
            return fail(
                at(base, &[N("size_range")]),
                format!(
                    "size_range [{lo}, {hi}] must be [min, max] size factors with \
                     0 < min <= max <= 1000 (relative to the type's size)"
                ),
            );
        }
    }
    if let Some(f) = &e.flipbook {
        if !(1..=4).contains(&f.frames) {
            return fail(
                at(base, &[N("flipbook"), N("frames")]),
                format!(
                    "flipbook frames = {} must lie in 1 to 4: the atlas holds four tiles",
                    f.frames
                ),
            );
        }
        if let Some(rate) = f.rate {
            if !(rate > 0.0 && rate <= 1e4) {
                return fail(
                    at(base, &[N("flipbook"), N("rate")]),
                    format!(
                        "flipbook rate = {rate} must lie in (0, 10000] tiles per second; leave \
                         it out to spread the tiles over the particle's life"
                    ),
                );
            }
        }
    }
    keyframes(&at(base, &[N("keyframes")]), &e.keyframes)
}

/// `size_over_life`: two to four [relative age, scale] points, ages from 0 up to 1.
fn size_curve(base: &[Key], curve: &[[f32; 2]]) -> Check {
    if curve.is_empty() {
        return Ok(());
    }
    let here = at(base, &[N("size_over_life")]);
    if !(2..=4).contains(&curve.len()) {
        return fail(
            here,
            format!(
                "size_over_life has {} points: give two to four [relative age, scale] points",
                curve.len()
            ),
        );
    }
    let last = curve.len() - 1;
    let bad = (0..curve.len()).find(|&i| {
        let a = curve[i][0];
        (i == 0 && a != 0.0) || (i == last && a != 1.0) || (i > 0 && a < curve[i - 1][0])
    });
    if let Some(i) = bad {
        return fail(
            at(&here, &[I(i), I(0)]),
            format!(
                "size_over_life ages must ascend from 0 to 1 (the first 0, the last 1); \
                 point {} has age {}",
                i + 1,
                curve[i][0]
            ),
        );
    }
    if let Some(i) = curve.iter().position(|p| !(p[1] >= 0.0 && p[1] <= 1e3)) {
        return fail(
            at(&here, &[I(i), I(1)]),
            format!(
                "size_over_life scale {} must lie in [0, 1000] (relative to the sprite size)",
                curve[i][1]
            ),
        );
    }
    Ok(())
}
