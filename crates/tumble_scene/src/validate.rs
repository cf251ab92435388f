//! Semantic checks of a parsed scene file, with the line of each offending field.

use crate::error::SceneError;

/// Finds the line of `key` inside the `index`-th `[[table]]` (or `[table]` when `index` is
/// `None`); falls back to the table header, then to line 1.
pub fn line_of(text: &str, table: &str, index: Option<usize>, key: &str) -> usize {
    let header = match index {
        Some(_) => format!("[[{table}]]"),
        None => format!("[{table}]"),
    };
    let mut seen = 0;
    let mut in_table = false;
    let mut header_line = 0;
    for (n, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.starts_with('[') {
            in_table = false;
            if line.replace(' ', "") == header {
                if index.is_none_or(|i| i == seen) {
                    in_table = true;
                    header_line = n + 1;
                }
                seen += 1;
            }
            continue;
        }
        if in_table {
            let name = line.split('=').next().unwrap_or("").trim();
            if name == key {
                return n + 1;
            }
        }
    }
    header_line.max(1)
}

/// Context for the checks of one scene: the file name and its text.
pub struct Checker<'a> {
    /// File name for messages.
    pub file: &'a str,
    /// The text, for line numbers.
    pub text: &'a str,
}

impl Checker<'_> {
    /// An error at `table[index].key`.
    pub fn error(
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
        SceneError::at(
            self.file,
            line_of(self.text, table, index, key),
            field,
            message,
        )
    }

    /// A finite number that fits in f32.
    pub fn scalar(
        &self,
        table: &str,
        index: Option<usize>,
        key: &str,
        x: f64,
    ) -> Result<f32, SceneError> {
        if !x.is_finite() {
            return Err(self.error(
                table,
                index,
                key,
                format!("expected a finite number, got {x}"),
            ));
        }
        let y = x as f32;
        if !y.is_finite() {
            return Err(self.error(
                table,
                index,
                key,
                format!("{x} overflows f32 (|x| must be below 3.4e38)"),
            ));
        }
        Ok(y)
    }

    /// A vector of finite f32 numbers.
    pub fn vec3(
        &self,
        table: &str,
        index: Option<usize>,
        key: &str,
        v: [f64; 3],
    ) -> Result<glam::Vec3, SceneError> {
        let mut out = [0.0f32; 3];
        for (o, x) in out.iter_mut().zip(v) {
            *o = self.scalar(table, index, key, x)?;
        }
        Ok(glam::Vec3::from_array(out))
    }
}
