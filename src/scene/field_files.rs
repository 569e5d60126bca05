//! Fields from files (UberFlow §4.2: "the flow field is stored in a 3D texture"; §4.6: "height
//! fields ... stored in a 2D texture"; Latta §3.4.2: "a flow field texture"): the files that
//! `[[colliders.heightfield]] image` or `npy`, `[[forces.wind]] field` and `[[colliders.sdf]]
//! field` name, read and checked when the scene is parsed, so that a missing or bad file is a
//! scene error at the key's line and column that says what is wrong with the file (its shape,
//! dtype, a non-finite value). Data only: `sim::fields` builds the textures. The sizes are checked
//! against the device's limits by [`super::check_limits`], once a context exists.
//!
//! Files are read relative to the scene file's folder; they must be regular files of at most
//! [`MAX_FIELD_FILE`] bytes. Built-in scenes name none.

use std::path::Path;

use toml::de::DeTable;
use toml::Spanned;

use super::locate::{locate, scene_error, Key};
use super::schema::{FieldData, SceneFile};
use crate::error::Result;

use Key::{Index as I, Name as N};

/// The largest field file read (bytes): a 256³ wind of three float32 components is 192 MiB.
pub const MAX_FIELD_FILE: u64 = 256 << 20;

/// The most nodes a height map from an image may have: as many float32 values as a field file
/// may hold.
pub const MAX_FIELD_NODES: u64 = MAX_FIELD_FILE / 4;

/// Reads and checks every field file `scene` names; `path` labels the scene (a file path, or a
/// built-in's label) and `src` is its source, for the errors' line and column.
pub(super) fn load_field_files(
    path: &str,
    src: &str,
    doc: &Spanned<DeTable<'_>>,
    scene: &mut SceneFile,
) -> Result<()> {
    let fail = |at: &[Key], message: String| scene_error(path, src, locate(doc, at), message);
    for (i, hf) in scene.colliders.heightfield.iter_mut().enumerate() {
        let (key, name) = match (&hf.image, &hf.npy) {
            (Some(n), _) => ("image", n.clone()),
            (None, Some(n)) => ("npy", n.clone()),
            (None, None) => continue,
        };
        let at = [N("colliders"), N("heightfield"), I(i), N(key)];
        let bytes = read(path, &name).map_err(|m| fail(&at, m))?;
        let data = if key == "image" {
            grey_image(&bytes)
        } else {
            npy_field(&name, &bytes, &[2], 1)
        };
        hf.heights = Some(data.map_err(|m| fail(&at, format!("{key} `{name}`: {m}")))?);
    }
    for (i, w) in scene.forces.wind.iter_mut().enumerate() {
        let Some(name) = w.field.clone() else {
            continue;
        };
        let at = [N("forces"), N("wind"), I(i), N("field")];
        let bytes = read(path, &name).map_err(|m| fail(&at, m))?;
        let data = npy_field(&name, &bytes, &[3, 2], 3)
            .map_err(|m| fail(&at, format!("field `{name}`: {m}")))?;
        w.data = Some(data);
    }
    for (i, sdf) in scene.colliders.sdf.iter_mut().enumerate() {
        let Some(name) = sdf.field.clone() else {
            continue;
        };
        let at = [N("colliders"), N("sdf"), I(i), N("field")];
        let bytes = read(path, &name).map_err(|m| fail(&at, m))?;
        let data = npy_field(&name, &bytes, &[3], 1)
            .map_err(|m| fail(&at, format!("field `{name}`: {m}")))?;
        sdf.distances = Some(data);
    }
    Ok(())
}

/// The bytes of field file `name` of the scene labelled `scene`.
fn read(scene: &str, name: &str) -> std::result::Result<Vec<u8>, String> {
    if scene.ends_with(" (built-in)") {
        return Err(format!("the built-in scenes have no file `{name}`"));
    }
    let folder = Path::new(scene).parent().unwrap_or(Path::new(""));
    let file = folder.join(name);
    let why = "the path is relative to the scene file's folder";
    let meta = std::fs::metadata(&file)
        .map_err(|e| format!("cannot read field file {}: {e} ({why})", file.display()))?;
    if !meta.is_file() {
        return Err(format!(
            "field file {} is not a regular file ({why})",
            file.display()
        ));
    }
    if meta.len() > MAX_FIELD_FILE {
        return Err(format!(
            "field file {} has {} bytes, more than the {MAX_FIELD_FILE} a field may have: \
             resample it",
            file.display(),
            meta.len()
        ));
    }
    std::fs::read(&file).map_err(|e| format!("cannot read field file {}: {e}", file.display()))
}

/// A greyscale PNG as values in [0, 1], row 0 first (x along a row): 8 or 16 bits, or 1, 2 or 4
/// (the decoder spreads their levels over 0..=255, so black is 0 and white 1 at any depth).
pub fn grey_image(bytes: &[u8]) -> std::result::Result<FieldData, String> {
    // The size the header declares is bounded before a pixel is decoded: a small file may
    // declare an image whose floats would not fit in memory.
    let reader = || {
        let mut r =
            image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Png);
        r.no_limits();
        r
    };
    let (w, h) = reader()
        .into_dimensions()
        .map_err(|e| format!("not a readable PNG: {e}"))?;
    if w as u64 * h as u64 > MAX_FIELD_NODES {
        return Err(format!(
            "the image is {w}x{h}: a height map has at most {MAX_FIELD_NODES} pixels (the \
             values a field file of {MAX_FIELD_FILE} bytes holds); resample it"
        ));
    }
    let img = reader()
        .decode()
        .map_err(|e| format!("not a readable PNG: {e}"))?;
    let (w, h) = (img.width(), img.height());
    let data: Vec<f32> = match img {
        image::DynamicImage::ImageLuma8(g) => g.pixels().map(|p| p.0[0] as f32 / 255.0).collect(),
        image::DynamicImage::ImageLuma16(g) => {
            g.pixels().map(|p| p.0[0] as f32 / 65535.0).collect()
        }
        other => {
            return Err(format!(
                "the image is {:?}, not 8- or 16-bit greyscale: save it as grey (L or I;16)",
                other.color()
            ))
        }
    };
    if w < 2 || h < 2 {
        return Err(format!(
            "the image is {w}x{h}: a height field needs at least 2x2 pixels"
        ));
    }
    Ok(FieldData {
        size: [w, h, 1],
        channels: 1,
        data,
    })
}

/// A float32 `.npy` field of one of the spatial dimensions `dims` (3 or 2: (nz, ny, nx) or
/// (nz, nx); a 2D wind is extruded to two layers in y), each with at least 2 nodes, and
/// `channels` values per node (a last axis of that length when above 1). Every value finite.
pub fn npy_field(
    name: &str,
    bytes: &[u8],
    dims: &[usize],
    channels: usize,
) -> std::result::Result<FieldData, String> {
    let (shape, v) =
        crate::npy::decode_f32_shaped(Path::new(name), bytes).map_err(|e| e.to_string())?;
    let spatial = if channels > 1 {
        match shape.split_last() {
            Some((&c, rest)) if c == channels => rest.to_vec(),
            _ => {
                return Err(format!(
                    "shape {shape:?} does not end in {channels} components per node"
                ))
            }
        }
    } else {
        shape.clone()
    };
    let want = dims
        .iter()
        .map(|d| {
            let axes = if *d == 3 { "(nz, ny, nx" } else { "(nz, nx" };
            if channels > 1 {
                format!("{axes}, {channels})")
            } else {
                format!("{axes})")
            }
        })
        .collect::<Vec<_>>()
        .join(" or ");
    if !dims.contains(&spatial.len()) {
        return Err(format!("shape {shape:?} is not {want}"));
    }
    if let Some(n) = spatial.iter().find(|&&n| n < 2) {
        return Err(format!(
            "shape {shape:?} has an axis of {n}: a field needs at least 2 nodes per axis"
        ));
    }
    if spatial.iter().any(|&n| n > u32::MAX as usize) {
        return Err(format!("shape {shape:?} is too large"));
    }
    if let Some(k) = v.iter().position(|x| !x.is_finite()) {
        return Err(format!(
            "value {} at flat index {k} is not finite: every value must be a finite float",
            v[k]
        ));
    }
    let size = match spatial.as_slice() {
        [nz, ny, nx] => [*nx as u32, *ny as u32, *nz as u32],
        [nz, nx] if channels > 1 => {
            // A horizontal layer the same at every height: two identical layers in y.
            let (nx, nz) = (*nx, *nz);
            let mut data = Vec::with_capacity(2 * v.len());
            for k in 0..nz {
                let row = &v[k * nx * channels..(k + 1) * nx * channels];
                data.extend_from_slice(row);
                data.extend_from_slice(row);
            }
            return Ok(FieldData {
                size: [nx as u32, 2, nz as u32],
                channels,
                data,
            });
        }
        [nz, nx] => [*nx as u32, *nz as u32, 1],
        _ => unreachable!("checked above"),
    };
    Ok(FieldData {
        size,
        channels,
        data: v,
    })
}
