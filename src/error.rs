//! One error type for everything a user can get wrong, with the context to fix it.

use std::fmt;
use std::path::{Path, PathBuf};

/// Every failure stereolab reports: which input, where in it, which value, and why.
#[derive(Debug)]
pub enum Error {
    /// A file could not be read or written.
    Io {
        /// The file.
        path: PathBuf,
        /// What the operating system said.
        source: std::io::Error,
    },
    /// A file was read but its content is wrong.
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line, when known.
        line: Option<usize>,
        /// What is wrong, naming the value.
        message: String,
    },
    /// A parameter (scene field, CLI option, function argument) has a value we refuse.
    Invalid {
        /// Dotted name of the field, e.g. `camera.near`.
        field: String,
        /// The offending value as the user wrote it.
        value: String,
        /// Why it is refused and what would be accepted.
        reason: String,
    },
}

/// Shorthand used across the crate.
pub type Result<T> = std::result::Result<T, Error>;

impl Error {
    /// An invalid parameter.
    pub fn invalid(
        field: impl Into<String>,
        value: impl fmt::Display,
        reason: impl Into<String>,
    ) -> Self {
        Error::Invalid {
            field: field.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }

    /// A parse error in a file.
    pub fn parse(path: &Path, line: Option<usize>, message: impl Into<String>) -> Self {
        Error::Parse {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    /// An I/O error on a file.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// Adds a file name to an `Invalid` error (e.g. a scene field), keeping other kinds as they are.
    pub fn in_file(self, path: &Path) -> Self {
        match self {
            Error::Invalid {
                field,
                value,
                reason,
            } => Error::Parse {
                path: path.to_path_buf(),
                line: None,
                message: format!("{field} = {value}: {reason}"),
            },
            other => other,
        }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Error::Parse {
                path,
                line: Some(line),
                message,
            } => {
                write!(f, "{}:{line}: {message}", path.display())
            }
            Error::Parse {
                path,
                line: None,
                message,
            } => write!(f, "{}: {message}", path.display()),
            Error::Invalid {
                field,
                value,
                reason,
            } => write!(f, "{field} = {value}: {reason}"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
