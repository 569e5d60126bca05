//! Everything `render` will write, checked against everything it reads and against each other
//! before the GPU starts: a refused run creates nothing, and a run that starts is not stopped
//! later by a file in the way.

use std::fs;
use std::path::{Path, PathBuf};

use texflow::output::same_file;
use texflow::scene::SceneFile;

use super::bad;

/// The files a command reads, each with what it is (for messages): collected in one list when
/// the scene and the options are resolved, and checked against every output before anything is
/// written ([`check_file`], [`check_folder`]).
pub type Inputs = Vec<(PathBuf, String)>;

/// The files a scene reads: the scene file (unless built in), its custom and pair forces' GLSL,
/// its meshes and its field files (height maps, wind and distance fields), each with what it is.
/// `label` is the scene's path, or a built-in's name and ` (built-in)`, which reads no file.
pub fn inputs(label: &str, scene: &SceneFile) -> Inputs {
    if label.ends_with(" (built-in)") {
        return Vec::new();
    }
    let mut v = vec![(PathBuf::from(label), "the scene file".to_owned())];
    // Custom and pair forces' paths are made relative to the scene's folder when it is parsed.
    for c in &scene.forces.custom {
        v.push((PathBuf::from(&c.glsl), "a custom force's GLSL".into()));
    }
    for c in &scene.forces.pair {
        v.push((PathBuf::from(&c.glsl), "a pair force's GLSL".into()));
    }
    // Meshes and field files are read relative to the scene's folder.
    let folder = Path::new(label).parent().unwrap_or(Path::new(""));
    let mut relative = |name: &Option<String>, what: &str| {
        if let Some(n) = name {
            v.push((folder.join(n), what.to_owned()));
        }
    };
    for s in &scene.colliders.sdf {
        relative(&s.mesh, "a distance field's mesh");
        relative(&s.field, "a distance field's array, colliders.sdf.field");
    }
    for h in &scene.colliders.heightfield {
        relative(
            &h.image,
            "a height field's image, colliders.heightfield.image",
        );
        relative(&h.npy, "a height field's array, colliders.heightfield.npy");
    }
    for w in &scene.forces.wind {
        relative(&w.field, "a wind field's array, forces.wind.field");
    }
    v
}

/// The folder `path` is in (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Refuses an output file `path` (option `flag`) that is one of `inputs`, by path or by file
/// identity (a hard or symbolic link to an input).
pub fn check_file(path: &Path, flag: &str, inputs: &[(PathBuf, String)]) -> texflow::Result<()> {
    match inputs.iter().find(|(i, _)| same_file(path, i)) {
        Some((input, what)) => Err(bad(format!(
            "{flag} {} is {} ({what}), which the run reads: give the output another name",
            path.display(),
            input.display()
        ))),
        None => Ok(()),
    }
}

/// Refuses an output folder `dir` (option `flag`) that holds, under a name the command writes
/// there (`writes`), one of `inputs` (by path or file identity) or something that is not a
/// regular file or a link.
pub fn check_folder(
    dir: &Path,
    flag: &str,
    writes: &dyn Fn(&str) -> bool,
    inputs: &[(PathBuf, String)],
) -> texflow::Result<()> {
    for (input, what) in inputs {
        if same_file(dir, input) {
            return Err(bad(format!(
                "{flag} {} is {what}, which the run reads: choose another folder",
                dir.display()
            )));
        }
        // An input that does not exist yet cannot be listed below, but its name can be written.
        let name = input.file_name().map(|n| n.to_string_lossy().into_owned());
        if same_file(folder_of(input), dir) && name.as_deref().is_some_and(writes) {
            return Err(bad(format!(
                "{flag} {}: the run would replace {} ({what}, which it reads): choose another \
                 folder",
                dir.display(),
                input.display()
            )));
        }
    }
    let Ok(entries) = fs::read_dir(dir) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if !writes(&name) {
            continue;
        }
        let path = e.path();
        // A link is replaced by the rename, never written through; what it points at does not
        // matter, unless it is an input.
        if let Some((_, what)) = inputs.iter().find(|(i, _)| same_file(&path, i)) {
            return Err(bad(format!(
                "{flag} {}: the run would replace {} ({what}, which it reads): choose another \
                 folder",
                dir.display(),
                path.display()
            )));
        }
        let meta = fs::symlink_metadata(&path);
        if meta.is_ok_and(|m| !m.is_file() && !m.file_type().is_symlink()) {
            return Err(bad(format!(
                "{flag} {}: {} exists and is not a regular file (a folder, fifo, device or \
                 socket), and the run would write a file there: remove it or choose another folder",
                dir.display(),
                path.display()
            )));
        }
    }
    Ok(())
}

/// Whether `name` is a file `texflow trace` writes into its folder: `index.md`, `sort.gif`,
/// `NN_pass.png` (scene traces) or `pass_NNN.png` (sort traces).
pub fn trace_writes(name: &str) -> bool {
    let numbered = |n: &str| {
        let digits = n.chars().take_while(char::is_ascii_digit).count();
        digits > 0 && n[digits..].starts_with('_')
    };
    name == "index.md"
        || name == "sort.gif"
        || name
            .strip_suffix(".png")
            .is_some_and(|n| numbered(n) || n.starts_with("pass_"))
}

/// What a render writes.
pub struct Plan<'a> {
    /// Frames simulated.
    pub frames: u64,
    /// Every K-th frame is written.
    pub every: u64,
    /// Every K-th frame is dumped, with --dump-state.
    pub dump_every: u64,
    /// The frames' folder (--out), if frames are written.
    pub out: Option<&'a Path>,
    /// The dumps' folder (--dump-state).
    pub dumps: Option<&'a Path>,
    /// The animation (--video).
    pub video: Option<&'a Path>,
    /// What the run reads ([`inputs`]).
    pub inputs: &'a [(PathBuf, String)],
}

/// A folder written into: its path, the option that names it, and which names it gets.
type Folder<'a> = (&'a Path, &'static str, Box<dyn Fn(&str) -> bool + 'a>);

/// The index in a frame or dump name (`frame_00012.png` is frame 12 when `prefix` is `frame_`
/// and `ext` `.png`), if the name is exactly what the writer makes for it.
fn index_in(name: &str, prefix: &str, ext: &str) -> Option<u64> {
    let digits = name.strip_prefix(prefix)?.strip_suffix(ext)?;
    let i: u64 = digits.parse().ok()?;
    (format!("{i:05}") == digits).then_some(i)
}

impl Plan<'_> {
    /// Whether the run writes a file called `name` into the frames' folder.
    fn writes_frame(&self, name: &str) -> bool {
        index_in(name, "frame_", ".png").is_some_and(|i| i < self.frames && i % self.every == 0)
    }

    /// Whether the run writes a file called `name` into the dumps' folder.
    fn writes_dump(&self, name: &str) -> bool {
        texflow::engine::DUMP_NAMES.iter().any(|p| {
            index_in(name, &format!("{p}_"), ".npy")
                .is_some_and(|i| i < self.frames && i % self.dump_every == 0)
        })
    }

    /// The folders written into, with the option naming each and the names written there.
    fn folders(&self) -> Vec<Folder<'_>> {
        let mut v: Vec<Folder<'_>> = Vec::new();
        if let Some(o) = self.out {
            v.push((o, "--out", Box::new(|n| self.writes_frame(n))));
        }
        if let Some(d) = self.dumps {
            v.push((d, "--dump-state", Box::new(|n| self.writes_dump(n))));
        }
        v
    }

    /// Checks every output against every input and every other output, and every file the run
    /// will write into an existing folder.
    pub fn check(&self) -> texflow::Result<()> {
        if let Some(v) = self.video {
            check_file(v, "--video", self.inputs)?;
            for (dir, flag, writes) in self.folders() {
                if same_file(v, dir) {
                    return Err(bad(format!(
                        "--video {} is the folder {flag} {} writes into: give the video another \
                         name",
                        v.display(),
                        dir.display()
                    )));
                }
                let name = v.file_name().map(|n| n.to_string_lossy().into_owned());
                if same_file(folder_of(v), dir) && name.as_deref().is_some_and(&writes) {
                    return Err(bad(format!(
                        "--video {} is a file that {flag} {} will write: give the video another \
                         name or folder",
                        v.display(),
                        dir.display()
                    )));
                }
            }
        }
        for (dir, flag, writes) in self.folders() {
            check_folder(dir, flag, &writes, self.inputs)?;
        }
        Ok(())
    }

    /// Removes the temporary files a killed run left in the folders written into, for the
    /// names this command writes there (frames, dumps, the video), and nothing else.
    pub fn remove_stale(&self) -> usize {
        let frame = |n: &str| index_in(n, "frame_", ".png").is_some();
        let dump = |n: &str| {
            (texflow::engine::DUMP_NAMES.iter())
                .any(|p| index_in(n, &format!("{p}_"), ".npy").is_some())
        };
        let mut removed = 0;
        if let Some(o) = self.out {
            removed += texflow::output::remove_stale_temporaries(o, |n| frame(n) || dump(n));
        }
        if let Some(d) = self.dumps {
            removed += texflow::output::remove_stale_temporaries(d, dump);
        }
        if let Some(v) = self.video {
            let name = v.file_name().map(|n| n.to_string_lossy().into_owned());
            let parent = match v.parent() {
                Some(p) if !p.as_os_str().is_empty() => p,
                _ => Path::new("."),
            };
            removed +=
                texflow::output::remove_stale_temporaries(parent, |n| Some(n) == name.as_deref());
        }
        removed
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use texflow::output::temporary_of;

    #[test]
    fn trace_names_are_the_ones_a_trace_writes() {
        for n in [
            "index.md",
            "sort.gif",
            "01_position.png",
            "112_key.png",
            "pass_003.png",
        ] {
            assert!(trace_writes(n), "{n}");
        }
        for n in [
            "notes.md",
            "a_01.png",
            "01position.png",
            "01_position.npy",
            "sort.png",
        ] {
            assert!(!trace_writes(n), "{n}");
        }
    }

    #[test]
    fn names_are_matched_exactly() {
        assert_eq!(index_in("frame_00012.png", "frame_", ".png"), Some(12));
        assert_eq!(index_in("frame_123456.png", "frame_", ".png"), Some(123456));
        assert_eq!(index_in("frame_0012.png", "frame_", ".png"), None);
        assert_eq!(index_in("frame_000012.png", "frame_", ".png"), None);
        assert_eq!(
            temporary_of(".frame_00001.png.AbCd1234.tmp"),
            Some("frame_00001.png")
        );
        assert_eq!(
            temporary_of(".frame_00001.png.AbCd12.tmp"),
            Some("frame_00001.png")
        );
        assert_eq!(temporary_of(".frame_00001.png.AbCd123.tmp"), None);
        assert_eq!(temporary_of("frame_00001.png.AbCd1234.tmp"), None);
    }
}
