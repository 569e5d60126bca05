//! Files texflow reads: regular files only, bounded in size before a byte is read.
//!
//! A fifo would block the reader until a writer comes, and `/dev/zero` or `/dev/urandom` never
//! end: every input (scene files, custom GLSL, OBJ meshes, `.npy` arrays) is looked at first
//! (following links), refused unless it is a regular file no larger than its bound, and then read
//! with the bound enforced again on the open file (it may have changed in between).

use std::fs::{self, File};
use std::io::Read;
use std::path::Path;

use crate::error::{Error, Result};

/// Largest scene file (TOML): far more than any scene needs.
pub const MAX_SCENE_BYTES: u64 = 1 << 20;
/// Largest custom-force GLSL file.
pub const MAX_GLSL_BYTES: u64 = 256 << 10;
/// Largest OBJ mesh file (a mesh holds at most 1024 triangles; comments and unused vertices
/// are allowed around them).
pub const MAX_MESH_BYTES: u64 = 16 << 20;
/// Largest `.npy` file: 2^24 keys (what `texflow sort` takes) of 8 bytes, with room to spare.
pub const MAX_NPY_BYTES: u64 = 256 << 20;

/// Why an input was refused, without the file's name (callers add it with their own wording).
#[derive(Debug)]
pub enum Refused {
    /// A folder, fifo, device or socket.
    NotRegular(&'static str),
    /// Larger than the bound.
    TooLarge {
        /// The file's size in bytes.
        size: u64,
        /// The bound.
        max: u64,
    },
    /// Missing, unreadable, or a read error.
    Io(std::io::Error),
}

impl std::fmt::Display for Refused {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Refused::NotRegular(kind) => write!(
                f,
                "it is {kind}, not a regular file (inputs are read whole, so only regular files \
                 are taken)"
            ),
            Refused::TooLarge { size, max } => write!(
                f,
                "it is {size} bytes, over the limit of {max} bytes for this kind of file"
            ),
            Refused::Io(e) => write!(f, "{e}"),
        }
    }
}

fn kind(m: &fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = m.file_type();
    if t.is_dir() {
        "a folder"
    } else if t.is_fifo() {
        "a fifo (named pipe)"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else if t.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

fn check(m: &fs::Metadata, max: u64) -> std::result::Result<(), Refused> {
    if !m.is_file() {
        return Err(Refused::NotRegular(kind(m)));
    }
    if m.len() > max {
        return Err(Refused::TooLarge { size: m.len(), max });
    }
    Ok(())
}

/// Reads `path` whole if it is a regular file (after following links) of at most `max` bytes.
pub fn read_bounded(path: &Path, max: u64) -> std::result::Result<Vec<u8>, Refused> {
    // Looked at before opening: opening a fifo for reading blocks until a writer comes.
    check(&fs::metadata(path).map_err(Refused::Io)?, max)?;
    let file = File::open(path).map_err(Refused::Io)?;
    // And again on the open file, which is the one read.
    check(&file.metadata().map_err(Refused::Io)?, max)?;
    let mut bytes = Vec::new();
    file.take(max + 1)
        .read_to_end(&mut bytes)
        .map_err(Refused::Io)?;
    if bytes.len() as u64 > max {
        return Err(Refused::TooLarge {
            size: bytes.len() as u64,
            max,
        });
    }
    Ok(bytes)
}

/// [`read_bounded`], with an input error that names the file as `what path: reason`.
pub fn read_input(path: &Path, what: &str, max: u64) -> Result<Vec<u8>> {
    read_bounded(path, max)
        .map_err(|r| Error::InvalidInput(format!("{what} {}: {r}", path.display())))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_bounded_regular_files_are_read() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("a.txt");
        fs::write(&f, b"hello").unwrap();
        assert_eq!(read_bounded(&f, 5).unwrap(), b"hello");
        assert!(matches!(
            read_bounded(&f, 4),
            Err(Refused::TooLarge { size: 5, max: 4 })
        ));
        assert!(matches!(
            read_bounded(dir.path(), 100),
            Err(Refused::NotRegular("a folder"))
        ));
        // /dev/zero never ends: refused before a byte is read.
        assert!(matches!(
            read_bounded(Path::new("/dev/zero"), 100),
            Err(Refused::NotRegular("a device"))
        ));
        let e = read_input(&dir.path().join("none"), "scene file", 10).unwrap_err();
        assert!(
            e.to_string().contains("scene file") && e.exit_code() == 2,
            "{e}"
        );
    }
}
