//! The walk of the fetch floor: what the floor of a draw that walked the cells around every
//! live particle (`glsl/collide/cells.glsl`) repeats of it, from its recorded shape.

use crate::gl::{Context, Defines, DrawShape, RecordedTexture, Uniform};

/// The samplers of the neighbour search a walking draw bound, which the floor binds to the
/// same textures (the table only with `CELL_TABLE`).
const WALK_SAMPLERS: [&str; 3] = ["u_keys", "u_position", "u_cell_start"];

/// The search's integer uniforms, which the floor sets to the draw's values.
const WALK_INTS: [&str; 3] = ["u_key_width", "u_count", "u_dims"];

/// The trimmed search's float uniforms (`SEARCH_TRIM`), which the floor sets to the draw's values.
const WALK_FLOATS: [&str; 3] = ["u_cell_origin", "u_cell_size", "u_search_radius"];

/// The defines the search reads (`glsl/collide/cells.glsl`, `sorted_keys.glsl`).
const WALK_DEFINES: [&str; 7] = [
    "CELL_TABLE",
    "EXACT_SCAN",
    "KEY_WIDTH_SHIFT",
    "PACKED_KEYS",
    "SEARCH_TRIM",
    "TABLE_WIDTH_SHIFT",
    "WALK_TILES",
];

/// What the floor of a draw that walked the cells repeats: the search's textures (by the
/// samplers' names), defines and uniforms (the integer ones and a trimmed search's
/// float geometry).
pub(super) struct Walk {
    pub(super) textures: Vec<(&'static str, RecordedTexture)>,
    pub(super) defines: Defines,
    pub(super) uniforms: Vec<(&'static str, Uniform)>,
}

/// The indices of `d`'s reads that the floor fetches once at the fragment's texel: all, but
/// for a walk the search's own textures, which the walk reads where the pass does.
pub(super) fn generic_reads(d: &DrawShape, walk: Option<&Walk>) -> Vec<usize> {
    (0..d.reads.len())
        .filter(|&i| {
            walk.is_none()
                || !(d.samplers.get(i)).is_some_and(|n| WALK_SAMPLERS.contains(&n.as_str()))
        })
        .collect()
}

/// The walk of draw `d`, where it walked the cells and the textures it searched still live.
pub(super) fn walk_of(ctx: &Context, d: &DrawShape) -> Option<Walk> {
    if !d.walks() {
        return None;
    }
    // Every sampler the search reads, or no walk (a pass that names its layout otherwise).
    let table = d.defines.iter().any(|(k, _)| k == "CELL_TABLE");
    let mut textures = Vec::new();
    for name in WALK_SAMPLERS {
        if name == "u_cell_start" && !table {
            continue;
        }
        let i = d.samplers.iter().position(|s| s == name)?;
        let t = d.sources.get(i).filter(|t| ctx.is_live(t))?;
        textures.push((name, *t));
    }
    let mut defines: Defines = (d.defines.iter())
        .filter(|(k, _)| WALK_DEFINES.contains(&k.as_str()))
        .cloned()
        .collect();
    defines.push(("WALK".into(), "1".into()));
    let ints = (WALK_INTS.iter())
        .filter_map(|&name| {
            let (_, v) = d.ints.iter().find(|(n, _)| n == name)?;
            Some((
                name,
                match v.as_slice() {
                    [x] => Uniform::I32(*x),
                    [x, y, z] => Uniform::IVec3(glam::IVec3::new(*x, *y, *z)),
                    _ => return None,
                },
            ))
        })
        .collect::<Vec<_>>();
    let floats = (WALK_FLOATS.iter()).filter_map(|&name| {
        let (_, v) = d.floats.iter().find(|(n, _)| n == name)?;
        Some((
            name,
            match v.as_slice() {
                [x] => Uniform::F32(*x),
                [x, y, z] => Uniform::Vec3(glam::Vec3::new(*x, *y, *z)),
                _ => return None,
            },
        ))
    });
    Some(Walk {
        textures,
        defines,
        uniforms: ints.into_iter().chain(floats).collect(),
    })
}
