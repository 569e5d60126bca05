//! The one error type of the crate.
//!
//! Each variant carries the driver's or the parser's own words, so that the CLI can turn it into a
//! one-paragraph message that names the problem and the fix.

use std::path::PathBuf;

/// Why a framebuffer is not complete (the `glCheckFramebufferStatus` answers, one variant each).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Incomplete {
    /// An attachment is missing its storage or has a zero size.
    Attachment,
    /// No image is attached at all.
    MissingAttachment,
    /// A draw buffer names an attachment point with nothing attached.
    DrawBuffer,
    /// The read buffer names an attachment point with nothing attached.
    ReadBuffer,
    /// The driver cannot render to this combination of formats (for example no float colour buffers).
    Unsupported,
    /// Attachments disagree in their number of samples.
    Multisample,
    /// Layered and non-layered attachments are mixed.
    LayerTargets,
    /// A status this crate does not know.
    Other(u32),
}

impl std::fmt::Display for Incomplete {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let s = match self {
            Incomplete::Attachment => "an attachment has no storage or a zero size",
            Incomplete::MissingAttachment => "no image is attached",
            Incomplete::DrawBuffer => "a draw buffer names an empty attachment point",
            Incomplete::ReadBuffer => "the read buffer names an empty attachment point",
            Incomplete::Unsupported => {
                "the driver cannot render to this format combination (float colour buffers?)"
            }
            Incomplete::Multisample => "attachments differ in sample count",
            Incomplete::LayerTargets => "layered and non-layered attachments are mixed",
            Incomplete::Other(code) => return write!(f, "unknown status 0x{code:04x}"),
        };
        f.write_str(s)
    }
}

/// Every way texflow can fail.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// EGL could not be loaded or offers no device.
    #[error("no EGL device: {reason}. Install an EGL driver: on Debian/Ubuntu `apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri` (Mesa's llvmpipe runs on any CPU); on an NVIDIA machine, the NVIDIA driver's EGL library")]
    NoEglDevice {
        /// What EGL said.
        reason: String,
    },
    /// `--device N` names a device that does not exist.
    #[error("EGL device {index} does not exist: this machine has {count} device(s); run `texflow info` to list them and pick one with --device")]
    DeviceIndex {
        /// The index asked for.
        index: usize,
        /// How many devices there are.
        count: usize,
    },
    /// The display, config or context could not be created on the chosen device.
    #[error("could not create an OpenGL 3.3 core context on EGL device {device}: {reason}")]
    Context {
        /// The device index.
        device: usize,
        /// What EGL or glutin said.
        reason: String,
    },
    /// The context lacks something texflow needs.
    #[error("the GL context lacks {what}: {detail}")]
    MissingCapability {
        /// The capability.
        what: String,
        /// What was found instead.
        detail: String,
    },
    /// A shader failed to compile; `file` and `line` point into `glsl/`.
    #[error("shader compile error in glsl/{file}:{line}:\n{log}")]
    ShaderCompile {
        /// The GLSL file (relative to `glsl/`) where the driver reported the first error.
        file: String,
        /// The line in that file.
        line: u32,
        /// The driver's log, with source numbers turned into file names.
        log: String,
    },
    /// A program failed to link.
    #[error("program {name} failed to link:\n{log}")]
    ProgramLink {
        /// The program's name (its shader files).
        name: String,
        /// The driver's log.
        log: String,
    },
    /// A GLSL file or include is not among the embedded sources.
    #[error("GLSL source `{0}` is not embedded in the binary (see src/gl/source.rs)")]
    MissingSource(String),
    /// A framebuffer is incomplete.
    #[error("framebuffer `{label}` is incomplete: {reason}")]
    FramebufferIncomplete {
        /// The framebuffer's label.
        label: String,
        /// The status.
        reason: Incomplete,
    },
    /// A scene file is malformed or meaningless; `line` and `column` count from 1.
    #[error("{path}:{line}:{column}: {message}")]
    Scene {
        /// The scene file (or the built-in scene's name).
        path: String,
        /// Line of the offending text.
        line: usize,
        /// Column of the offending text.
        column: usize,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A size or limit was exceeded, or a value is out of range.
    #[error("{0}")]
    InvalidInput(String),
    /// A GL call failed at run time.
    #[error("GL error: {0}")]
    Gl(String),
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A run produced NaN or infinite particle state (see `LoopOptions::non_finite`).
    #[error("frame {frame}: {count} of {live} live particles have NaN or infinite values{origin}; the scene is unstable at these settings (try a smaller --dt or more --substeps), or pass --allow-non-finite to write the frames anyway")]
    NonFinite {
        /// Where the values came from, when the state tells (`; all are particles of
        /// emitters.timestamp.0 ...`), else empty.
        origin: String,
        /// The first written frame that had any.
        frame: u64,
        /// Live particles with a NaN or infinite component.
        count: u64,
        /// Live particles.
        live: u64,
    },
    /// The run was stopped by a signal (SIGINT or SIGTERM) between frames; what was written so
    /// far is complete, nothing unfinished was left.
    #[error("interrupted by signal {signal}: stopped between frames; every file written is complete and unfinished ones were removed")]
    Interrupted {
        /// The signal number.
        signal: i32,
    },
    /// A run's state differs from a saved reference beyond the tolerance (`render --compare`).
    #[error("{0}")]
    Mismatch(String),
    /// Encoding an image failed.
    #[error("could not encode {path}: {reason}")]
    Image {
        /// The file.
        path: PathBuf,
        /// The encoder's words.
        reason: String,
    },
}

impl Error {
    /// Whether the error is the user's input (exit code 2) rather than the machine's.
    pub fn is_bad_input(&self) -> bool {
        matches!(
            self,
            Error::InvalidInput(_)
                | Error::DeviceIndex { .. }
                | Error::Io { .. }
                | Error::Scene { .. }
        )
    }
}

impl Error {
    /// The CLI's exit code for this error (docs/reliability.md): 2 for bad input, 3 for a run
    /// whose state turned NaN or infinite, 4 for a
    /// state that differs from its reference (`render --compare`), 128 + the signal for an
    /// interrupted run, 1 otherwise.
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::NonFinite { .. } => 3,
            Error::Mismatch(_) => 4,
            Error::Interrupted { signal } => (128 + signal).clamp(0, 255) as u8,
            e if e.is_bad_input() => 2,
            _ => 1,
        }
    }
}

/// Shorthand for results of this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
