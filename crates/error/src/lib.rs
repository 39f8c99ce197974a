//! One error type for everything a user can get wrong, with the context to fix it, plus the two
//! failures that are not the user's doing: the GPU's ([`Error::Gpu`]) and stereolab's own bugs
//! ([`Error::Internal`]).

#![warn(missing_docs)]

use std::borrow::Cow;
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
    /// The GPU path failed: no adapter or device, a shader rejected, a buffer that would not map,
    /// a readback that did not come back. Not about a value the user set.
    Gpu {
        /// What was being done or used, e.g. `readback`, `sirds_strip.wgsl`, the adapter's name.
        context: String,
        /// What went wrong, with the driver's own words where there are some.
        message: String,
    },
    /// A bug in stereolab: an invariant it keeps itself does not hold (e.g. a plan that did not
    /// run a pass its outputs need). Never the user's doing.
    Internal {
        /// Where, e.g. `plan` or `pipeline cache`.
        context: String,
        /// Which invariant broke.
        message: String,
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

    /// A GPU failure: `context` is what was being done (e.g. `readback`), `message` what failed.
    pub fn gpu(context: impl fmt::Display, message: impl Into<String>) -> Self {
        Error::Gpu {
            context: context.to_string(),
            message: message.into(),
        }
    }

    /// A bug in stereolab: `context` is where (e.g. `plan`), `message` the broken invariant.
    pub fn internal(context: impl fmt::Display, message: impl Into<String>) -> Self {
        Error::Internal {
            context: context.to_string(),
            message: message.into(),
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

/// `text` with every control character escaped as Rust writes it (`\u{1b}` for ESC, `\u{7}`
/// for BEL) except line breaks and tabs, so that nothing an input held (a file name, a field,
/// a value) reaches a terminal as a control sequence. C1 controls (U+0080–U+009F) are escaped
/// too: some terminals read U+009B as the start of a sequence.
pub fn printable(text: &str) -> Cow<'_, str> {
    if !text.chars().any(is_escaped) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if is_escaped(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

fn is_escaped(c: char) -> bool {
    c.is_control() && c != '\n' && c != '\t'
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = printable;
        match self {
            Error::Io { path, source } => write!(
                f,
                "{}: {}",
                p(&path.display().to_string()),
                p(&source.to_string())
            ),
            Error::Parse {
                path,
                line: Some(line),
                message,
            } => {
                write!(
                    f,
                    "{}:{line}: {}",
                    p(&path.display().to_string()),
                    p(message)
                )
            }
            Error::Parse {
                path,
                line: None,
                message,
            } => write!(f, "{}: {}", p(&path.display().to_string()), p(message)),
            Error::Invalid {
                field,
                value,
                reason,
            } => write!(f, "{} = {}: {}", p(field), p(value), p(reason)),
            Error::Gpu { context, message } => write!(
                f,
                "gpu {}: {} (the CPU renderer, --backend cpu, needs no GPU)",
                p(context),
                p(message)
            ),
            Error::Internal { context, message } => write!(
                f,
                "internal error in {}: {}; this is a bug in stereolab, not in \
                 your input: please report it with the command and scene that triggered it",
                p(context),
                p(message)
            ),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gpu_and_internal_name_their_context_and_remedy() {
        let g = Error::gpu("readback", "cannot map a buffer: lost").to_string();
        assert!(
            g.starts_with("gpu readback: cannot map a buffer: lost"),
            "{g}"
        );
        assert!(g.contains("--backend cpu"), "{g}");
        let i = Error::internal("plan", "the Left pass was not run").to_string();
        assert!(
            i.starts_with("internal error in plan: the Left pass was not run"),
            "{i}"
        );
        assert!(
            i.contains("bug in stereolab") && i.contains("report"),
            "{i}"
        );
    }

    #[test]
    fn control_characters_never_reach_the_terminal_raw() {
        let e = Error::invalid(
            "outputs\u{1b}[2J",
            "\"a\u{7}\u{9b}b\"",
            "unknown\u{0} output",
        );
        let shown = e.to_string();
        assert_eq!(
            shown,
            "outputs\\u{1b}[2J = \"a\\u{7}\\u{9b}b\": unknown\\u{0} output"
        );
        let e = Error::parse(
            Path::new("a\u{1b}.toml"),
            Some(2),
            "line one\nline two\tend",
        );
        assert_eq!(e.to_string(), "a\\u{1b}.toml:2: line one\nline two\tend");
        assert!(!shown.chars().any(|c| c.is_control()), "{shown}");
    }

    #[test]
    fn in_file_keeps_gpu_and_internal_as_they_are() {
        let p = Path::new("scene.toml");
        assert!(matches!(Error::gpu("a", "b").in_file(p), Error::Gpu { .. }));
        assert!(matches!(
            Error::internal("a", "b").in_file(p),
            Error::Internal { .. }
        ));
    }
}
