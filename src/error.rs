//! The library's error type.
//!
//! Every error a user can cause (a missing file, a RON syntax error, an unknown
//! field or name, a broken mesh, a bad size, a foreign or corrupt checkpoint) becomes an [`Error`] that names the
//! file and, where known, the line:column or the field path, and says what was
//! expected. Only `main` prints it; library code never panics on user input.

use std::fmt;
use std::path::{Path, PathBuf};

/// Errors returned by the library.
#[derive(Debug)]
pub enum Error {
    /// An I/O failure on a named file.
    Io {
        /// The file involved.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A scene file that does not parse or does not make sense.
    Scene {
        /// The scene file.
        path: PathBuf,
        /// `line:column` when the parser knows it, else empty.
        position: Option<(usize, usize)>,
        /// Field path (`objects[3].material`) when known, else empty.
        field: String,
        /// What is wrong and what was expected.
        message: String,
    },
    /// A mesh file that cannot be read.
    Mesh {
        /// The mesh file.
        path: PathBuf,
        /// What is wrong (with a line number when the format has lines).
        message: String,
    },
    /// An image that cannot be read or written.
    Image {
        /// The image file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A checkpoint that cannot be read, resumed or merged.
    Checkpoint {
        /// The checkpoint file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// Invalid settings (command line or scene), e.g. a zero width.
    Settings(String),
    /// One render setting out of range or unreadable; the caller says where
    /// it came from (`render.width` in a scene, `--width` on the command line).
    Setting {
        /// The setting's name (`width`).
        name: &'static str,
        /// What is wrong and what was expected.
        message: String,
    },
    /// Two things that must agree do not (films of different sizes, pass
    /// ranges that do not follow each other); the caller names the file.
    Mismatch(String),
}

impl Error {
    /// An I/O error on `path`.
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io { path: path.to_path_buf(), source }
    }

    /// A mesh error on `path`.
    pub fn mesh(path: &Path, message: impl Into<String>) -> Self {
        Error::Mesh { path: path.to_path_buf(), message: message.into() }
    }

    /// A checkpoint error on `path`.
    pub fn checkpoint(path: &Path, message: impl Into<String>) -> Self {
        Error::Checkpoint { path: path.to_path_buf(), message: message.into() }
    }

    /// A scene error at a field path, without a position.
    pub fn scene_field(path: &Path, field: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Scene { path: path.to_path_buf(), position: None, field: field.into(), message: message.into() }
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io { path, source } => write!(f, "{}: {}", show_path(path), source),
            Error::Scene { path, position, field, message } => {
                write!(f, "{}", show_path(path))?;
                if let Some((line, col)) = position {
                    write!(f, ":{line}:{col}")?;
                }
                if !field.is_empty() {
                    write!(f, ": {field}")?;
                }
                write!(f, ": {message}")
            }
            Error::Mesh { path, message } => write!(f, "mesh {}: {}", show_path(path), message),
            Error::Image { path, message } => write!(f, "image {}: {}", show_path(path), message),
            Error::Checkpoint { path, message } => write!(f, "checkpoint {}: {}", show_path(path), message),
            Error::Settings(message) | Error::Mismatch(message) => write!(f, "{message}"),
            Error::Setting { name, message } => write!(f, "{name}: {message}"),
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

/// A path as messages print it (see [`show_path`]).
#[derive(Clone, Copy, Debug)]
pub struct ShowPath<'a>(&'a Path);

/// A path for a message: as is when it is plain text, else quoted with its
/// control characters (a newline, a tab), quotes, backslashes and any bytes
/// that are not UTF-8 escaped, so that a message stays one line and shows
/// where the path ends. Every message that prints a path prints it this way.
pub fn show_path(path: &Path) -> ShowPath<'_> {
    ShowPath(path)
}

impl fmt::Display for ShowPath<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0.to_str() {
            Some(s) if !s.chars().any(char::is_control) => f.write_str(s),
            _ => write!(f, "{:?}", self.0),
        }
    }
}

/// The library's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
