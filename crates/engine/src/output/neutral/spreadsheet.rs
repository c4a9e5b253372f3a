//! Text cells a spreadsheet will not run as formulas. A CSV or JSON lines table is opened in
//! spreadsheets, which read a cell that starts with `=`, `+`, `-` or `@` (or a tab or a
//! carriage return before one) as a formula: a case key or a program name from someone
//! else's config such as `=HYPERLINK(...)` would run when the table is opened. Such a text
//! cell is written with a `'` in front, which spreadsheets take as "text" and do not show
//! (the usual neutralisation of CSV injection).
//!
//! Numbers are values, not text, and are written as they are; a text cell that is a plain
//! number (`-1.5`, `+2e3`) is no formula and is left as it is too.

use std::borrow::Cow;

/// The characters that make a spreadsheet read a cell as a formula.
const FORMULA_STARTS: [char; 6] = ['=', '+', '-', '@', '\t', '\r'];

/// `text` as a table's text cell: with a `'` in front when it starts like a formula.
pub fn text_cell(text: &str) -> Cow<'_, str> {
    if text.starts_with(FORMULA_STARTS) && !is_plain_number(text) {
        Cow::Owned(format!("'{text}"))
    } else {
        Cow::Borrowed(text)
    }
}

/// A decimal number and nothing else: digits, a sign, a point, an exponent.
fn is_plain_number(text: &str) -> bool {
    text.chars()
        .all(|c| c.is_ascii_digit() || matches!(c, '+' | '-' | '.' | 'e' | 'E'))
        && text.parse::<f64>().is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formulas_become_text_and_numbers_stay() {
        assert_eq!(text_cell("=HYPERLINK(\"x\")"), "'=HYPERLINK(\"x\")");
        assert_eq!(text_cell("+cmd"), "'+cmd");
        assert_eq!(text_cell("-2+3"), "'-2+3");
        assert_eq!(text_cell("@SUM(A1)"), "'@SUM(A1)");
        assert_eq!(text_cell("\t=1"), "'\t=1");
        assert_eq!(text_cell("\r=1"), "'\r=1");
        assert_eq!(text_cell("lj-box/naive"), "lj-box/naive");
        assert_eq!(text_cell("-1.5"), "-1.5");
        assert_eq!(text_cell("+2e3"), "+2e3");
        assert_eq!(text_cell(""), "");
    }
}
