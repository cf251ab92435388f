//! Scene files in JSON: the same schema as TOML, read as a stream.
//!
//! TOML parsers build the whole document before serde sees it (2.5 GB for a million bodies);
//! `serde_json` deserializes straight from a reader into the scene model, so a large scene costs
//! its model and nothing else. Errors name the file, the line and the field like TOML's:
//! `serde_path_to_error` tracks the field path during the parse, and the scanner in
//! [`crate::json_locate`] finds the line of a field that fails a later check.

use std::io::BufRead;

use serde::Deserialize;
use std::path::Path;

use crate::error::SceneError;
use crate::format::SceneFile;
use crate::json_locate::{Step, array_member_of_len, line_of, number_at};
use crate::json_strings::LimitedStrings;
use crate::validate::Locate;

/// Where the JSON text can be read again to locate a field: the scene is parsed once, as a
/// stream, and the text is scanned a second time only when an error must be located.
#[derive(Debug, Clone, Copy)]
pub(crate) enum JsonSource<'a> {
    /// Text in memory.
    Text(&'a [u8]),
    /// A file, opened again when needed.
    File(&'a Path),
}

impl JsonSource<'_> {
    /// The text again, from its start; `None` when the file cannot be opened again.
    fn open(&self) -> Option<Box<dyn BufRead + '_>> {
        match self {
            Self::Text(text) => Some(Box::new(*text)),
            Self::File(file) => std::fs::File::open(file)
                .ok()
                .map(|f| Box::new(std::io::BufReader::new(f)) as Box<dyn BufRead>),
        }
    }

    /// The line of `path`; 0 when the file cannot be opened again.
    fn line(&self, path: &[Step<'_>]) -> usize {
        self.open().map_or(0, |input| line_of(input, path))
    }
}

/// The path of `table[index].key` (`key` at the top level without a table).
fn field_path<'a>(table: Option<&'a str>, index: Option<usize>, key: &'a str) -> Vec<Step<'a>> {
    let mut path = Vec::with_capacity(3);
    path.extend(table.map(Step::Key));
    path.extend(index.map(Step::Index));
    path.push(Step::Key(key));
    path
}

impl Locate for JsonSource<'_> {
    fn line(&self, table: Option<&str>, index: Option<usize>, key: &str) -> usize {
        JsonSource::line(self, &field_path(table, index, key))
    }

    fn number_literal(
        &self,
        table: Option<&str>,
        index: Option<usize>,
        key: &str,
    ) -> Option<String> {
        number_at(self.open()?, &field_path(table, index, key))
    }
}

/// Parses the scene model from `input`; `file` names it in errors and `source` finds lines.
///
/// The parse tracks no field path: `serde_path_to_error` allocates every key it passes, which
/// tripled the time of a million-body load. A document that fails is parsed again from
/// `source` with the path tracked, to name the field.
pub(crate) fn parse(
    file: &str,
    mut input: impl BufRead,
    source: JsonSource<'_>,
) -> Result<SceneFile, SceneError> {
    skip_byte_order_mark(&mut input);
    let mut limited = LimitedStrings::new(input);
    let mut de = serde_json::Deserializer::from_reader(&mut limited);
    let model = SceneFile::deserialize(&mut de).and_then(|model| de.end().map(|()| model));
    model.map_err(|e| {
        if let Some(too_long) = limited.too_long() {
            // Not parsed again: the path tracking would read the same string.
            return SceneError::at(file, too_long.line, "json", too_long.to_string());
        }
        match source.open() {
            Some(again) => located(file, again, source).unwrap_or_else(|| unlocated(file, &e)),
            None => unlocated(file, &e),
        }
    })
}

/// Skips a UTF-8 byte order mark at the start of `input` (editors on Windows write one; JSON
/// parsers may ignore it, RFC 8259 §8.1).
fn skip_byte_order_mark(input: &mut impl BufRead) {
    const BOM: &[u8] = b"\xEF\xBB\xBF";
    if input.fill_buf().is_ok_and(|start| start.starts_with(BOM)) {
        input.consume(BOM.len());
    }
}

/// The error of a second parse, with its field path; `None` if the second parse passes (the
/// file changed in between).
fn located(file: &str, mut input: impl BufRead, source: JsonSource<'_>) -> Option<SceneError> {
    skip_byte_order_mark(&mut input);
    let mut de = serde_json::Deserializer::from_reader(input);
    let tracked = serde_path_to_error::deserialize::<_, SceneFile>(&mut de);
    let e = match tracked {
        Ok(_) => return de.end().err().map(|e| unlocated(file, &e)),
        Err(e) => e,
    };
    // `?` stands for a part of the path serde could not name (an unfinished document).
    let field = e
        .path()
        .to_string()
        .split('.')
        .filter(|part| !matches!(*part, "" | "?"))
        .collect::<Vec<_>>()
        .join(".");
    let inner = e.inner();
    let message = strip_position(&inner.to_string()).to_owned();
    // A field inside an internally tagged object (`forces`) is reported by serde_json at the
    // object's end, with the object's path: find the named key itself.
    let mut line = inner.line();
    let mut field = field;
    let steps = path_steps(&field);
    if let Some(name) = crate::validate::unknown_name(&message).filter(|_| !steps.is_empty()) {
        let mut with_key = steps.clone();
        with_key.push(Step::Key(name));
        line = source.line(&with_key).max(source.line(&steps));
    } else if let Some(len) = crate::validate::wrong_length(&message).filter(|_| !steps.is_empty())
        && let Some((key, at)) = source
            .open()
            .and_then(|input| array_member_of_len(input, &steps, len))
    {
        // Likewise a fixed-length array of the wrong length: the first member of that length.
        field = format!("{field}.{key}");
        line = at;
    }
    if field.is_empty() {
        field = "json".to_owned();
    }
    Some(SceneError::at(file, line, field, message))
}

/// serde_json's error at its line, the field unnamed.
fn unlocated(file: &str, e: &serde_json::Error) -> SceneError {
    SceneError::at(
        file,
        e.line(),
        "json",
        strip_position(&e.to_string()).to_owned(),
    )
}

/// serde_json's message without its " at line L column C" suffix (the line is reported apart).
fn strip_position(message: &str) -> &str {
    match message.rfind(" at line ") {
        Some(at) if message[at..].contains(" column ") => &message[..at],
        _ => message,
    }
}

/// The steps of a dotted path as `serde_path_to_error` writes it (`bodies[3].mass`).
fn path_steps(path: &str) -> Vec<Step<'_>> {
    let mut steps = Vec::new();
    for part in path.split('.') {
        let (key, indices) = part
            .split_once('[')
            .map_or((part, ""), |(k, rest)| (k, rest));
        if !key.is_empty() {
            steps.push(Step::Key(key));
        }
        for index in indices.split('[') {
            if let Some(i) = index.strip_suffix(']').and_then(|i| i.parse().ok()) {
                steps.push(Step::Index(i));
            }
        }
    }
    steps
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_become_steps() {
        assert_eq!(
            path_steps("bodies[3].mass"),
            [Step::Key("bodies"), Step::Index(3), Step::Key("mass")]
        );
        assert_eq!(
            path_steps("bodies[1].shape.convex_hull[2]"),
            [
                Step::Key("bodies"),
                Step::Index(1),
                Step::Key("shape"),
                Step::Key("convex_hull"),
                Step::Index(2)
            ]
        );
    }

    #[test]
    fn the_position_suffix_is_cut() {
        assert_eq!(
            strip_position("invalid type: string \"x\", expected f64 at line 3 column 9"),
            "invalid type: string \"x\", expected f64"
        );
        assert_eq!(strip_position("no position"), "no position");
    }
}
