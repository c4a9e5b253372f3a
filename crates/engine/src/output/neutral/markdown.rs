//! Foreign text in Markdown (REPORT.md, `summary.md`, the gate's job summary, the history's
//! pull-request summary). A case key is written as a code span, and a backtick in it would
//! close the span early and let what follows (raw HTML, a link) be read as Markdown; a reason
//! or a date is written as text, where `<`, `[` or `*` would be read as HTML, a link or
//! emphasis. Here:
//!
//! - [`code`] fences the text with one backtick more than its longest run of backticks
//!   (CommonMark closes a span only on a run of the same length), padded with a space where
//!   the text starts or ends with a backtick or a space (CommonMark strips one from each side);
//! - [`text`] writes `&`, `<` and `>` as HTML entities and backslash-escapes the punctuation
//!   that starts a link, a code span or a table cell (emphasis characters are left: they
//!   change how a text looks, not what it is or where it leads, and `FAST_KER=ON` stays
//!   readable in the Markdown source);
//! - both keep the text on one line (a line break would end a table row, a blank line the
//!   paragraph, and with it the span): control characters are shown escaped
//!   ([`super::control`]), and [`cell_code`] / [`text`] escape `|`, which ends a table cell.

use super::control;

/// `text` as one code span that nothing in it can close, on one line.
pub fn code(text: &str) -> String {
    if text.is_empty() {
        // A span of one space: two backticks alone would be an empty run, not a span.
        return "` `".to_string();
    }
    let text = control::visible(text);
    let longest = longest_run(&text, '`');
    let fence = "`".repeat(longest + 1);
    let pad = text.is_empty() || text.starts_with(['`', ' ']) || text.ends_with(['`', ' ']);
    let space = if pad { " " } else { "" };
    format!("{fence}{space}{text}{space}{fence}")
}

/// `text` as a code span in a cell of a table: [`code`] with `|` escaped (GitHub's tables
/// split the row at every unescaped `|`, inside code spans too, and drop the backslash). A
/// backslash just before a `|` would escape the escape, so it is shown as `\u{5c}`.
pub fn cell_code(text: &str) -> String {
    code(&text.replace("\\|", "\\u{5c}|")).replace('|', "\\|")
}

/// `text` as Markdown text on one line: no raw HTML, no entity, link, image, code span or
/// table cell border of its own. Line breaks and tabs become spaces; other control characters
/// are shown escaped.
pub fn text(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '\n' | '\r' | '\t' => out.push(' '),
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '\\' | '`' | '[' | ']' | '|' => {
                out.push('\\');
                out.push(c);
            }
            c if control::is_control(c) => out.push_str(&control::visible(&c.to_string())),
            c => out.push(c),
        }
    }
    out
}

/// The length of the longest run of `c` in `text`.
fn longest_run(text: &str, c: char) -> usize {
    let (mut longest, mut run) = (0, 0);
    for x in text.chars() {
        run = if x == c { run + 1 } else { 0 };
        longest = longest.max(run);
    }
    longest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_code_span_is_not_closed_by_its_content() {
        assert_eq!(code("lj-box/naive/n=1000"), "`lj-box/naive/n=1000`");
        assert_eq!(code("a`<img src=x>"), "``a`<img src=x>``");
        assert_eq!(code("``x"), "``` ``x ```");
        assert_eq!(code("x`"), "`` x` ``");
        assert_eq!(code(" x "), "`  x  `");
        assert_eq!(code(""), "` `");
        assert_eq!(code("a\n\n<b>"), "`a\\u{a}\\u{a}<b>`");
        assert_eq!(cell_code("a|b"), "`a\\|b`");
        assert_eq!(cell_code("a\\|b"), "`a\\u{5c}\\|b`");
    }

    #[test]
    fn text_carries_no_markup() {
        assert_eq!(text("plain words, 1.5x"), "plain words, 1.5x");
        assert_eq!(
            text("<script>[x](javascript:y) *b* `c` a|b &amp; FAST_KER"),
            "&lt;script&gt;\\[x\\](javascript:y) *b* \\`c\\` a\\|b &amp;amp; FAST_KER"
        );
        assert_eq!(text("one\ntwo\u{1b}"), "one two\\u{1b}");
    }
}
