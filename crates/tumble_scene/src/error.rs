//! One error type for everything that can be wrong with a scene file.

use thiserror::Error;

/// A scene file that cannot be used, with where and why.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{}", location(self))]
pub struct SceneError {
    /// The file, made safe to print ([`crate::text::terminal_safe`]: a newline or ESC in the
    /// path is shown escaped).
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
            file: crate::text::terminal_safe(file).into_owned(),
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

/// `text` made safe to print on one line: control and format characters
/// ([`crate::text::is_unsafe_char`]: line breaks, ESC, bidi overrides, zero-width characters) are shown as
/// Rust escapes, through [`crate::text::terminal_safe_within`], and the text is cut to `max`
/// characters with an ellipsis. Messages quote user strings (keys, names, values), so this
/// applies to the whole message, not only to the parts known to come from the user.
fn one_line(text: String, max: usize) -> String {
    crate::text::terminal_safe_within(&text, max).into_owned()
}

/// A scene model that could not be written as TOML.
#[derive(Debug, Error)]
pub enum SaveError {
    /// The serializer refused the model.
    #[error("the scene cannot be written as TOML: {0}")]
    Serialize(#[from] toml::ser::Error),
    /// The text written does not read back as the same model: a value TOML cannot hold (its
    /// integers are 64-bit signed, so e.g. `steps` above 9223372036854775807), or a float
    /// that does not survive the round trip.
    #[error(
        "the scene cannot be written as TOML: the text would not read back as the same scene ({0})"
    )]
    NotReadable(String),
}
