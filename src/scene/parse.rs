//! Reading a scene file: parse, reject non-finite numbers, validate, read the meshes it names,
//! locate the first error; and the device-size check that runs once a context exists.

use toml::de::DeTable;
use toml::Spanned;

use super::locate::{document, find_non_finite, locate, scene_error, Key};
use super::schema::{Blending, SceneFile};
use crate::error::Result;

use Key::{Index as I, Name as N};

/// Parses and validates a scene file; `path` names it in errors. Reads the files it names
/// (meshes, fields) after any settings, in one place for every command.
pub fn parse(path: &str, src: &str) -> Result<SceneFile> {
    let (doc, mut scene) = parse_unloaded(path, src)?;
    load_files(path, src, &doc, &mut scene)?;
    Ok(scene)
}

/// Parses and validates a scene file without reading the files it names: what `--set` edits
/// before [`load_files`] reads them (a setting may name another file).
pub(super) fn parse_unloaded<'s>(
    path: &str,
    src: &'s str,
) -> Result<(Spanned<DeTable<'s>>, SceneFile)> {
    let doc = DeTable::parse(src).map_err(|e| {
        let at = e.span().map_or(0, |s| s.start);
        let mut message = e.message().trim().to_owned();
        if message == "duplicate key" {
            // Name the key: the parser's message does not.
            let key: String = src
                .get(at..)
                .unwrap_or_default()
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == '-')
                .collect();
            if !key.is_empty() {
                message = format!("duplicate key `{key}`: each key may be set only once");
            }
        }
        scene_error(path, src, at, message)
    })?;
    if let Some((at, message)) = find_non_finite(doc.get_ref()) {
        return Err(scene_error(path, src, at, message));
    }
    let scene: SceneFile = toml::from_str(src).map_err(|e| {
        scene_error(
            path,
            src,
            e.span().map_or(0, |s| s.start),
            super::suggest::suggest_in_message(e.message().trim()),
        )
    })?;
    if let Err(invalid) = scene.validate() {
        return Err(scene_error(
            path,
            src,
            locate(&doc, &invalid.at),
            invalid.message,
        ));
    }
    Ok((doc, scene))
}

/// Reads every file a validated scene names, relative to the scene file's folder: the meshes
/// and fields (height images and `.npy`, wind, distances) into the scene, and the custom
/// forces' GLSL paths made relative to here; records where the scene came from. The one place
/// a scene's files are loaded, after any `--set`, so that a field is the same with or without
/// one. `doc` is `src` parsed, for the errors' line and column.
pub(super) fn load_files(
    path: &str,
    src: &str,
    doc: &Spanned<DeTable<'_>>,
    scene: &mut SceneFile,
) -> Result<()> {
    super::mesh::load_meshes(path, src, doc, scene)?;
    super::field_files::load_field_files(path, src, doc, scene)?;
    // A custom force's GLSL file is named relative to the scene file, like its meshes.
    if !path.ends_with(" (built-in)") {
        if let Some(dir) = std::path::Path::new(path).parent() {
            scene.resolve_custom_paths(dir);
        }
    }
    scene.origin =
        super::schema::Origin(Some(std::sync::Arc::new((path.to_owned(), src.to_owned()))));
    Ok(())
}

impl SceneFile {
    /// [`validate`](SceneFile::validate) as an error: at the file's line and column where the
    /// scene was parsed from one (the key's value there, or its table when the key was added
    /// later), else naming the key. What the engine and the simulations call, so that a scene
    /// changed after parsing still names where its fault lies.
    pub fn check(&self) -> Result<()> {
        let Err(invalid) = self.validate() else {
            return Ok(());
        };
        Err(match &self.origin.0 {
            Some(origin) => {
                let (path, src) = (&origin.0, &origin.1);
                let at = document(path, src).map_or(0, |doc| locate(&doc, &invalid.at));
                scene_error(path, src, at, invalid.message)
            }
            None => crate::error::Error::InvalidInput(format!(
                "scene `{}`: {}: {}",
                self.name,
                super::locate::key_path(&invalid.at),
                invalid.message
            )),
        })
    }
}

/// Texture size limits of a device, for [`check_limits`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SizeLimits {
    /// GL_MAX_TEXTURE_SIZE.
    pub max_texture: u32,
    /// GL_MAX_3D_TEXTURE_SIZE.
    pub max_3d_texture: u32,
}

/// Checks the sizes a scene asks of the device (state and sort textures, frame, fields) and
/// reports the first one over the limit at its file, line and column. `skip` names keys whose
/// values came from elsewhere (command-line overrides), which the caller checks itself.
pub fn check_limits(
    path: &str,
    src: &str,
    scene: &SceneFile,
    limits: SizeLimits,
    skip: &[&str],
) -> Result<()> {
    let mut over = sizes_2d(scene, limits.max_texture, skip);
    over.extend(sizes_3d(scene, limits.max_3d_texture));
    let Some((at, what, value, max)) = over.into_iter().find(|o| o.2 > o.3) else {
        return Ok(());
    };
    let doc = document(path, src)?;
    Err(scene_error(
        path,
        src,
        locate(&doc, &at),
        format!("{what} {value} is over this device's limit of {max}: use a smaller size"),
    ))
}

/// A size a scene asks of the device: the key that sets it, what it is, its value, the limit.
type Over = (Vec<Key>, &'static str, u32, u32);

/// The 2D texture sides a scene asks for (state, sort, frame, height fields), in the order
/// [`check_limits`] reports them, each against `t`; keys in `skip` are left out.
fn sizes_2d(scene: &SceneFile, t: u32, skip: &[&str]) -> Vec<Over> {
    let mut over: Vec<Over> = Vec::new();
    let [w, h] = scene.particles.size;
    if !skip.contains(&"particles.size") {
        let sort = if scene.render.blending == Blending::Alpha {
            w.next_power_of_two().max(h.next_power_of_two())
        } else {
            0
        };
        over.push((
            vec![N("particles"), N("size")],
            "state texture side",
            w.max(h),
            t,
        ));
        over.push((
            vec![N("particles"), N("size")],
            "sort texture side (the state's, rounded up to a power of two)",
            sort,
            t,
        ));
    }
    if !skip.contains(&"render.resolution") {
        let [rw, rh] = scene.render.resolution;
        over.push((
            vec![N("render"), N("resolution")],
            "frame side",
            rw.max(rh),
            t,
        ));
    }
    for (i, hf) in scene.colliders.heightfield.iter().enumerate() {
        let (key, side) = match &hf.heights {
            Some(d) => (
                if hf.image.is_some() { "image" } else { "npy" },
                d.size[0].max(d.size[1]),
            ),
            None => ("resolution", hf.resolution),
        };
        over.push((
            vec![N("colliders"), N("heightfield"), I(i), N(key)],
            "height-field texture side",
            side,
            t,
        ));
    }
    over
}

/// The 3D texture sides a scene asks for (fields from files, then the fields' resolutions),
/// each against `max_3d`.
fn sizes_3d(scene: &SceneFile, max_3d: u32) -> Vec<Over> {
    let mut over: Vec<Over> = Vec::new();
    // Fields from files: their sides are the files' shapes.
    let side3 = |d: &Option<super::FieldData>| d.as_ref().map(|d| d.size.into_iter().max());
    let sdf_files = scene.colliders.sdf.iter().enumerate().map(|(i, s)| {
        let at = vec![N("colliders"), N("sdf"), I(i), N("field")];
        (
            at,
            "distance-field 3D texture side (the file's shape)",
            &s.distances,
        )
    });
    let wind_files = scene.forces.wind.iter().enumerate().map(|(i, w)| {
        let at = vec![N("forces"), N("wind"), I(i), N("field")];
        (at, "flow-field 3D texture side (the file's shape)", &w.data)
    });
    for (at, what, data) in sdf_files.chain(wind_files) {
        if let Some(Some(side)) = side3(data) {
            over.push((at, what, side, max_3d));
        }
    }
    for (i, s) in scene.colliders.sdf.iter().enumerate() {
        over.push((
            vec![N("colliders"), N("sdf"), I(i), N("resolution")],
            "distance-field 3D texture side",
            s.resolution,
            max_3d,
        ));
    }
    for (i, wnd) in scene.forces.wind.iter().enumerate() {
        over.push((
            vec![N("forces"), N("wind"), I(i), N("resolution")],
            "flow-field 3D texture side",
            wnd.resolution,
            max_3d,
        ));
    }
    over
}

/// Checks the widest point a particle scene draws (`render.point_size`, for sprites times an
/// emitter's `sprite_scale` and its largest `size_over_life` scale) against the device's
/// largest point, `max_point` pixels, as the renderer does; the error is at the key to change.
/// Quads have no such limit; the fire draws points of `point_size` (its sprites are soft discs
/// of that size, with no emitter's scale).
pub fn check_point_size(path: &str, src: &str, scene: &SceneFile, max_point: f32) -> Result<()> {
    use super::schema::{DrawMode, DrawPrimitive};
    let r = &scene.render;
    if r.primitive != DrawPrimitive::Points {
        return Ok(());
    }
    let fix = match scene.fire {
        // The fire draws points only (render.primitive is refused there).
        Some(_) => format!("give a point_size of at most {max_point}"),
        None => {
            "use render.primitive = \"quads\", which has no such limit, or smaller sizes".into()
        }
    };
    let mut over: Option<(Vec<Key>, String)> = None;
    if r.point_size > max_point {
        over = Some((
            vec![N("render"), N("point_size")],
            format!("point_size {} is wider", r.point_size),
        ));
    } else if r.mode == DrawMode::Sprites && scene.fire.is_none() {
        // The renderer looks at the first four emitters, in type order (one type each).
        let emitters = (scene.emitters.by_kind())
            .map(|(k, j, e)| (k.key(), j, e))
            .take(4);
        for (kind, j, e) in emitters {
            let curve = if (2..=4).contains(&e.size_over_life.len()) {
                e.size_over_life.iter().map(|p| p[1]).fold(0.0, f32::max)
            } else {
                1.0
            };
            // A curve's scale: the largest it can take.
            let scale = e.sprite_scale.bounds()[0][1];
            let widest = r.point_size * scale * curve;
            if widest > max_point {
                let (key, what) = if r.point_size * scale > max_point {
                    (N("sprite_scale"), format!("sprite_scale up to {scale}"))
                } else {
                    (N("size_over_life"), format!("size_over_life up to {curve}"))
                };
                over = Some((
                    vec![N("emitters"), N(kind), I(j), key],
                    format!("{what} makes sprites {widest} pixels wide, which is wider"),
                ));
                break;
            }
        }
    }
    let Some((at, what)) = over else {
        return Ok(());
    };
    let doc = document(path, src)?;
    Err(scene_error(
        path,
        src,
        locate(&doc, &at),
        format!(
            "{what} than this device's largest point, {max_point} pixels \
             (GL_ALIASED_POINT_SIZE_RANGE): {fix}"
        ),
    ))
}
