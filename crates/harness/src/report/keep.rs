//! Hand-written interpretation inside a generated document. Regions between
//! `<!-- keep:NAME -->` and `<!-- /keep:NAME -->` belong to people: regenerating the document
//! carries them over from the previous version, so running `report` never destroys analysis.

use std::collections::BTreeMap;
use thiserror::Error;

/// Why the kept regions of a document cannot be read; lines are 1-based.
#[derive(Debug, Error, PartialEq)]
pub enum KeepError {
    /// An opening marker with no closing marker after it.
    #[error(
        "line {line}: `<!-- keep:{name} -->` is never closed; add `<!-- /keep:{name} -->` after the text to keep"
    )]
    Unclosed {
        /// The region's name.
        name: String,
        /// The line of its opening marker (when merging a generated document: its last line).
        line: usize,
    },
    /// Two regions of the same name.
    #[error("line {line}: the kept region `{name}` appears twice; rename one of them")]
    Duplicate {
        /// The repeated name.
        name: String,
        /// The line of the second region's opening marker.
        line: usize,
    },
}

/// The opening marker of a kept region.
pub fn open(name: &str) -> String {
    format!("<!-- keep:{name} -->")
}

/// The closing marker of a kept region.
pub fn close(name: &str) -> String {
    format!("<!-- /keep:{name} -->")
}

/// A kept region with `default` as its text, for a newly generated document.
pub fn region(name: &str, default: &str) -> String {
    format!("{}\n{}\n{}\n", open(name), default.trim_end(), close(name))
}

/// The text of every kept region of `doc`, by name (markers excluded).
pub(crate) fn extract(doc: &str) -> Result<BTreeMap<String, String>, KeepError> {
    let mut out = BTreeMap::new();
    let mut current: Option<(String, usize, Vec<&str>)> = None;
    for (i, line) in doc.lines().enumerate() {
        let trimmed = line.trim();
        if let Some((name, start, body)) = current.as_mut() {
            if trimmed == close(name) {
                let text = body.join("\n");
                let (name, start) = (std::mem::take(name), *start);
                if out.insert(name.clone(), text).is_some() {
                    return Err(KeepError::Duplicate { name, line: start });
                }
                current = None;
            } else {
                body.push(line);
            }
        } else if let Some(name) = marker_name(trimmed) {
            current = Some((name.to_string(), i + 1, Vec::new()));
        }
    }
    match current {
        Some((name, line, _)) => Err(KeepError::Unclosed { name, line }),
        None => Ok(out),
    }
}

/// The figures written in each kept region of `kept` that holds any, by region. A figure is a
/// number: a digit that does not continue a word (`FMM3D`, `f64` and `M2L` are names) and is
/// outside a code span (`--steps 500` is a command).
pub fn figures(kept: &BTreeMap<String, String>) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    for (name, text) in kept {
        let mut found = Vec::new();
        // Every other piece between backticks is a code span.
        for prose in text.split('`').step_by(2) {
            for word in prose.split_whitespace() {
                let mut previous = ' ';
                for c in word.chars() {
                    if c.is_ascii_digit() && !(previous.is_alphanumeric() || previous == '_') {
                        found.push(word.to_string());
                        break;
                    }
                    previous = c;
                }
            }
        }
        if !found.is_empty() {
            out.push((name.clone(), found));
        }
    }
    out
}

/// `generated` with each kept region's text replaced by the one in `kept` (when present).
/// Regions of `kept` that the new document no longer has are appended at the end under a
/// heading, so that no hand-written text is ever dropped silently.
pub fn merge(generated: &str, kept: &BTreeMap<String, String>) -> Result<String, KeepError> {
    let mut out = String::with_capacity(generated.len());
    let mut used = Vec::new();
    let mut skipping: Option<String> = None;
    for line in generated.lines() {
        let trimmed = line.trim();
        if let Some(name) = &skipping {
            if trimmed == close(name) {
                out.push_str(line);
                out.push('\n');
                skipping = None;
            }
            continue;
        }
        out.push_str(line);
        out.push('\n');
        if let Some(name) = marker_name(trimmed)
            && let Some(text) = kept.get(name)
        {
            if !text.is_empty() {
                out.push_str(text);
                out.push('\n');
            }
            used.push(name.to_string());
            skipping = Some(name.to_string());
        }
    }
    if let Some(name) = skipping {
        return Err(KeepError::Unclosed {
            name,
            line: generated.lines().count(),
        });
    }
    let orphans: Vec<_> = kept.iter().filter(|(n, _)| !used.contains(n)).collect();
    if !orphans.is_empty() {
        out.push_str("\n## Kept notes whose section no longer exists\n\n");
        for (name, text) in orphans {
            out.push_str(&region(name, text));
            out.push('\n');
        }
    }
    Ok(out)
}

fn marker_name(line: &str) -> Option<&str> {
    line.strip_prefix("<!-- keep:")?
        .strip_suffix("-->")
        .map(str::trim)
        .filter(|n| !n.is_empty())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_number_in_prose_is_a_figure_and_names_and_code_are_not() {
        let kept = BTreeMap::from([
            (
                "a".to_string(),
                "FMM3D's M2L in f64 (`--steps 500`) is fine".to_string(),
            ),
            (
                "b".to_string(),
                "keeps 0.94 at p = 2, (3.9e-4 there)".to_string(),
            ),
        ]);
        let found = figures(&kept);
        assert_eq!(
            found,
            vec![(
                "b".to_string(),
                vec!["0.94".into(), "2,".into(), "(3.9e-4".into()]
            )]
        );
    }

    #[test]
    fn the_reports_kept_regions_hold_no_figure() {
        // Interpretation only: every number of REPORT.md comes from a results file through
        // the generated sections, and a number written by hand goes stale.
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../REPORT.md");
        let kept = extract(&std::fs::read_to_string(path).unwrap()).unwrap();
        assert!(kept.len() >= 5, "{:?}", kept.keys());
        assert_eq!(figures(&kept), Vec::<(String, Vec<String>)>::new());
    }

    #[test]
    fn kept_text_survives_regeneration() {
        let old = format!(
            "# Old\nnumber 1\n{}\nfooter\n",
            region("strong", "My reading:\nserial work dominates.")
        );
        let new = format!(
            "# New\nnumber 2\n{}\nfooter 2\n",
            region("strong", "(write here)")
        );
        let merged = merge(&new, &extract(&old).unwrap()).unwrap();
        assert!(merged.contains("number 2"));
        assert!(merged.contains("My reading:\nserial work dominates."));
        assert!(!merged.contains("(write here)"));
        // Idempotent: merging again with its own regions changes nothing.
        assert_eq!(merge(&merged, &extract(&merged).unwrap()).unwrap(), merged);
    }

    #[test]
    fn new_regions_keep_their_default_and_orphans_are_not_lost() {
        let old = region("gone", "text of a removed section");
        let new = region("fresh", "default");
        let merged = merge(&new, &extract(&old).unwrap()).unwrap();
        assert!(merged.contains("default"));
        assert!(merged.contains("text of a removed section"));
        assert!(merged.contains("no longer exists"));
    }

    #[test]
    fn malformed_markers_are_errors() {
        let unclosed = "a\n<!-- keep:x -->\nb\n";
        assert_eq!(
            extract(unclosed),
            Err(KeepError::Unclosed {
                name: "x".into(),
                line: 2
            })
        );
        let twice = format!("{}{}", region("x", "a"), region("x", "b"));
        assert!(matches!(extract(&twice), Err(KeepError::Duplicate { .. })));
    }
}
