//! One error type for the whole library, carried to the CLI and printed there once.

use std::path::PathBuf;

/// Everything that can go wrong in latvox.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The caller asked for something that cannot be done (bad option, infeasible target).
    #[error("{0}")]
    Invalid(String),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file was read but its contents are not what its format promises.
    #[error("{path}: {message}")]
    Format { path: PathBuf, message: String },
    /// OpenVDB or CGAL threw.
    #[error("{context}: {message}")]
    Backend {
        context: &'static str,
        message: String,
    },
}

impl Error {
    pub fn invalid(msg: impl Into<String>) -> Self {
        Error::Invalid(msg.into())
    }

    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }

    /// Process exit code for this error: 2 for bad input, 3 for a failure inside a backend.
    pub fn exit_code(&self) -> i32 {
        match self {
            Error::Invalid(_) | Error::Io { .. } | Error::Format { .. } => 2,
            Error::Backend { .. } => 3,
        }
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
