//! A reader that refuses a JSON string longer than any the scene schema holds, before the parser
//! has read it whole.
//!
//! `serde_json` reads a string (a key or a value) into a buffer of its own before the model sees
//! it, and an unknown key is copied again into the error: a file whose one key is 50 MB long took
//! 447 MB to refuse, unbounded by anything the schema needs. The longest string the schema holds
//! is a name ([`MAX_NAME_BYTES`](crate::MAX_NAME_BYTES)); every other is a key or a tag of a few
//! bytes. So the bytes are watched on their way to the parser, and a string that runs past
//! [`MAX_JSON_STRING_BYTES`] fails the read, naming its line. No crate offers this: serde_json has
//! no limit on a string's length, and the watch is a few lines (outside strings, JSON has no `"`
//! byte; inside, `\` escapes the next byte).

use std::io::{self, BufRead, Read};

/// Longest JSON string (key or value) a scene file may hold, in bytes of its raw text: far past
/// the longest the schema uses (a 256-byte name, written with escapes), far below what would
/// cost memory.
pub const MAX_JSON_STRING_BYTES: usize = 64 * 1024;

/// What the reader found: a string too long, with the line it starts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct StringTooLong {
    /// The line the string starts on (1-based).
    pub(crate) line: usize,
}

impl std::fmt::Display for StringTooLong {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a string starting on line {} is longer than {MAX_JSON_STRING_BYTES} bytes; the \
             longest a scene holds is a name of {} bytes",
            self.line,
            crate::MAX_NAME_BYTES
        )
    }
}

impl std::error::Error for StringTooLong {}

/// `input`, passed through unchanged, that fails with [`StringTooLong`] (as an
/// [`io::Error`]) once a string runs past [`MAX_JSON_STRING_BYTES`].
pub(crate) struct LimitedStrings<R> {
    input: R,
    /// The line being read (1-based).
    line: usize,
    /// Inside a string: the line it starts on and its length so far.
    string: Option<(usize, usize)>,
    /// The last byte was a `\` inside a string.
    escaped: bool,
    /// The string that ran too long, once one has (the parser's error then only says the read
    /// failed).
    too_long: Option<StringTooLong>,
}

impl<R> LimitedStrings<R> {
    pub(crate) fn new(input: R) -> Self {
        Self {
            input,
            line: 1,
            string: None,
            escaped: false,
            too_long: None,
        }
    }

    /// The string that ran too long, if the read failed for it.
    pub(crate) fn too_long(&self) -> Option<StringTooLong> {
        self.too_long
    }

    /// Follows `bytes` through the JSON grammar's strings; the string that runs too long, if any.
    fn watch(&mut self, bytes: &[u8]) -> Result<(), StringTooLong> {
        for &b in bytes {
            if b == b'\n' {
                self.line += 1;
            }
            match &mut self.string {
                None => {
                    if b == b'"' {
                        self.string = Some((self.line, 0));
                    }
                }
                Some((start, length)) => {
                    if self.escaped {
                        self.escaped = false;
                    } else if b == b'\\' {
                        self.escaped = true;
                    } else if b == b'"' {
                        self.string = None;
                        continue;
                    }
                    *length += 1;
                    if *length > MAX_JSON_STRING_BYTES {
                        return Err(StringTooLong { line: *start });
                    }
                }
            }
        }
        Ok(())
    }
}

impl<R: BufRead> Read for LimitedStrings<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        let available = self.input.fill_buf()?;
        let n = available.len().min(out.len());
        out[..n].copy_from_slice(&available[..n]);
        self.input.consume(n);
        if let Err(e) = self.watch(&out[..n]) {
            self.too_long = Some(e);
            return Err(io::Error::other(e));
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_all(text: &[u8]) -> io::Result<Vec<u8>> {
        let mut out = Vec::new();
        LimitedStrings::new(text).read_to_end(&mut out)?;
        Ok(out)
    }

    #[test]
    fn text_with_short_strings_passes_unchanged() {
        let text = br#"{"name": "a \"quoted\" \\ name", "bodies": [1, 2]}"#;
        assert_eq!(read_all(text).unwrap(), text);
        // A string of exactly the limit, escapes counted as written.
        let at_limit = format!("{{\"k\": \"{}\"}}", "x".repeat(MAX_JSON_STRING_BYTES));
        assert!(read_all(at_limit.as_bytes()).is_ok());
    }

    #[test]
    fn a_string_past_the_limit_fails_naming_its_line() {
        for (key, escape) in [(true, ""), (false, "\\\"")] {
            let long = format!("{escape}{}", "x".repeat(MAX_JSON_STRING_BYTES + 1));
            let text = if key {
                format!("{{\n\"name\": \"a\",\n\"{long}\": 1}}")
            } else {
                format!("{{\n\"name\": \"a\",\n\"k\": \"{long}\"}}")
            };
            let Err(e) = read_all(text.as_bytes()) else {
                panic!("a string past the limit was read")
            };
            let inner = e.get_ref().unwrap().downcast_ref::<StringTooLong>();
            assert_eq!(inner, Some(&StringTooLong { line: 3 }), "{e}");
        }
    }

    #[test]
    fn quotes_outside_strings_and_escaped_quotes_inside_are_told_apart() {
        // An escaped quote does not end the string; the limit counts on past it.
        let long = format!(
            "\"{}\\\"{}\"",
            "x".repeat(10),
            "y".repeat(MAX_JSON_STRING_BYTES)
        );
        assert!(read_all(long.as_bytes()).is_err());
        // Many short strings in a row never add up.
        let many = "\"ab\",".repeat(MAX_JSON_STRING_BYTES);
        assert!(read_all(many.as_bytes()).is_ok());
    }
}
