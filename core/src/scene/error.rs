//! Errors and warnings of scene loading, each naming the file and, where it
//! applies, the line and the key, so that one line tells the user what to fix.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in the user's files a problem sits.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file, as the user named it or the scene file refers to it.
    pub file: PathBuf,
    /// 1-based line, when the problem has one.
    pub line: Option<usize>,
    /// The TOML key path (`materials.wall.kind`), when the problem has one.
    pub key: Option<String>,
}

impl Location {
    /// A whole file, with no line: one that cannot be read, say.
    pub fn file(file: &Path) -> Self {
        Self { file: file.to_path_buf(), line: None, key: None }
    }

    /// A line (1-based) of a file.
    pub fn line(file: &Path, line: usize) -> Self {
        Self { file: file.to_path_buf(), line: Some(line), key: None }
    }

    /// A key in a TOML file, located by the byte offset of its value.
    pub fn key(file: &Path, text: &str, offset: usize, key: impl Into<String>) -> Self {
        Self { file: file.to_path_buf(), line: Some(line_of(text, offset)), key: Some(key.into()) }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(key) = &self.key {
            write!(f, ": {key}")?;
        }
        Ok(())
    }
}

/// A scene that cannot be loaded. `Display` is one line: `file:line: key: message`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneError {
    /// Where the problem is.
    pub location: Location,
    /// What is wrong, in a few words.
    pub message: String,
}

impl SceneError {
    /// An error at `location`.
    pub fn new(location: Location, message: impl Into<String>) -> Self {
        Self { location, message: message.into() }
    }
}

impl fmt::Display for SceneError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.location, self.message)
    }
}

impl std::error::Error for SceneError {}

/// Something the user should know that does not stop the load (an unused
/// material, dropped degenerate triangles).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SceneWarning {
    /// Where it applies.
    pub location: Location,
    /// What the user should know, in a few words.
    pub message: String,
}

impl fmt::Display for SceneWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.location, self.message)
    }
}

/// 1-based line number of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end].iter().filter(|&&b| b == b'\n').count() + 1
}
