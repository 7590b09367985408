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
            Error::Invalid(_) | Error::Io { .. } | Error::Format { .. } | Error::Parse(_) => 2,
            Error::Backend { .. } => 3,
        }
    }
}

/// latvox's result: [`Error`] unless said otherwise.
pub type Result<T, E = Error> = std::result::Result<T, E>;
