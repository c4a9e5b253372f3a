//! Which links an HTML page makes clickable. A link taken from someone else's file (a figure
//! of REPORT.md) could name a `javascript:` or `data:` URL, which would run in the page when
//! clicked; only links that lead to a document are made `href`s: http, https and mailto URLs,
//! relative paths and fragments. Anything else is shown as text by its writer.
//!
//! A browser removes tabs and line breaks from a URL and strips leading spaces and control
//! characters before it reads the scheme (`java\tscript:` is `javascript:`), so a link that
//! holds any of these is refused whole rather than cleaned.

/// The schemes a page links to.
const SCHEMES: [&str; 3] = ["http", "https", "mailto"];

/// `link` when a page may make it an `href` (it still needs HTML escaping); `None` when it
/// must be shown as text.
pub fn href(link: &str) -> Option<&str> {
    if link.is_empty() || link.starts_with(' ') || link.chars().any(char::is_control) {
        return None;
    }
    match scheme(link) {
        None => Some(link),
        Some(s) if SCHEMES.iter().any(|k| s.eq_ignore_ascii_case(k)) => Some(link),
        Some(_) => None,
    }
}

/// The scheme of `link` as a URL parser reads it: the letters, digits, `+`, `-` and `.`
/// before the first `:`, starting with a letter, when no `/`, `?` or `#` comes first; `None`
/// for a relative link (a path, a query, a fragment).
fn scheme(link: &str) -> Option<&str> {
    let end = link.find([':', '/', '?', '#', '\\'])?;
    let candidate = &link[..end];
    let is_scheme = link[end..].starts_with(':')
        && candidate.starts_with(|c: char| c.is_ascii_alphabetic())
        && candidate
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '+' | '-' | '.'));
    is_scheme.then_some(candidate)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_documents_are_linked() {
        for ok in [
            "../../a/analysis/t.svg",
            "figures/x.png",
            "#case-1",
            "?q=1",
            "https://example.org/x.png",
            "HTTP://example.org",
            "mailto:someone@example.org",
            "a/b:c.svg",
            "1x:y",
        ] {
            assert_eq!(href(ok), Some(ok), "{ok}");
        }
        for bad in [
            "javascript:alert(1)",
            "JavaScript:alert(1)",
            "data:text/html,<script>",
            "vbscript:x",
            "java\tscript:alert(1)",
            " javascript:alert(1)",
            "file:///etc/passwd",
            "",
        ] {
            assert_eq!(href(bad), None, "{bad:?}");
        }
    }
}
