//! The built-in scenes' sources and meshes (the files in `examples/scenes/`, compiled into the
//! binary): data that loading by name (`builtin`) and reading meshes (`mesh`) both look up.

macro_rules! builtin_scenes {
    ($($name:literal),* $(,)?) => {
        /// The built-in scenes: name and TOML source.
        pub static BUILTIN_SOURCES: &[(&str, &str)] = &[$(
            ($name, include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/scenes/", $name, ".toml"))),
        )*];
        /// The names of the built-in scenes.
        pub const BUILTIN: &[&str] = &[$($name),*];
    };
}

builtin_scenes![
    "fire",
    "fire-points",
    "snow",
    "fountain",
    "smoke",
    "smoke-unlit",
    "e1",
    "e2",
    "e3",
    "collide",
    "gas",
    "mesh",
    "cloth",
    "hair",
    "spin",
    "fireworks",
    "dem",
    "flicker",
    "dam",
    "drop",
];

/// The meshes the built-in scenes name (`[[colliders.sdf]] mesh`), by the path they give
/// (relative to `examples/scenes/`), compiled into the binary.
pub static BUILTIN_MESHES: &[(&str, &[u8])] = &[(
    "meshes/blob.obj",
    include_bytes!(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/meshes/blob.obj"
    )),
)];

/// For the scene labelled `scene`: `None` if it is not a built-in (its meshes are files), else
/// the built-in mesh `name` if there is one.
pub(super) fn builtin_mesh(scene: &str, name: &str) -> Option<Option<&'static [u8]>> {
    let builtin = scene
        .strip_suffix(" (built-in)")
        .is_some_and(|n| builtin_source(n).is_some());
    builtin.then(|| {
        BUILTIN_MESHES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, b)| *b)
    })
}

/// The TOML source of a built-in scene.
pub fn builtin_source(name: &str) -> Option<&'static str> {
    BUILTIN_SOURCES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| *s)
}
