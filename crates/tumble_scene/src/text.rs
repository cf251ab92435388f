//! Text that reaches a terminal: every string tumble echoes that came from a user (scene and body
//! names, file paths, parser messages) goes through [`terminal_safe`] first.
//!
//! A raw string could move the cursor or rewrite earlier lines (ESC sequences), ring the bell,
//! forge a summary line (a newline), reorder what is shown (bidi overrides) or hide characters
//! (zero-width format characters); a 1 MB name would flood the screen.

use std::borrow::Cow;

/// Longest user string echoed whole, in characters; longer ones are cut with an ellipsis.
pub const MAX_ECHO_CHARS: usize = 200;

/// `name` in Unicode normalization form C (composed: `é` as U+00E9, not `e` + U+0301), the form
/// every name of a loaded scene is kept in; borrowed when it already is (almost always).
pub fn composed(name: &str) -> Cow<'_, str> {
    use unicode_normalization::{UnicodeNormalization, is_nfc};
    if is_nfc(name) {
        Cow::Borrowed(name)
    } else {
        Cow::Owned(name.nfc().collect())
    }
}

/// Whether `c` must not be printed raw: C0/C1 controls (Unicode `Cc`, which includes newline,
/// ESC, BEL and DEL), the format characters (`Cf`: bidi embeddings, overrides and isolates,
/// zero-width joiners and spaces, the BOM, soft hyphen, …), and the line and paragraph
/// separators U+2028/U+2029.
pub fn is_unsafe_char(c: char) -> bool {
    c.is_control() || is_format_char(c) || matches!(c, '\u{2028}' | '\u{2029}')
}

/// Unicode general category `Cf` (format characters), as of Unicode 15.
fn is_format_char(c: char) -> bool {
    matches!(
        c as u32,
        0x00AD
            | 0x0600..=0x0605
            | 0x061C
            | 0x06DD
            | 0x070F
            | 0x0890..=0x0891
            | 0x08E2
            | 0x180E
            | 0x200B..=0x200F
            | 0x202A..=0x202E
            | 0x2060..=0x2064
            | 0x2066..=0x206F
            | 0xFEFF
            | 0xFFF9..=0xFFFB
            | 0x110BD
            | 0x110CD
            | 0x13430..=0x1343F
            | 0x1BCA0..=0x1BCA3
            | 0x1D173..=0x1D17A
            | 0xE0001
            | 0xE0020..=0xE007F
    )
}

/// `text` made safe to print on one terminal line: unsafe characters ([`is_unsafe_char`]) are
/// shown as Rust escapes (`\n`, `\u{1b}`, `\u{202e}`), and text longer than
/// [`MAX_ECHO_CHARS`] is cut with `…`. Borrowed when nothing changes.
pub fn terminal_safe(text: &str) -> Cow<'_, str> {
    terminal_safe_within(text, MAX_ECHO_CHARS)
}

/// [`terminal_safe`] with the cut at `max` characters instead of [`MAX_ECHO_CHARS`].
pub fn terminal_safe_within(text: &str, max: usize) -> Cow<'_, str> {
    let long = text.chars().nth(max).is_some();
    if !long && !text.chars().any(is_unsafe_char) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len().min(4 * max));
    for c in text.chars().take(max) {
        if is_unsafe_char(c) {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    if long {
        out.push('…');
    }
    Cow::Owned(out)
}

/// A path made safe to print (see [`terminal_safe`]); non-UTF-8 bytes are shown as `�`.
pub fn path_for_terminal(path: &std::path::Path) -> String {
    terminal_safe(&path.to_string_lossy()).into_owned()
}

/// `text` with what stands between `<!-- {name}:begin -->` and `<!-- {name}:end -->` replaced
/// by a line break and `section`; `None` unless the text holds exactly one pair of them, in
/// that order (a second pair would be left stale, or the text between two begins lost).
pub fn replace_between_markers(text: &str, name: &str, section: &str) -> Option<String> {
    let begin = format!("<!-- {name}:begin -->");
    let end = format!("<!-- {name}:end -->");
    if markers_repeated(text, name) {
        return None;
    }
    let start = text.find(&begin)? + begin.len();
    let end = start + text[start..].find(&end)?;
    Some(format!("{}\n{}{}", &text[..start], section, &text[end..]))
}

/// True when `text` holds either marker of section `name` more than once.
pub fn markers_repeated(text: &str, name: &str) -> bool {
    ["begin", "end"]
        .iter()
        .any(|which| text.matches(&format!("<!-- {name}:{which} -->")).count() > 1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markers_are_replaced_once_and_repeated_ones_refused() {
        let one = "a\n<!-- s:begin -->\nold\n<!-- s:end -->\nb";
        assert_eq!(
            replace_between_markers(one, "s", "new\n").unwrap(),
            "a\n<!-- s:begin -->\nnew\n<!-- s:end -->\nb"
        );
        let two = "<!-- s:begin -->x<!-- s:end --> <!-- s:begin -->y<!-- s:end -->";
        assert!(markers_repeated(two, "s"));
        assert_eq!(replace_between_markers(two, "s", "new"), None);
        let two_begins = "<!-- s:begin -->x<!-- s:begin -->y<!-- s:end -->";
        assert_eq!(replace_between_markers(two_begins, "s", "new"), None);
        assert!(!markers_repeated(one, "s"));
    }

    #[test]
    fn plain_text_is_borrowed_unchanged() {
        assert!(matches!(
            terminal_safe("chain α-β"),
            Cow::Borrowed("chain α-β")
        ));
    }

    #[test]
    fn controls_and_format_characters_are_escaped() {
        let shown = terminal_safe("a\nb\u{1b}[2Jc\u{7}d\u{202e}e\u{200b}f\u{2028}");
        assert_eq!(
            shown,
            "a\\nb\\u{1b}[2Jc\\u{7}d\\u{202e}e\\u{200b}f\\u{2028}"
        );
        assert!(!shown.chars().any(is_unsafe_char));
    }

    #[test]
    fn long_text_is_cut_with_an_ellipsis() {
        let long = "x".repeat(1_000_000);
        let shown = terminal_safe(&long);
        assert_eq!(shown.chars().count(), MAX_ECHO_CHARS + 1);
        assert!(shown.ends_with('…'));
    }
}
