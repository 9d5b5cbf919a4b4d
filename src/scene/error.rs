//! Errors reported by the scene loaders.

use std::fmt;

/// What kind of problem stopped a scene from loading.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadErrorKind {
    /// A file could not be read (missing, unreadable).
    Io,
    /// The bytes are not a glTF file (empty, truncated, bad magic, invalid JSON).
    Format,
    /// The file is glTF but its content is invalid (bad index, out-of-bounds data, NaN...).
    Invalid,
    /// The file needs something Tesela does not support (a required extension, a URI scheme...).
    Unsupported,
    /// A URI tried to reach outside the scene's folder.
    Refused,
    /// The scene exceeds the loader's size limits.
    TooLarge,
}

/// A scene that failed to load. `Display` gives `file: problem`.
#[derive(Clone, Debug)]
pub struct LoadError {
    /// The file the problem was found in (the name given to the loader).
    pub file: String,
    pub kind: LoadErrorKind,
    /// The problem, with the JSON path or accessor index when relevant.
    pub message: String,
}

impl LoadError {
    pub fn new(kind: LoadErrorKind, message: impl Into<String>) -> Self {
        LoadError {
            file: String::new(),
            kind,
            message: message.into(),
        }
    }

    /// Sets the file name (used by the loaders once the problem reaches the top).
    pub fn in_file(mut self, file: &str) -> Self {
        if self.file.is_empty() {
            self.file = file.to_string();
        }
        self
    }
}

impl fmt::Display for LoadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.file.is_empty() {
            write!(f, "{}", self.message)
        } else {
            write!(f, "{}: {}", self.file, self.message)
        }
    }
}

impl std::error::Error for LoadError {}
