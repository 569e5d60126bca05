//! Folders of numbered PNG frames, each written atomically.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::error::{Error, Result};

/// Encodes `img` as PNG into `path` atomically ([`super::write_atomic`]).
pub fn write_png_atomic(path: &Path, img: &image::RgbImage) -> Result<()> {
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image_rgb(img)
        .map_err(|e| Error::Image {
            path: path.to_owned(),
            reason: e.to_string(),
        })?;
    super::write_atomic(path, &bytes)
}

trait WriteRgb {
    fn write_image_rgb(self, img: &image::RgbImage) -> image::ImageResult<()>;
}

impl<W: Write> WriteRgb for image::codecs::png::PngEncoder<W> {
    fn write_image_rgb(self, img: &image::RgbImage) -> image::ImageResult<()> {
        use image::ImageEncoder;
        self.write_image(
            img.as_raw(),
            img.width(),
            img.height(),
            image::ExtendedColorType::Rgb8,
        )
    }
}

/// A folder of numbered frames `frame_00000.png`, ...
#[derive(Debug, Clone)]
pub struct FrameWriter {
    dir: PathBuf,
}

impl FrameWriter {
    /// Checks, without creating anything, that `dir` can become a folder of frames: it is a
    /// folder or does not exist yet, and its nearest existing ancestor is a writable folder.
    pub fn check(dir: &Path) -> Result<()> {
        Self::check_for(dir, "--out")
    }

    /// [`check`](Self::check), naming the option `flag` in its messages.
    pub fn check_for(dir: &Path, flag: &str) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidInput(m));
        if !dir.exists() && fs::symlink_metadata(dir).is_ok() {
            return bad(format!(
                "{flag} {} is a link to a missing path: remove it or name another folder",
                dir.display()
            ));
        }
        if dir.exists() && !dir.is_dir() {
            return bad(format!(
                "{flag} {} exists and is not a folder: pass a folder to {flag}",
                dir.display()
            ));
        }
        let mut probe = dir.to_path_buf();
        while !probe.exists() {
            match probe.parent() {
                Some(p) if !p.as_os_str().is_empty() => probe = p.to_path_buf(),
                _ => {
                    probe = PathBuf::from(".");
                    break;
                }
            }
        }
        if !probe.is_dir() {
            return bad(format!(
                "{flag} {}: the folder cannot be created, {} is a file: name a folder",
                dir.display(),
                probe.display()
            ));
        }
        // Write permission is best checked by writing.
        match super::probe_writable(&probe) {
            Ok(()) => Ok(()),
            Err(e) => bad(format!(
                "output folder {} cannot be written ({}: {e}): choose another {flag}",
                dir.display(),
                probe.display()
            )),
        }
    }

    /// Creates the folder (and its parents) if needed.
    pub fn create(dir: &Path) -> Result<Self> {
        Self::create_for(dir, "--out")
    }

    /// [`create`](Self::create), naming the option `flag` in its messages.
    pub fn create_for(dir: &Path, flag: &str) -> Result<Self> {
        Self::check_for(dir, flag)?;
        fs::create_dir_all(dir).map_err(|source| Error::Io {
            path: dir.to_owned(),
            source,
        })?;
        Ok(FrameWriter {
            dir: dir.to_owned(),
        })
    }

    /// The folder written to.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The path of frame `index`.
    pub fn path(&self, index: u64) -> PathBuf {
        self.dir.join(format!("frame_{index:05}.png"))
    }

    /// Writes frame `index` atomically and returns its path.
    pub fn write(&self, index: u64, img: &image::RgbImage) -> Result<PathBuf> {
        let path = self.path(index);
        write_png_atomic(&path, img)?;
        Ok(path)
    }
}
