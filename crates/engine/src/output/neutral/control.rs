//! Control characters as visible escapes. A case key or a commit read from someone else's
//! file can hold ESC sequences that recolour, move the cursor or retitle a terminal, a
//! carriage return that overwrites the line before it, or a line break that forges a line of
//! output; shown escaped (`\u{1b}`), they are text like any other.

use std::borrow::Cow;

/// Whether `c` is a control character: C0 (tab and line breaks included), DEL and C1.
pub fn is_control(c: char) -> bool {
    c.is_control()
}

/// `text` with every control character as `\u{..}` (ESC as `\u{1b}`, a line break as
/// `\u{a}`): for a piece of foreign text inside a line.
pub fn visible(text: &str) -> Cow<'_, str> {
    escape_except(text, &[])
}

/// `text` with every control character but the line break as `\u{..}`: for a whole message
/// of several lines (an error and its causes), whose line breaks are the writer's own.
pub fn visible_lines(text: &str) -> Cow<'_, str> {
    escape_except(text, &['\n'])
}

fn escape_except<'a>(text: &'a str, kept: &[char]) -> Cow<'a, str> {
    let escaped = |c: char| is_control(c) && !kept.contains(&c);
    if !text.chars().any(escaped) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        if escaped(c) {
            out.push_str(&format!("\\u{{{:x}}}", c as u32));
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_control_character_is_shown_escaped() {
        assert_eq!(visible("lj-box/naive"), "lj-box/naive");
        assert!(matches!(visible("plain"), Cow::Borrowed(_)));
        assert_eq!(visible("a\u{1b}[31mb"), "a\\u{1b}[31mb");
        assert_eq!(visible("a\rb\nc\td"), "a\\u{d}b\\u{a}c\\u{9}d");
        assert_eq!(visible("\u{7f}\u{9b}é"), "\\u{7f}\\u{9b}é");
        assert_eq!(visible_lines("one\ntwo\u{1b}"), "one\ntwo\\u{1b}");
    }
}
