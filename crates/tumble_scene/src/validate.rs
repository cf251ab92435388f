//! Semantic checks of a parsed scene file, with the line of each offending field (TOML here;
//! JSON in [`crate::json`]).

use toml::de::{DeTable, DeValue};
use tumble_core::error::compact;
use tumble_core::math::{REAL_NAME, Real, Vec3};

use crate::error::SceneError;

/// The 1-based line holding byte offset `at` of `text`.
pub(crate) fn line_at(text: &str, at: usize) -> usize {
    let at = at.min(text.len());
    1 + text.as_bytes()[..at]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
}

/// The 1-based line of the longest dotted key (a header `[a.b.c]` or a key `a.b.c = …`): where
/// a reader's error without a position ("recursion limit", a key path nested too deep) arose.
/// Dots inside quoted key parts and everything after `=` or `#` are not counted.
pub(crate) fn line_of_longest_key(text: &str) -> usize {
    let mut deepest = (0, 1);
    for (i, line) in text.lines().enumerate() {
        let mut dots = 0;
        let mut quote = None;
        for c in line.chars() {
            match (quote, c) {
                (None, '"' | '\'') => quote = Some(c),
                (Some(q), _) if c == q => quote = None,
                (None, '=' | '#') => break,
                (None, '.') => dots += 1,
                _ => {}
            }
        }
        if dots > deepest.0 {
            deepest = (dots, i + 1);
        }
    }
    deepest.1
}

/// Finds the line of `key` inside `table` (the `index`-th element when `table` is an array of
/// tables), from the spans of the parsed document, so that headers with comments, inline tables,
/// dotted and quoted keys and multi-line strings are all located correctly. Falls back to the
/// table (or element), then to line 1.
pub(crate) fn line_of(text: &str, table: &str, index: Option<usize>, key: &str) -> usize {
    let Ok(doc) = DeTable::parse(text) else {
        return 1;
    };
    let Some(entry) = doc.get_ref().get(table) else {
        return 1;
    };
    let scope = match (index, entry.get_ref()) {
        (Some(i), DeValue::Array(items)) => items.get(i).unwrap_or(entry),
        _ => entry,
    };
    if let DeValue::Table(fields) = scope.get_ref()
        && let Some((k, _)) = fields.get_key_value(key)
    {
        return line_at(text, k.span().start);
    }
    line_at(text, scope.span().start)
}

/// The text of the number at `table[index].key` (`key` at the top level without a table), as
/// written; `None` when it is not a number or not there.
pub(crate) fn number_literal_of(
    text: &str,
    table: Option<&str>,
    index: Option<usize>,
    key: &str,
) -> Option<String> {
    let doc = DeTable::parse(text).ok()?;
    let scope = match table {
        Some(table) => {
            let entry = doc.get_ref().get(table)?;
            match (index, entry.get_ref()) {
                (Some(i), DeValue::Array(items)) => items.get(i)?.get_ref(),
                (None, value) => value,
                _ => return None,
            }
        }
        None => return number_text(doc.get_ref().get(key)?.get_ref()),
    };
    match scope {
        DeValue::Table(fields) => number_text(fields.get(key)?.get_ref()),
        _ => None,
    }
}

fn number_text(value: &DeValue<'_>) -> Option<String> {
    match value {
        DeValue::Float(f) => Some(f.as_str().to_owned()),
        DeValue::Integer(i) => Some(i.as_str().to_owned()),
        _ => None,
    }
}

/// Whether the number written as `literal` is not zero but reads as 0 in `f64` (`1e-400`):
/// a reader rounds it to 0 without a word, and a check of the 0 must say why it saw 0.
pub(crate) fn underflows_f64(literal: &str) -> bool {
    let digits: String = literal.chars().filter(|&c| c != '_').collect();
    let mantissa = digits.split(['e', 'E']).next().unwrap_or("");
    digits.parse::<f64>().is_ok_and(|x| x == 0.0)
        && mantissa.contains(|c: char| matches!(c, '1'..='9'))
}

/// The dotted path (e.g. `bodies[1].mass`) of the deepest key or value whose span holds byte
/// offset `at`, or `None` when the text does not parse or no key is there.
pub(crate) fn path_at(text: &str, at: usize) -> Option<String> {
    let doc = DeTable::parse(text).ok()?;
    let mut path = String::new();
    table_path(doc.get_ref(), at, &mut path).then_some(path)
}

fn table_path(table: &DeTable<'_>, at: usize, path: &mut String) -> bool {
    for (k, v) in table.iter() {
        let len = path.len();
        if !path.is_empty() {
            path.push('.');
        }
        path.push_str(k.get_ref());
        if value_path(v.get_ref(), at, path) || k.span().contains(&at) || v.span().contains(&at) {
            return true;
        }
        path.truncate(len);
    }
    false
}

fn value_path(value: &DeValue<'_>, at: usize, path: &mut String) -> bool {
    match value {
        DeValue::Table(t) => table_path(t, at, path),
        DeValue::Array(items) => items.iter().enumerate().any(|(i, item)| {
            let len = path.len();
            path.push_str(&format!("[{i}]"));
            if value_path(item.get_ref(), at, path) || item.span().contains(&at) {
                return true;
            }
            path.truncate(len);
            false
        }),
        _ => false,
    }
}

/// The start of the first array of `len` elements (not an array of tables) that begins at or
/// after byte `from`. An array of the wrong length inside an internally tagged table
/// (`[[forces]]`) is reported by toml at the table's header, because serde buffers tagged
/// tables; the offending array is the first one of that length in the table, hence the first
/// after the header.
pub(crate) fn array_of_len_after(text: &str, from: usize, len: usize) -> Option<usize> {
    fn search(
        value: &toml::Spanned<DeValue<'_>>,
        from: usize,
        len: usize,
        best: &mut Option<usize>,
    ) {
        match value.get_ref() {
            DeValue::Table(t) => t.iter().for_each(|(_, v)| search(v, from, len, best)),
            DeValue::Array(items) => {
                let start = value.span().start;
                let is_table_array = items
                    .iter()
                    .all(|v| matches!(v.get_ref(), DeValue::Table(_)));
                if start >= from && items.len() == len && !(is_table_array && len > 0) {
                    *best = Some(best.map_or(start, |b| b.min(start)));
                }
                items.iter().for_each(|v| search(v, from, len, best));
            }
            _ => {}
        }
    }
    let doc = DeTable::parse(text).ok()?;
    let mut best = None;
    doc.get_ref()
        .iter()
        .for_each(|(_, v)| search(v, from, len, &mut best));
    best
}

/// The start of the first key named `name` at or after byte `from`. toml reports an unknown
/// key inside an internally tagged table (`[[forces]]`, also under a deeply nested header such
/// as `[forces.x.y.z]`) at the table's header; the key itself is the first of that name after
/// it.
pub(crate) fn key_after(text: &str, from: usize, name: &str) -> Option<usize> {
    fn search(table: &DeTable<'_>, from: usize, name: &str, best: &mut Option<usize>) {
        for (k, v) in table.iter() {
            let start = k.span().start;
            if k.get_ref() == name && start >= from {
                *best = Some(best.map_or(start, |b| b.min(start)));
            }
            value(v.get_ref(), from, name, best);
        }
    }
    fn value(v: &DeValue<'_>, from: usize, name: &str, best: &mut Option<usize>) {
        match v {
            DeValue::Table(t) => search(t, from, name, best),
            DeValue::Array(items) => items
                .iter()
                .for_each(|i| value(i.get_ref(), from, name, best)),
            _ => {}
        }
    }
    let doc = DeTable::parse(text).ok()?;
    let mut best = None;
    search(doc.get_ref(), from, name, &mut best);
    best
}

/// Finds the line of a field in a scene's text, for an error message.
pub(crate) trait Locate {
    /// The 1-based line of `table[index].key` (`table.key` without an index, the top-level
    /// `key` without a table); 0 when no line can be told.
    fn line(&self, table: Option<&str>, index: Option<usize>, key: &str) -> usize;

    /// The number at `table[index].key` as written in the text (for messages about a value the
    /// reader changed, such as `1e-400` read as 0); `None` when it cannot be told.
    fn number_literal(
        &self,
        table: Option<&str>,
        index: Option<usize>,
        key: &str,
    ) -> Option<String> {
        let _ = (table, index, key);
        None
    }
}

/// TOML text.
pub(crate) struct TomlText<'a>(pub &'a str);

impl Locate for TomlText<'_> {
    fn line(&self, table: Option<&str>, index: Option<usize>, key: &str) -> usize {
        let text = self.0;
        match table {
            Some(table) => line_of(text, table, index, key),
            None => DeTable::parse(text)
                .ok()
                .and_then(|doc| {
                    doc.get_ref()
                        .get_key_value(key)
                        .map(|(k, _)| line_at(text, k.span().start))
                })
                .unwrap_or(1),
        }
    }

    fn number_literal(
        &self,
        table: Option<&str>,
        index: Option<usize>,
        key: &str,
    ) -> Option<String> {
        number_literal_of(self.0, table, index, key)
    }
}

/// No text to point into (settings given apart from a file): errors name no line.
pub(crate) struct NoText;

impl Locate for NoText {
    fn line(&self, _: Option<&str>, _: Option<usize>, _: &str) -> usize {
        0
    }
}

/// Context for the checks of one scene: the file name and where its fields stand.
#[derive(Clone, Copy)]
pub(crate) struct Checker<'a> {
    /// File name for messages.
    pub file: &'a str,
    /// Finds the line of a field.
    pub locate: &'a dyn Locate,
}

impl Checker<'_> {
    /// An error at `table[index].key`.
    pub(crate) fn error(
        &self,
        table: &str,
        index: Option<usize>,
        key: &str,
        message: impl Into<String>,
    ) -> SceneError {
        let field = match index {
            Some(i) => format!("{table}[{i}].{key}"),
            None => format!("{table}.{key}"),
        };
        let line = self.locate.line(Some(table), index, key);
        let message = self.with_underflow(Some(table), index, key, message.into());
        SceneError::at(self.file, line, field, message)
    }

    /// An error at the top-level key `key` (e.g. the scene `name`).
    pub(crate) fn top_error(&self, key: &str, message: impl Into<String>) -> SceneError {
        let line = self.locate.line(None, None, key);
        let message = self.with_underflow(None, None, key, message.into());
        SceneError::at(self.file, line, key, message)
    }

    /// `message`, and when the field's number underflowed to 0 as the file was read, a word
    /// about it: the check saw 0 where the file has `1e-400`. Looked up only on this error path.
    fn with_underflow(
        &self,
        table: Option<&str>,
        index: Option<usize>,
        key: &str,
        message: String,
    ) -> String {
        match self.locate.number_literal(table, index, key) {
            Some(literal) if underflows_f64(&literal) => format!(
                "{message} (the file's `{}` is below the smallest f64, {:e}, and reads as 0)",
                crate::text::terminal_safe(&literal),
                f64::from_bits(1)
            ),
            _ => message,
        }
    }

    /// A finite number that fits in the engine precision ([`Real`]).
    pub(crate) fn scalar(
        &self,
        table: &str,
        index: Option<usize>,
        key: &str,
        x: f64,
    ) -> Result<Real, SceneError> {
        if !x.is_finite() {
            return Err(self.error(
                table,
                index,
                key,
                format!("expected a finite number, got {}", compact(x)),
            ));
        }
        let y = x as Real;
        if y == 0.0 && x != 0.0 {
            return Err(self.error(
                table,
                index,
                key,
                format!(
                    // Not "expected 0 or …": whether 0 itself is allowed is the field's rule.
                    "{} rounds to 0 in {REAL_NAME}, whose smallest magnitude is {:.1e}",
                    compact(x),
                    Real::from_bits(1)
                ),
            ));
        }
        if !y.is_finite() {
            return Err(self.error(
                table,
                index,
                key,
                format!(
                    "{} overflows {REAL_NAME} (|x| must be below {:.1e})",
                    compact(x),
                    Real::MAX
                ),
            ));
        }
        Ok(y)
    }

    /// A vector of finite [`Real`] numbers.
    pub(crate) fn vec3(
        &self,
        table: &str,
        index: Option<usize>,
        key: &str,
        v: [f64; 3],
    ) -> Result<Vec3, SceneError> {
        let mut out: [Real; 3] = [0.0; 3];
        for (o, x) in out.iter_mut().zip(v) {
            *o = self.scalar(table, index, key, x)?;
        }
        Ok(Vec3::from_array(out))
    }
}

/// `k` from the messages "unknown field `k`, …" and "unknown variant `k`, …".
pub(crate) fn unknown_name(message: &str) -> Option<&str> {
    let rest = message
        .strip_prefix("unknown field `")
        .or_else(|| message.strip_prefix("unknown variant `"))?;
    rest.split_once('`').map(|(name, _)| name)
}

/// `M` from the message "expected N numbers, got M" of a fixed-length array.
pub(crate) fn wrong_length(message: &str) -> Option<usize> {
    let rest = message.split_once("numbers, got ")?.1;
    rest.trim().parse().ok()
}
