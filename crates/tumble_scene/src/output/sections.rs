//! Generated sections of a hand-written Markdown file (the report's headline in the README, a
//! bench run's summary in a page of the user's): the file's text with what stands between each
//! section's markers replaced.

use std::path::Path;

use super::OutputError;
use crate::text::{markers_repeated, replace_between_markers};

/// The text of the Markdown file at `path` with, for each `(name, section)`, what stands between
/// `<!-- {name}:begin -->` and `<!-- {name}:end -->` replaced by `section`. Reads the file; writes
/// nothing (the caller writes the result with the rest of its outputs, all or none).
pub fn with_sections(path: &Path, sections: &[(&str, &str)]) -> Result<String, OutputError> {
    let mut text = std::fs::read_to_string(path).map_err(|e| OutputError::io(path, e))?;
    for &(name, section) in sections {
        if markers_repeated(&text, name) {
            return Err(OutputError::RepeatedMarkers {
                path: path.to_owned(),
                name: name.to_owned(),
            });
        }
        text = replace_between_markers(&text, name, section).ok_or_else(|| {
            OutputError::MissingMarkers {
                path: path.to_owned(),
                name: name.to_owned(),
            }
        })?;
    }
    Ok(text)
}
