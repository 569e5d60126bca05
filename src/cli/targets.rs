//! Everything `render` will write, checked against everything it reads and against each other
//! before the GPU starts: a refused run creates nothing, and a run that starts is not stopped
//! later by a file in the way.

use std::fs;
use std::path::{Path, PathBuf};

use texflow::output::same_file;
use texflow::scene::SceneFile;

use super::bad;

/// The files a render reads: the scene file (unless built in), its custom forces' GLSL and its
/// meshes, each with what it is, for messages.
pub fn inputs(label: &str, scene: &SceneFile, builtin: bool) -> Vec<(PathBuf, String)> {
    if builtin {
        return Vec::new();
    }
    let mut v = vec![(PathBuf::from(label), "the scene file".to_owned())];
    for c in &scene.forces.custom {
        v.push((PathBuf::from(&c.glsl), "a custom force's GLSL".into()));
    }
    for c in &scene.forces.pair {
        v.push((PathBuf::from(&c.glsl), "a pair force's GLSL".into()));
    }
    let folder = Path::new(label).parent().unwrap_or(Path::new(""));
    for s in &scene.colliders.sdf {
        if let Some(m) = &s.mesh {
            v.push((folder.join(m), "a distance field's mesh".into()));
        }
    }
    v
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
            for (input, what) in self.inputs {
                if same_file(v, input) {
                    return Err(bad(format!(
                        "--video {} is {what} ({}), which the run reads: give the video another \
                         name",
                        v.display(),
                        input.display()
                    )));
                }
            }
            for (dir, flag, writes) in self.folders() {
                if same_file(v, dir) {
                    return Err(bad(format!(
                        "--video {} is the folder {flag} {} writes into: give the video another \
                         name",
                        v.display(),
                        dir.display()
                    )));
                }
                let parent = match v.parent() {
                    Some(p) if !p.as_os_str().is_empty() => p,
                    _ => Path::new("."),
                };
                let name = v.file_name().map(|n| n.to_string_lossy().into_owned());
                if same_file(parent, dir) && name.as_deref().is_some_and(&writes) {
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
            let Ok(entries) = fs::read_dir(dir) else {
                continue;
            };
            for e in entries.flatten() {
                let name = e.file_name().to_string_lossy().into_owned();
                if !writes(&name) {
                    continue;
                }
                let path = e.path();
                // A link is replaced by the rename, never written through; what it points at
                // does not matter, unless it is an input.
                if let Some((_, what)) = self.inputs.iter().find(|(i, _)| same_file(&path, i)) {
                    return Err(bad(format!(
                        "{flag} {}: the run would replace {} ({what}, which it reads): choose \
                         another folder",
                        dir.display(),
                        path.display()
                    )));
                }
                let meta = fs::symlink_metadata(&path);
                if meta.is_ok_and(|m| !m.is_file() && !m.file_type().is_symlink()) {
                    return Err(bad(format!(
                        "{flag} {}: {} exists and is not a regular file (a folder, fifo, device \
                         or socket), and the run would write a file there: remove it or choose \
                         another folder",
                        dir.display(),
                        path.display()
                    )));
                }
            }
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
