//! Animations of a run's frames: GIF (image's gif encoder), APNG (the png crate's animation
//! chunks) or MP4/WebM (frames piped to an `ffmpeg` found on `PATH`), each written atomically.
//!
//! The encoder writes into a temporary file beside the target, registered like every other
//! unfinished file (a signal removes it); [`VideoWriter::finish`] renames it into place only when
//! the last frame is encoded, so an interrupted run leaves the old file or none.

use std::cell::RefCell;
use std::fs::File;
use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::rc::Rc;

use tempfile::NamedTempFile;

use crate::error::{Error, Result};

/// The kind of animation, chosen by the target's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VideoFormat {
    /// `.gif`: 256 colours a frame (exact when a frame has no more, NeuQuant otherwise).
    Gif,
    /// `.png` or `.apng`: animated PNG, lossless.
    Apng,
    /// `.mp4`: H.264 through ffmpeg.
    Mp4,
    /// `.webm`: VP9 through ffmpeg.
    Webm,
}

impl VideoFormat {
    /// The format `path`'s extension names; an error lists the ones understood.
    pub fn from_path(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ext.as_deref() {
            Some("gif") => Ok(VideoFormat::Gif),
            Some("png") | Some("apng") => Ok(VideoFormat::Apng),
            Some("mp4") => Ok(VideoFormat::Mp4),
            Some("webm") => Ok(VideoFormat::Webm),
            _ => Err(Error::InvalidInput(format!(
                "--video {}: unknown video format; name a .gif, .png (APNG), .mp4 or .webm file",
                path.display()
            ))),
        }
    }

    /// Whether the format needs an `ffmpeg` executable.
    pub fn needs_ffmpeg(self) -> bool {
        matches!(self, VideoFormat::Mp4 | VideoFormat::Webm)
    }
}

/// The first executable called `ffmpeg` on `PATH`, if any.
pub fn find_ffmpeg() -> Option<PathBuf> {
    use std::os::unix::fs::PermissionsExt;
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join("ffmpeg"))
        .find(|p| {
            std::fs::metadata(p)
                .map(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
                .unwrap_or(false)
        })
}

/// Checks, before anything runs, that `path` can take a video: a known extension, a writable
/// target ([`super::check_target`]) and, for MP4/WebM, an `ffmpeg` on `PATH`.
pub fn check_video(path: &Path) -> Result<VideoFormat> {
    let format = VideoFormat::from_path(path)?;
    super::check_target(path, "--video")?;
    if format.needs_ffmpeg() && find_ffmpeg().is_none() {
        return Err(Error::InvalidInput(format!(
            "--video {}: MP4 and WebM are encoded by ffmpeg, and no `ffmpeg` was found on PATH; \
             install ffmpeg, or write a .gif or .png (APNG) instead, which need nothing else",
            path.display()
        )));
    }
    Ok(format)
}

/// [`check_video`], and what the format can hold: an APNG counts its frames in 32 bits, a GIF
/// is at most 65535 pixels a side, and the rate must be a positive number. Everything
/// [`VideoWriter::create`] would refuse, refused before anything runs.
pub fn check_video_run(
    path: &Path,
    [w, h]: [u32; 2],
    frames: u64,
    fps: f64,
) -> Result<VideoFormat> {
    let format = check_video(path)?;
    if !(fps.is_finite() && fps > 0.0) {
        return Err(Error::InvalidInput(format!(
            "--fps {fps}: give a positive number of frames a second"
        )));
    }
    if format == VideoFormat::Gif && (w > u16::MAX as u32 || h > u16::MAX as u32) {
        return Err(Error::InvalidInput(format!(
            "--video {}: a GIF is at most 65535x65535 pixels, the frames are {w}x{h}",
            path.display()
        )));
    }
    if format == VideoFormat::Apng && frames > u32::MAX as u64 {
        return Err(Error::InvalidInput(format!(
            "--video {}: an APNG holds at most {} frames, the run writes {frames}: write fewer \
             frames (--frames, --every)",
            path.display(),
            u32::MAX
        )));
    }
    Ok(format)
}

/// The encoders running now, so that a signal can end them ([`kill_encoders`]).
static ENCODERS: std::sync::Mutex<Vec<std::sync::Weak<std::sync::Mutex<Child>>>> =
    std::sync::Mutex::new(Vec::new());

/// Kills every encoder process this process started and that still runs (for a signal: an
/// encoder that stopped reading, or never exits, would otherwise hold the run). Returns how many
/// were running.
pub fn kill_encoders() -> usize {
    let list = ENCODERS.lock().unwrap_or_else(|e| e.into_inner());
    let mut n = 0;
    for c in list.iter().filter_map(std::sync::Weak::upgrade) {
        let mut c = c.lock().unwrap_or_else(|e| e.into_inner());
        if matches!(c.try_wait(), Ok(None)) {
            let _ = c.kill();
            n += 1;
        }
    }
    n
}

/// Whether `head`, the first bytes of a finished file, looks like `format`'s container: an ISO
/// media file (`ftyp` box) for MP4, an EBML header for WebM.
fn looks_like(format: VideoFormat, head: &[u8]) -> bool {
    match format {
        VideoFormat::Mp4 => head.get(4..8) == Some(b"ftyp".as_slice()),
        VideoFormat::Webm => head.starts_with(&[0x1a, 0x45, 0xdf, 0xa3]),
        VideoFormat::Gif => head.starts_with(b"GIF8"),
        VideoFormat::Apng => head.starts_with(b"\x89PNG"),
    }
}

/// Bytes an encoder wrote and the writer has not yet moved to the file. The image and png
/// encoders own their writer until they are dropped or finished; this one is shared, so that the
/// bytes can be moved to disk after every frame and every write error is seen.
#[derive(Clone, Default)]
struct Shared(Rc<RefCell<Vec<u8>>>);

impl Write for Shared {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.borrow_mut().extend_from_slice(buf);
        Ok(buf.len())
    }
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

enum Encoder {
    Gif(Box<image::codecs::gif::GifEncoder<Shared>>, Shared),
    Apng(Box<png::Writer<Shared>>, Shared),
    Ffmpeg {
        /// Shared with [`ENCODERS`], so that a signal can kill it.
        child: std::sync::Arc<std::sync::Mutex<Child>>,
        stdin: Option<ChildStdin>,
        log: std::thread::JoinHandle<String>,
    },
}

/// An animation being written, frame after frame, to a temporary file beside its target.
pub struct VideoWriter {
    target: PathBuf,
    format: VideoFormat,
    size: [u32; 2],
    expected: u64,
    written: u64,
    /// GIF's delay between frames in milliseconds (the encoder keeps hundredths of a second).
    delay_ms: u32,
    temp: Option<NamedTempFile>,
    encoder: Option<Encoder>,
}

impl std::fmt::Debug for VideoWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("VideoWriter")
            .field("target", &self.target)
            .field("format", &self.format)
            .field("size", &self.size)
            .field("written", &self.written)
            .finish()
    }
}

fn encoding(path: &Path) -> impl Fn(String) -> Error + '_ {
    move |reason| Error::Image {
        path: path.to_owned(),
        reason,
    }
}

/// The frame rate as the ratio `num/den` seconds of one frame, both in `u16` (APNG's fcTL).
fn delay_ratio(fps: f64) -> (u16, u16) {
    let den = (fps * 100.0).round().clamp(1.0, u16::MAX as f64) as u16;
    (100, den)
}

impl VideoWriter {
    /// Starts a `width`×`height` animation of exactly `frames` frames at `fps` frames a second
    /// (GIF keeps delays in hundredths of a second, so it plays at the nearest such delay).
    pub fn create(path: &Path, size: [u32; 2], frames: u64, fps: f64) -> Result<Self> {
        let format = check_video_run(path, size, frames, fps)?;
        let [w, h] = size;
        let temp = super::temporary_beside(path)?;
        let err = encoding(path);
        let encoder = match format {
            VideoFormat::Gif => {
                let shared = Shared::default();
                let mut gif = image::codecs::gif::GifEncoder::new_with_speed(shared.clone(), 10);
                gif.set_repeat(image::codecs::gif::Repeat::Infinite)
                    .map_err(|e| err(e.to_string()))?;
                Encoder::Gif(Box::new(gif), shared)
            }
            VideoFormat::Apng => {
                let shared = Shared::default();
                let mut enc = png::Encoder::new(shared.clone(), w, h);
                enc.set_color(png::ColorType::Rgb);
                enc.set_depth(png::BitDepth::Eight);
                let count = u32::try_from(frames.max(1)).map_err(|_| {
                    Error::InvalidInput(format!("{frames} frames are too many for an APNG"))
                })?;
                enc.set_animated(count, 0).map_err(|e| err(e.to_string()))?;
                let (num, den) = delay_ratio(fps);
                enc.set_frame_delay(num, den)
                    .map_err(|e| err(e.to_string()))?;
                let writer = enc.write_header().map_err(|e| err(e.to_string()))?;
                Encoder::Apng(Box::new(writer), shared)
            }
            VideoFormat::Mp4 | VideoFormat::Webm => {
                spawn_ffmpeg(path, temp.path(), format, size, fps)?
            }
        };
        Ok(VideoWriter {
            target: path.to_owned(),
            format,
            size,
            expected: frames,
            written: 0,
            delay_ms: (1000.0 / fps).round().max(10.0) as u32,
            temp: Some(temp),
            encoder: Some(encoder),
        })
    }

    /// The format being written.
    pub fn format(&self) -> VideoFormat {
        self.format
    }

    /// Frames encoded so far.
    pub fn written(&self) -> u64 {
        self.written
    }

    fn file(&mut self) -> &mut File {
        self.temp
            .as_mut()
            .expect("an unfinished video holds its temporary file")
            .as_file_mut()
    }

    fn drain(&mut self, shared: &Shared) -> Result<()> {
        let bytes = std::mem::take(&mut *shared.0.borrow_mut());
        let target = self.target.clone();
        self.file().write_all(&bytes).map_err(|source| Error::Io {
            path: target,
            source,
        })
    }

    /// Encodes the next frame; it must have the size given to [`create`](Self::create).
    pub fn push(&mut self, image: &image::RgbImage) -> Result<()> {
        let [w, h] = self.size;
        if image.dimensions() != (w, h) {
            return Err(Error::InvalidInput(format!(
                "video frame of {}x{} in a {w}x{h} video",
                image.width(),
                image.height()
            )));
        }
        let path = self.target.clone();
        let err = encoding(&path);
        let mut encoder = self.encoder.take().expect("an unfinished video");
        let result = match &mut encoder {
            Encoder::Gif(gif, shared) => {
                let rgba = image::DynamicImage::ImageRgb8(image.clone()).into_rgba8();
                let frame = image::Frame::from_parts(
                    rgba,
                    0,
                    0,
                    image::Delay::from_numer_denom_ms(self.delay_ms, 1),
                );
                let shared = shared.clone();
                gif.encode_frame(frame)
                    .map_err(|e| err(e.to_string()))
                    .and_then(|()| self.drain(&shared))
            }
            Encoder::Apng(writer, shared) => {
                let shared = shared.clone();
                writer
                    .write_image_data(image.as_raw())
                    .map_err(|e| err(e.to_string()))
                    .and_then(|()| self.drain(&shared))
            }
            // A write to an ffmpeg that has exited would raise SIGPIPE (the CLI keeps its default
            // action); an ffmpeg that stopped early is reported instead.
            Encoder::Ffmpeg { child, stdin, .. } => {
                let exited = matches!(lock(child).try_wait(), Ok(Some(_)));
                if exited {
                    Err(err("ffmpeg exited before every frame was written".into()))
                } else {
                    stdin
                        .as_mut()
                        .expect("ffmpeg's input is open until finish")
                        .write_all(image.as_raw())
                        .map_err(|e| err(format!("writing a frame to ffmpeg: {e}")))
                }
            }
        };
        self.encoder = Some(encoder);
        result?;
        self.written += 1;
        Ok(())
    }

    /// Encodes the end of the animation and renames it over the target. Fails, leaving the
    /// target as it was, if fewer or more frames came than [`create`](Self::create) was told.
    pub fn finish(mut self) -> Result<PathBuf> {
        if self.written != self.expected {
            return Err(Error::InvalidInput(format!(
                "--video {}: {} frame(s) were encoded, {} expected",
                self.target.display(),
                self.written,
                self.expected
            )));
        }
        let path = self.target.clone();
        let err = encoding(&path);
        match self.encoder.take().expect("an unfinished video") {
            Encoder::Gif(gif, shared) => {
                // image's GIF encoder writes the trailer when it is dropped.
                drop(gif);
                self.drain(&shared)?;
            }
            Encoder::Apng(writer, shared) => {
                writer.finish().map_err(|e| err(e.to_string()))?;
                self.drain(&shared)?;
            }
            Encoder::Ffmpeg { child, stdin, log } => {
                drop(stdin);
                // Polled, not waited for under the lock, so that a signal can kill it meanwhile.
                let status = loop {
                    match lock(&child).try_wait() {
                        Ok(Some(status)) => break status,
                        Ok(None) => std::thread::sleep(std::time::Duration::from_millis(5)),
                        Err(e) => return Err(err(format!("waiting for ffmpeg: {e}"))),
                    }
                };
                let log = log.join().unwrap_or_default();
                if !status.success() {
                    return Err(err(format!(
                        "ffmpeg failed ({status}): {}",
                        log.trim().lines().last().unwrap_or("no message")
                    )));
                }
            }
        }
        let temp = self.temp.take().expect("an unfinished video");
        temp.as_file().sync_all().map_err(|source| Error::Io {
            path: path.clone(),
            source,
        })?;
        // Written only if the encoder wrote something that is the container asked for (an
        // encoder that exits 0 without writing leaves an empty file).
        let mut head = [0u8; 16];
        let read = File::open(temp.path())
            .and_then(|mut f| f.read(&mut head))
            .map_err(|source| Error::Io {
                path: path.clone(),
                source,
            })?;
        if !looks_like(self.format, &head[..read]) {
            let p = temp.path().to_owned();
            drop(temp);
            super::forget(&p);
            return Err(err(format!(
                "the encoder wrote {}: not a {:?} file; nothing was written (is the `ffmpeg` on \
                 PATH a working ffmpeg?)",
                if read == 0 {
                    "nothing".to_owned()
                } else {
                    "something else".to_owned()
                },
                self.format
            )));
        }
        super::Staged {
            target: path.clone(),
            temp: Some(temp),
        }
        .persist()
    }
}

impl Drop for VideoWriter {
    fn drop(&mut self) {
        if let Some(Encoder::Ffmpeg { child, stdin, .. }) = self.encoder.take() {
            drop(stdin);
            let mut child = lock(&child);
            let _ = child.kill();
            let _ = child.wait();
        }
        if let Some(t) = self.temp.take() {
            let p = t.path().to_owned();
            drop(t);
            super::forget(&p);
        }
    }
}

fn lock(c: &std::sync::Mutex<Child>) -> std::sync::MutexGuard<'_, Child> {
    c.lock().unwrap_or_else(|e| e.into_inner())
}

/// Starts ffmpeg reading raw RGB frames on its standard input and writing `temp`.
fn spawn_ffmpeg(
    target: &Path,
    temp: &Path,
    format: VideoFormat,
    [w, h]: [u32; 2],
    fps: f64,
) -> Result<Encoder> {
    let (muxer, codec): (&str, &[&str]) = match format {
        VideoFormat::Mp4 => (
            "mp4",
            &["-c:v", "libx264", "-preset", "medium", "-crf", "18"],
        ),
        VideoFormat::Webm => ("webm", &["-c:v", "libvpx-vp9", "-b:v", "0", "-crf", "31"]),
        // `Video::create` encodes these itself and never comes here.
        VideoFormat::Gif | VideoFormat::Apng => {
            unreachable!("gif and apng are encoded without ffmpeg (Video::create)")
        }
    };
    let ffmpeg = find_ffmpeg().ok_or_else(|| {
        Error::InvalidInput("no `ffmpeg` on PATH: write a .gif or .png (APNG) instead".into())
    })?;
    let mut child = Command::new(&ffmpeg)
        .args(["-hide_banner", "-loglevel", "error", "-y"])
        .args(["-f", "rawvideo", "-pix_fmt", "rgb24"])
        .args([
            "-s",
            &format!("{w}x{h}"),
            "-r",
            &format!("{fps}"),
            "-i",
            "-",
        ])
        // 4:2:0 chroma needs even sides: pad by one black row or column where needed.
        .args([
            "-vf",
            "pad=ceil(iw/2)*2:ceil(ih/2)*2",
            "-pix_fmt",
            "yuv420p",
        ])
        .args(codec)
        .args(["-f", muxer])
        .arg(temp)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| Error::Image {
            path: target.to_owned(),
            reason: format!("starting {}: {e}", ffmpeg.display()),
        })?;
    let stdin = child.stdin.take();
    let child = std::sync::Arc::new(std::sync::Mutex::new(child));
    {
        let mut list = ENCODERS.lock().unwrap_or_else(|e| e.into_inner());
        list.retain(|w| w.strong_count() > 0);
        list.push(std::sync::Arc::downgrade(&child));
    }
    let mut stderr = lock(&child).stderr.take().expect("piped");
    // Read ffmpeg's messages while frames are written, so that a full pipe never blocks it.
    let log = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = stderr.read_to_string(&mut s);
        s
    });
    Ok(Encoder::Ffmpeg { child, stdin, log })
}
