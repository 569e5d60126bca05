//! `[render]`: frame, camera, keyframes and sort.

use super::{fail, path, Check};
use crate::scene::locate::Key;
use crate::scene::schema::{SceneFile, Variant};

use Key::{Index as I, Name as N};

/// `[render]`, `[render.camera]`, `[[render.keyframes]]`, `[render.sort]`.
pub(super) fn render(s: &SceneFile) -> Check {
    let r = &s.render;
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
    if !r.keyframes.is_empty() {
        if r.keyframes.len() != 4 {
            return fail(
                path(&[N("render"), N("keyframes")]),
                "give exactly four keyframes (three linear segments, Latta §3.4.6)",
            );
        }
        let ages: Vec<f32> = r.keyframes.iter().map(|k| k.age).collect();
        let bad_age = if ages[0] != 0.0 {
            Some(0)
        } else {
            (1..4)
                .find(|&i| ages[i] < ages[i - 1])
                .or((ages[3] != 1.0).then_some(3))
        };
        if let Some(i) = bad_age {
            return fail(
                path(&[N("render"), N("keyframes"), I(i), N("age")]),
                format!(
                    "keyframe ages must ascend from 0 to 1 (the first 0, the last 1); \
                     keyframe {} has age {}",
                    i + 1,
                    ages[i]
                ),
            );
        }
        for (i, k) in r.keyframes.iter().enumerate() {
            if let Some(c) = k.rgba.iter().position(|v| *v < 0.0) {
                return fail(
                    path(&[N("render"), N("keyframes"), I(i), N("rgba"), I(c)]),
                    "keyframe colours and opacities must not be negative",
                );
            }
        }
    }
    if let Some(v) = &r.sort.variant {
        if let Err(e) = Variant::from_name(v) {
            return fail(path(&[N("render"), N("sort"), N("variant")]), e.to_string());
        }
    }
    if r.sort.passes_per_frame == Some(0) {
        return fail(
            path(&[N("render"), N("sort"), N("passes_per_frame")]),
            "passes_per_frame must be at least 1",
        );
    }
    Ok(())
}
