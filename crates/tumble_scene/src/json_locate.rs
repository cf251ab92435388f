//! Lines of fields in JSON text, for error messages.
//!
//! `serde_json` reports the line of a syntax or type error, but not where a field that parsed
//! well but fails a later check (a negative mass, an unknown body name) stands. This scanner
//! finds it: it walks the text once, skipping every value off the path, and counts lines. It
//! runs only when a scene is rejected, reads from any [`Read`] (a scene of a million bodies is
//! scanned from its file, never held as text), never recurses (hostile nesting cannot overflow
//! the stack) and never fails: on text it cannot follow it returns the deepest line it found.
//! Written by hand because no JSON crate reports the positions of values.

use std::io::{BufRead, BufReader, Read};

/// One step of a path into a JSON document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Step<'a> {
    /// The member of an object with this key.
    Key(&'a str),
    /// The element of an array at this index.
    Index(usize),
}

/// The 1-based line of the deepest part of `path` found in the JSON read from `input`: the
/// line of the last key or array element on the path that exists, or of the document's start.
pub(crate) fn line_of(input: impl Read, path: &[Step<'_>]) -> usize {
    let mut scan = Scanner::new(input);
    scan.skip_space();
    let mut line = scan.line;
    for step in path {
        match scan.enter(*step) {
            Some(found) => line = found,
            None => break,
        }
    }
    line
}

/// The text of the number at `path` in the JSON read from `input`, as written; `None` when the
/// path is not there or holds no number.
pub(crate) fn number_at(input: impl Read, path: &[Step<'_>]) -> Option<String> {
    let mut scan = Scanner::new(input);
    scan.skip_space();
    for step in path {
        scan.enter(*step)?;
    }
    scan.skip_space();
    let mut literal = String::new();
    // A JSON number's characters; the longest literal worth quoting is short.
    while let Some(b) = scan.peek().filter(|b| b"0123456789+-.eE".contains(b)) {
        if literal.len() == 64 {
            return None;
        }
        literal.push(char::from(b));
        scan.bump();
    }
    (!literal.is_empty()).then_some(literal)
}

/// The key and line of the first member of the object at `path` whose value is an array of
/// `len` elements: `serde_json` reports an array of the wrong length inside an internally
/// tagged object (`forces`) with the object's path only.
pub(crate) fn array_member_of_len(
    input: impl Read,
    path: &[Step<'_>],
    len: usize,
) -> Option<(String, usize)> {
    let mut scan = Scanner::new(input);
    for step in path {
        scan.enter(*step)?;
    }
    scan.skip_space();
    scan.find_member(|scan, key, line| {
        scan.skip_space();
        if scan.peek()? == b'[' && scan.array_len()? == len {
            return Some(Some((key, line)));
        }
        if scan.peek()? != b',' && scan.peek()? != b'}' {
            scan.skip_value()?;
        }
        Some(None)
    })
}

/// A byte cursor over buffered input that counts lines.
struct Scanner<R> {
    input: BufReader<R>,
    line: usize,
}

impl<R: Read> Scanner<R> {
    /// A cursor at the start of `input`, past a UTF-8 byte order mark (the parse skips one).
    fn new(input: R) -> Self {
        let mut scan = Self {
            input: BufReader::with_capacity(1 << 16, input),
            line: 1,
        };
        if scan
            .input
            .fill_buf()
            .is_ok_and(|start| start.starts_with(b"\xEF\xBB\xBF"))
        {
            scan.input.consume(3);
        }
        scan
    }

    /// The next byte without consuming it; `None` at the end or on a read error.
    fn peek(&mut self) -> Option<u8> {
        self.input.fill_buf().ok()?.first().copied()
    }

    /// Consumes one byte.
    fn bump(&mut self) -> Option<u8> {
        let b = self.peek()?;
        self.input.consume(1);
        if b == b'\n' {
            self.line += 1;
        }
        Some(b)
    }

    fn skip_space(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | b'\n' | b'\r')) {
            self.bump();
        }
    }

    /// From the start of a value, moves into the member or element `step` and returns the
    /// line where it starts; the cursor is then at that member's value.
    fn enter(&mut self, step: Step<'_>) -> Option<usize> {
        self.skip_space();
        match step {
            Step::Key(key) => self.find_member(|scan, name, line| {
                if name == key {
                    scan.skip_space();
                    Some(Some(line))
                } else {
                    scan.skip_value()?;
                    Some(None)
                }
            }),
            Step::Index(index) => {
                if self.bump()? != b'[' {
                    return None;
                }
                for i in 0.. {
                    self.skip_space();
                    if self.peek()? == b']' {
                        return None;
                    }
                    if i == index {
                        return Some(self.line);
                    }
                    self.skip_value()?;
                    self.skip_space();
                    if self.bump()? != b',' {
                        return None;
                    }
                }
                None
            }
        }
    }

    /// Walks the members of the object at the cursor. For each, `visit` gets its key and the line
    /// where it starts, with the cursor just after its `:`; `visit` returns `Some(Some(found))`
    /// to stop there with `found`, `Some(None)` having moved past the value to go on, or `None`
    /// on text it cannot follow. `None` at the object's end or on text it cannot follow.
    fn find_member<T>(
        &mut self,
        mut visit: impl FnMut(&mut Self, String, usize) -> Option<Option<T>>,
    ) -> Option<T> {
        if self.bump()? != b'{' {
            return None;
        }
        loop {
            self.skip_space();
            if self.peek()? != b'"' {
                return None;
            }
            let line = self.line;
            let key = self.string()?;
            self.skip_space();
            if self.bump()? != b':' {
                return None;
            }
            if let Some(found) = visit(self, key, line)? {
                return Some(found);
            }
            self.skip_space();
            if self.bump()? != b',' {
                return None;
            }
        }
    }

    /// Counts the elements of the array at the cursor and moves past it.
    fn array_len(&mut self) -> Option<usize> {
        self.bump();
        self.skip_space();
        if self.peek()? == b']' {
            self.bump();
            return Some(0);
        }
        let mut count = 0;
        loop {
            self.skip_value()?;
            count += 1;
            self.skip_space();
            match self.bump()? {
                b',' => {}
                b']' => return Some(count),
                _ => return None,
            }
        }
    }

    /// Reads a string token (the cursor at its opening quote) and decodes its escapes.
    fn string(&mut self) -> Option<String> {
        self.bump();
        let mut bytes = Vec::new();
        loop {
            match self.bump()? {
                b'"' => break,
                b'\\' => match self.bump()? {
                    b'u' => {
                        let mut unit = self.hex4()?;
                        if (0xD800..0xDC00).contains(&unit)
                            && self.bump()? == b'\\'
                            && self.bump()? == b'u'
                        {
                            let low = self.hex4()?;
                            unit = 0x10000 + ((unit - 0xD800) << 10) + (low.wrapping_sub(0xDC00));
                        }
                        let c = char::from_u32(unit).unwrap_or('\u{fffd}');
                        bytes.extend_from_slice(c.encode_utf8(&mut [0; 4]).as_bytes());
                    }
                    b'b' => bytes.push(0x08),
                    b'f' => bytes.push(0x0c),
                    b'n' => bytes.push(b'\n'),
                    b'r' => bytes.push(b'\r'),
                    b't' => bytes.push(b'\t'),
                    other => bytes.push(other),
                },
                b => bytes.push(b),
            }
        }
        Some(String::from_utf8_lossy(&bytes).into_owned())
    }

    fn hex4(&mut self) -> Option<u32> {
        let mut unit = 0;
        for _ in 0..4 {
            unit = unit * 16 + char::from(self.bump()?).to_digit(16)?;
        }
        Some(unit)
    }

    /// Skips one value, however deeply nested, counting the depth instead of recursing.
    fn skip_value(&mut self) -> Option<()> {
        let mut depth = 0usize;
        loop {
            self.skip_space();
            match self.peek()? {
                b'"' => {
                    self.skip_string()?;
                }
                b'{' | b'[' => {
                    self.bump();
                    depth += 1;
                    continue;
                }
                b'}' | b']' => {
                    self.bump();
                    depth = depth.checked_sub(1)?;
                }
                b',' | b':' if depth > 0 => {
                    self.bump();
                    continue;
                }
                _ => {
                    // A number or a literal: up to the next delimiter.
                    while !matches!(
                        self.peek(),
                        None | Some(b',' | b'}' | b']' | b':' | b' ' | b'\t' | b'\n' | b'\r')
                    ) {
                        self.bump();
                    }
                }
            }
            if depth == 0 {
                return Some(());
            }
        }
    }

    fn skip_string(&mut self) -> Option<()> {
        self.bump();
        loop {
            match self.bump()? {
                b'"' => return Some(()),
                b'\\' => {
                    self.bump()?;
                }
                _ => {}
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Step::{Index, Key};
    use super::*;

    const DOC: &str = r#"{
  "name": "x",
  "world": {"dt": 0.01,
            "steps": 10},
  "bodies": [
    {"name": "a", "mass": 1.0, "inertia": [1, 2, 3]},
    {
      "name": "b\"}],",
      "nested": {"deep": [[{"x": "]"}], {}], "k": -1.5e3},
      "mass": -2
    }
  ],
  "for\u0063es": [ {"type": "spring"} ]
}"#;

    fn line(path: &[Step<'_>]) -> usize {
        line_of(DOC.as_bytes(), path)
    }

    #[test]
    fn keys_and_elements_are_found_on_their_lines() {
        assert_eq!(line(&[Key("name")]), 2);
        assert_eq!(line(&[Key("world"), Key("steps")]), 4);
        assert_eq!(line(&[Key("bodies"), Index(0), Key("mass")]), 6);
        assert_eq!(line(&[Key("bodies"), Index(1)]), 7);
        // Past a string holding quotes, brackets and commas, and nested values.
        assert_eq!(line(&[Key("bodies"), Index(1), Key("mass")]), 10);
        // An escaped key is compared decoded.
        assert_eq!(line(&[Key("forces"), Index(0), Key("type")]), 13);
    }

    #[test]
    fn numbers_are_read_as_written() {
        let text = "{\"world\": {\"dt\": 1e-400, \"steps\": 10},\n \"bodies\": [{\"mass\": -0.0}]}";
        let at = |path: &[Step<'_>]| number_at(text.as_bytes(), path);
        assert_eq!(
            at(&[Step::Key("world"), Step::Key("dt")]).as_deref(),
            Some("1e-400")
        );
        assert_eq!(
            at(&[Step::Key("bodies"), Step::Index(0), Step::Key("mass")]).as_deref(),
            Some("-0.0")
        );
        assert_eq!(at(&[Step::Key("world"), Step::Key("gone")]), None);
        assert_eq!(at(&[Step::Key("world")]), None);
    }

    #[test]
    fn a_byte_order_mark_is_skipped() {
        let doc = "\u{feff}{\"a\": 1,\n\"b\": 2}";
        assert_eq!(line_of(doc.as_bytes(), &[Key("b")]), 2);
    }

    #[test]
    fn a_missing_part_gives_the_deepest_line_found() {
        assert_eq!(line(&[Key("bodies"), Index(1), Key("density")]), 7);
        assert_eq!(line(&[Key("bodies"), Index(5), Key("mass")]), 5);
        assert_eq!(line(&[Key("nothing")]), 1);
        assert_eq!(line_of("[1, 2".as_bytes(), &[Index(4)]), 1);
        assert_eq!(line_of("".as_bytes(), &[Key("a")]), 1);
    }

    #[test]
    fn an_array_member_is_found_by_its_length() {
        let doc = "{\"forces\": [{\"type\": \"spring\", \"anchor_a\": [1, 2, 3],\n\"x\": \"[\",\n\"anchor_b\": [[1], 2, {\"a\": [5]}, 4]}]}";
        let path = [Key("forces"), Index(0)];
        assert_eq!(
            array_member_of_len(doc.as_bytes(), &path, 4),
            Some(("anchor_b".to_owned(), 3))
        );
        assert_eq!(
            array_member_of_len(doc.as_bytes(), &path, 3),
            Some(("anchor_a".to_owned(), 1))
        );
        assert_eq!(array_member_of_len(doc.as_bytes(), &path, 2), None);
    }

    #[test]
    fn deep_nesting_does_not_recurse() {
        let deep = format!(
            "{{\"a\": {}{},\n\"b\": 1}}",
            "[".repeat(1_000_000),
            "]".repeat(1_000_000)
        );
        assert_eq!(line_of(deep.as_bytes(), &[Key("b")]), 2);
        let broken = format!("{{\"a\": {}", "[".repeat(1_000_000));
        assert_eq!(line_of(broken.as_bytes(), &[Key("b")]), 1);
    }
}
