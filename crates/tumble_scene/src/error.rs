//! One error type for everything that can be wrong with a scene file.

use thiserror::Error;

/// A scene file that cannot be used, with where and why.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{file}:{line}: {field}: {message}")]
pub struct SceneError {
    /// The file.
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// The field (dotted path, e.g. `bodies[1].mass`).
    pub field: String,
    /// What is wrong and what was expected.
    pub message: String,
}

impl SceneError {
    /// An error at a line.
    pub fn at(
        file: &str,
        line: usize,
        field: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self {
            file: file.to_owned(),
            line,
            field: field.into(),
            message: message.into(),
        }
    }

    /// A file that could not be read.
    pub fn io(file: &str, e: std::io::Error) -> Self {
        Self::at(file, 0, "file", format!("cannot be read: {e}"))
    }
}
