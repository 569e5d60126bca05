//! Files written so that nothing is lost, half-written or overwritten by mistake.
//!
//! - Every file goes first to a temporary file in its own folder, created exclusively with an
//!   unpredictable name (never through a planted link), and is renamed over the target only when
//!   it is complete: an interrupted run leaves either the old file or the new one.
//! - A target that exists must be a regular file (or a link to one, which the rename replaces):
//!   a folder, a device such as `/dev/full`, a pipe or a socket is refused before anything runs.
//! - [`Outputs`] gathers all the files of one command: their paths must not clash with each other
//!   or with the command's inputs, and they are renamed into place together, only after every one
//!   has been written.
//! - Temporary files that exist right now are listed in a process-wide registry, so that a signal
//!   handler can remove them ([`remove_unfinished`]) before the process exits.

pub mod diff;
mod frames;
pub mod video;

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use tempfile::NamedTempFile;

pub use frames::{write_png_atomic, FrameWriter};
pub use video::{VideoFormat, VideoWriter};

use crate::error::{Error, Result};

/// Temporary files created and not yet renamed or removed.
static UNFINISHED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn registry() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    // A panic while the lock was held leaves the list as it was: still usable.
    UNFINISHED.lock().unwrap_or_else(|e| e.into_inner())
}

fn forget(path: &Path) {
    registry().retain(|p| p != path);
}

/// Removes every temporary file that is still unfinished (for signal handlers). Returns how many
/// were removed.
pub fn remove_unfinished() -> usize {
    let paths = std::mem::take(&mut *registry());
    paths.iter().filter(|p| fs::remove_file(p).is_ok()).count()
}

/// Removes every unfinished temporary file and then runs `exit` (which ends the process) while
/// still holding the registry, so that no other thread can create a new temporary file between
/// the clean-up and the end.
pub fn abandon(exit: impl FnOnce() -> std::convert::Infallible) -> std::convert::Infallible {
    let mut held = registry();
    for p in held.drain(..) {
        let _ = fs::remove_file(p);
    }
    // `exit` does not return: the registry stays locked until the process ends.
    match exit() {}
}

/// The temporary files unfinished right now (for tests).
pub fn unfinished() -> Vec<PathBuf> {
    registry().clone()
}

fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Error + '_ {
    move |source| Error::Io {
        path: path.to_owned(),
        source,
    }
}

/// Checks that `dir` can be written, by creating (and removing) an exclusive temporary file.
pub fn probe_writable(dir: &Path) -> std::io::Result<()> {
    tempfile::Builder::new()
        .prefix(".texflow-write-test-")
        .tempfile_in(dir)
        .map(drop)
}

/// Refuses a target that exists and is not a regular file, or whose folder is missing or cannot
/// be written; `flag` names the option in the message.
pub fn check_target(path: &Path, flag: &str) -> Result<()> {
    let bad = |m: String| Err(Error::InvalidInput(m));
    let shown = path.display();
    if path.as_os_str().is_empty() {
        return bad(format!("{flag} is empty: name a file"));
    }
    // `v.gif/` names a folder: the rename at the end would fail, after the run.
    if path.as_os_str().as_encoded_bytes().ends_with(b"/") {
        return bad(format!(
            "{flag} {shown} ends in `/`, which names a folder: name a file (drop the `/`)"
        ));
    }
    match fs::metadata(path) {
        Ok(m) if m.is_dir() => return bad(format!("{flag} {shown} is a folder: name a file")),
        Ok(m) if !m.is_file() => {
            return bad(format!(
                "{flag} {shown} exists and is not a regular file (a device, pipe or socket): \
                 name a new or regular file"
            ))
        }
        _ => {}
    }
    let dir = folder_of(path);
    if !dir.is_dir() {
        let why = match fs::metadata(dir) {
            Ok(_) => "is a file, not a folder",
            Err(_) if fs::symlink_metadata(dir).is_ok() => "is a link to a missing path",
            Err(_) => "does not exist",
        };
        return bad(format!("{flag} {shown}: {} {why}", dir.display()));
    }
    probe_writable(dir).or_else(|e| {
        bad(format!(
            "{flag} {shown}: cannot write in {} ({e})",
            dir.display()
        ))
    })
}

/// A temporary file beside `path`, registered as unfinished before it exists.
fn temporary_beside(path: &Path) -> Result<NamedTempFile> {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let dir = folder_of(path);
    tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".tmp")
        .rand_bytes(8)
        .make_in(dir, |p| {
            registry().push(p.to_owned());
            let f = fs::OpenOptions::new().write(true).create_new(true).open(p);
            if f.is_err() {
                forget(p);
            }
            f
        })
        .map_err(io(path))
}

/// A file being written: its bytes go to a temporary file until [`persist`](Self::persist).
/// Dropped without persisting, the temporary file is removed.
#[derive(Debug)]
pub struct Staged {
    target: PathBuf,
    temp: Option<NamedTempFile>,
}

impl Staged {
    /// Writes `bytes` to a new temporary file beside `target`, and flushes it to disk.
    pub fn new(target: &Path, bytes: &[u8]) -> Result<Self> {
        let mut temp = temporary_beside(target)?;
        let written = temp
            .as_file_mut()
            .write_all(bytes)
            .and_then(|_| temp.as_file().sync_all());
        // Owned before the error is returned, so that dropping it removes the temporary file.
        let staged = Staged {
            target: target.to_owned(),
            temp: Some(temp),
        };
        written.map_err(io(target))?;
        Ok(staged)
    }

    /// Renames the temporary file over the target.
    pub fn persist(mut self) -> Result<PathBuf> {
        let temp = self
            .temp
            .take()
            .expect("a staged file holds its temporary file");
        let temp_path = temp.path().to_owned();
        let result = temp.persist(&self.target);
        forget(&temp_path);
        result.map_err(|e| Error::Io {
            path: self.target.clone(),
            source: e.error,
        })?;
        Ok(self.target.clone())
    }
}

impl Drop for Staged {
    fn drop(&mut self) {
        if let Some(t) = self.temp.take() {
            let p = t.path().to_owned();
            drop(t);
            forget(&p);
        }
    }
}

/// Writes `bytes` to `path` atomically: the target is checked ([`check_target`]), then written
/// through a temporary file and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    if let Ok(m) = fs::metadata(path) {
        if !m.is_file() {
            return Err(Error::InvalidInput(format!(
                "{} exists and is not a regular file: refusing to replace it",
                path.display()
            )));
        }
    }
    Staged::new(path, bytes)?.persist().map(drop)
}

/// Identity of a path for clash checks: the canonical folder and the file name, and the file's
/// device and inode where it exists (so that two names of one file clash too).
fn identity(path: &Path) -> (Option<PathBuf>, Option<(u64, u64)>) {
    use std::os::unix::fs::MetadataExt;
    let dir = fs::canonicalize(folder_of(path)).ok();
    let full = dir.zip(path.file_name()).map(|(d, n)| d.join(n));
    let inode = fs::metadata(path).ok().map(|m| (m.dev(), m.ino()));
    (full, inode)
}

/// Whether `a` and `b` name the same file or folder: the same canonical folder and name (so
/// `dir/./x`, `dir/x/` and a linked folder count), or the same device and inode where both
/// exist (a hard link, a link to the file).
pub fn same_file(a: &Path, b: &Path) -> bool {
    let (pa, ia) = identity(a);
    let (pb, ib) = identity(b);
    (pa.is_some() && pa == pb) || (ia.is_some() && ia == ib)
}

/// Whether `file` is a temporary file that texflow's writer left for a target named `name`:
/// `.NAME.XXXXXXXX.tmp` (eight letters or digits; six in earlier versions).
pub fn temporary_of(file: &str) -> Option<&str> {
    let rest = file.strip_prefix('.')?.strip_suffix(".tmp")?;
    let (name, random) = rest.rsplit_once('.')?;
    let ours = matches!(random.len(), 6 | 8) && random.bytes().all(|b| b.is_ascii_alphanumeric());
    (ours && !name.is_empty()).then_some(name)
}

/// Removes the temporary files in `dir` that a killed run of texflow left for targets whose
/// name `ours` accepts (see [`temporary_of`]), except the ones this process is writing; returns
/// how many were removed. Nothing else is touched.
pub fn remove_stale_temporaries(dir: &Path, ours: impl Fn(&str) -> bool) -> usize {
    let Ok(entries) = fs::read_dir(dir) else {
        return 0;
    };
    // By name: the registry may hold the absolute path of a file `dir` names relatively.
    let live: Vec<std::ffi::OsString> = unfinished()
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_owned()))
        .collect();
    let mut removed = 0;
    for e in entries.flatten() {
        let name = e.file_name();
        let Some(target) = name.to_str().and_then(temporary_of) else {
            continue;
        };
        let path = e.path();
        let regular = e.file_type().is_ok_and(|t| t.is_file());
        if regular && ours(target) && !live.contains(&name) && fs::remove_file(&path).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// All the files one command writes, checked up front and renamed into place together.
#[derive(Debug, Default)]
pub struct Outputs {
    targets: Vec<(PathBuf, String)>,
    inputs: Vec<(PathBuf, String)>,
    staged: Vec<Option<Staged>>,
}

impl Outputs {
    /// No outputs yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Declares a file the command reads, so that no output may replace it.
    pub fn input(&mut self, path: &Path, flag: &str) {
        self.inputs.push((path.to_owned(), flag.to_owned()));
    }

    /// Declares an output given by option `flag`: checked now ([`check_target`]) and against the
    /// outputs and inputs declared before it. Returns its index for [`stage`](Self::stage).
    pub fn file(&mut self, path: &Path, flag: &str) -> Result<usize> {
        check_target(path, flag)?;
        let (me, my_inode) = identity(path);
        for (other, other_flag) in self.targets.iter().chain(&self.inputs) {
            let (them, their_inode) = identity(other);
            let same =
                (me.is_some() && me == them) || (my_inode.is_some() && my_inode == their_inode);
            if same {
                let role = if self.inputs.iter().any(|(p, _)| p == other) {
                    "the input"
                } else {
                    "another output"
                };
                return Err(Error::InvalidInput(format!(
                    "{flag} {} is the same file as {other_flag} {} ({role}): give each output \
                     its own path",
                    path.display(),
                    other.display()
                )));
            }
        }
        self.targets.push((path.to_owned(), flag.to_owned()));
        self.staged.push(None);
        Ok(self.targets.len() - 1)
    }

    /// Writes output `index`'s bytes to its temporary file.
    pub fn stage(&mut self, index: usize, bytes: &[u8]) -> Result<()> {
        let (path, _) = &self.targets[index];
        self.staged[index] = Some(Staged::new(path, bytes)?);
        Ok(())
    }

    /// Renames every staged file into place; fails, renaming nothing, if one was not staged.
    pub fn commit(mut self) -> Result<Vec<PathBuf>> {
        if let Some(i) = self.staged.iter().position(Option::is_none) {
            return Err(Error::InvalidInput(format!(
                "{} {} was never written",
                self.targets[i].1,
                self.targets[i].0.display()
            )));
        }
        let done: Vec<PathBuf> = self
            .staged
            .drain(..)
            .map(|s| s.expect("checked above").persist())
            .collect::<Result<_>>()?;
        // What a killed run left for these targets goes now.
        for p in &done {
            let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
            remove_stale_temporaries(folder_of(p), |t| Some(t) == name.as_deref());
        }
        Ok(done)
    }
}
