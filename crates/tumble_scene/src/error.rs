//! One error type for everything that can be wrong with a scene file.

use thiserror::Error;

/// A scene file that cannot be used, with where and why.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{}", location(self))]
pub struct SceneError {
    /// The file.
    pub file: String,
    /// 1-based line; 0 when the error concerns the whole file (it could not be read).
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
            field: one_line(field.into(), MAX_FIELD_CHARS),
            message: one_line(message.into(), MAX_MESSAGE_CHARS),
        }
    }

    /// A file that could not be read.
    pub fn io(file: &str, e: std::io::Error) -> Self {
        Self::at(file, 0, "file", format!("cannot be read: {e}"))
    }
}

/// `file:line: field: message`, or `file: field: message` for a whole-file error.
fn location(e: &SceneError) -> String {
    match e.line {
        0 => format!("{}: {}: {}", e.file, e.field, e.message),
        line => format!("{}:{line}: {}: {}", e.file, e.field, e.message),
    }
}

/// Longest field path kept in an error (a 10 MB key would otherwise be echoed whole).
const MAX_FIELD_CHARS: usize = 120;
/// Longest message kept in an error.
const MAX_MESSAGE_CHARS: usize = 400;

/// `text` on one line (line breaks become spaces), cut to `max` characters with an ellipsis.
fn one_line(text: String, max: usize) -> String {
    let mut out: String = text
        .chars()
        .take(max)
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    if text.chars().nth(max).is_some() {
        out.push('…');
    }
    out
}
