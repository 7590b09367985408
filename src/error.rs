//! One error type for the whole library, carried to the CLI and printed there once.
//!
//! Each kind a caller may act on is its own variant with its data: a setting out of its range
//! ([`Error::Setting`]), a target the part cannot reach with the range that it can
//! ([`Error::Infeasible`]), voxels too coarse with the resolution that works
//! ([`Error::Resolution`]), a file's contents ([`Error::Format`], [`Error::Parse`]), the operating
//! system ([`Error::Io`]) and OpenVDB or CGAL ([`Error::Backend`]). Every variant displays as
//! one line, the one the command line prints.

use std::path::PathBuf;

/// Everything that can go wrong in latvox.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The caller asked for something that cannot be done.
    #[error("{0}")]
    Invalid(String),
    /// A setting (an option of a job) has a value it cannot take.
    #[error("{message}")]
    Setting {
        /// The setting, as its command-line option is named (`density`, `cell-size`).
        setting: String,
        /// The whole message.
        message: String,
    },
    /// A target the part cannot meet: the setting asked, and the range in which it can.
    #[error("{message}")]
    Infeasible {
        /// The setting (`density`, `radius`).
        setting: String,
        /// The value asked for.
        value: f64,
        /// The least value that can be met.
        min: f64,
        /// The greatest value that can be met.
        max: f64,
        /// The whole message.
        message: String,
    },
    /// The voxels are too coarse for the part: the resolution (voxels per cell) asked for, and
    /// the smallest that works where one was found.
    #[error("{message}")]
    Resolution {
        /// Voxels per cell asked for.
        requested: u32,
        /// The smallest resolution that works, when one was found.
        needed: Option<u32>,
        /// The whole message.
        message: String,
    },
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        #[source]
        source: std::io::Error,
    },
    /// A file was read but its contents are not what its format promises.
    #[error("{path}: {message}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong with its contents.
        message: String,
    },
    /// Bytes (or text) given to a parser are not what their format promises; the parser does not
    /// know the file they came from ([`Error::in_file`] names it).
    #[error("{0}")]
    Parse(String),
    /// OpenVDB or CGAL threw.
    #[error("{context}: {message}")]
    Backend {
        /// The operation that failed.
        context: &'static str,
        /// The exception's message.
        message: String,
    },
}

impl Error {
    /// A request that cannot be done (exit code 2).
    pub fn invalid(msg: impl Into<String>) -> Self {
        Error::Invalid(msg.into())
    }

    /// A setting that cannot take the value given.
    pub fn setting(setting: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Setting {
            setting: setting.into(),
            message: message.into(),
        }
    }

    /// The same error with `prefix` in front of its message (a part file's name, a job's place),
    /// its kind and data kept: a request's errors ([`Error::Invalid`], [`Error::Setting`],
    /// [`Error::Infeasible`], [`Error::Resolution`]); others name their file already.
    pub fn prefixed(self, prefix: &str) -> Self {
        let with = |m: String| {
            if m.starts_with(prefix) {
                m
            } else {
                format!("{prefix}: {m}")
            }
        };
        match self {
            Error::Invalid(m) => Error::Invalid(with(m)),
            Error::Setting { setting, message } => Error::Setting {
                setting,
                message: with(message),
            },
            Error::Infeasible {
                setting,
                value,
                min,
                max,
                message,
            } => Error::Infeasible {
                setting,
                value,
                min,
                max,
                message: with(message),
            },
            Error::Resolution {
                requested,
                needed,
                message,
            } => Error::Resolution {
                requested,
                needed,
                message: with(message),
            },
            e => e,
        }
    }

    /// What a parser found wrong with its input.
    pub fn parse(msg: impl Into<String>) -> Self {
        Error::Parse(msg.into())
    }

    /// A parse error as found in the file `path` (a [`Error::Format`] naming it); other errors
    /// unchanged.
    pub fn in_file(self, path: impl Into<PathBuf>) -> Self {
        match self {
            Error::Parse(message) => Error::Format {
                path: path.into(),
                message,
            },
            e => e,
        }
    }

    /// A file that could not be read or written.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// Process exit code for this error: 2 for bad input, 3 for a failure inside a backend.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Invalid(_)
            | Error::Setting { .. }
            | Error::Infeasible { .. }
            | Error::Resolution { .. }
            | Error::Io { .. }
            | Error::Format { .. }
            | Error::Parse(_) => 2,
            Error::Backend { .. } => 3,
        }
    }
}

/// latvox's result: [`Error`] unless said otherwise.
pub type Result<T, E = Error> = std::result::Result<T, E>;
