//! The figures of REPORT.md, linked from the page: every image REPORT.md shows
//! (`![title](path)`), in its order, that exists, by a path relative to the page's folder (so
//! that the page and the figures move together with the repository).

use std::path::{Component, Path, PathBuf};

/// A figure: its title (REPORT.md's alternative text), its path as REPORT.md names it (two
/// sweeps' figures can share a title), and its link from the page.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure {
    /// REPORT.md's alternative text of the image.
    pub title: String,
    /// The image's path as REPORT.md writes it, relative to REPORT.md.
    pub path: String,
    /// Link to the image relative to the page's folder.
    pub href: String,
}

/// The figures `report` shows that exist, linked from the folder `out` (which must exist); a
/// missing report has none. The report is read as a regular file only (its figures are found
/// beside it): a pipe or a device is an error, not a wait.
pub fn figures(report: &Path, out: &Path) -> std::io::Result<Vec<Figure>> {
    let text = match nbody_engine::input::read_file_text(report) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e),
    };
    Ok(linked(report, &text, out))
}

/// The figures of the report at `report` (its `text`) that exist, linked from `out`.
fn linked(report: &Path, text: &str, out: &Path) -> Vec<Figure> {
    let (Some(base), Ok(out)) = (
        report
            .parent()
            .map(|p| {
                if p.as_os_str().is_empty() {
                    Path::new(".")
                } else {
                    p
                }
            })
            .and_then(|p| p.canonicalize().ok()),
        out.canonicalize(),
    ) else {
        return Vec::new();
    };
    let mut found: Vec<(PathBuf, Figure)> = Vec::new();
    for (title, target) in image_links(text) {
        // Only files of the repository, never a URL or an absolute path.
        if target.contains("://") || target.starts_with('/') {
            continue;
        }
        let Ok(file) = base.join(target).canonicalize() else {
            continue;
        };
        if !file.is_file() || found.iter().any(|(f, _)| *f == file) {
            continue;
        }
        let Some(href) = relative(&out, &file) else {
            continue;
        };
        found.push((
            file,
            Figure {
                title: title.to_string(),
                path: target.to_string(),
                href,
            },
        ));
    }
    found.into_iter().map(|(_, f)| f).collect()
}

/// The `(alt, target)` of every `![alt](target)` of a Markdown text.
fn image_links(text: &str) -> Vec<(&str, &str)> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(start) = rest.find("![") {
        rest = &rest[start + 2..];
        let Some(close) = rest.find("](") else { break };
        let alt = &rest[..close];
        let after = &rest[close + 2..];
        let Some(end) = after.find(')') else { break };
        if !alt.contains('\n') {
            out.push((alt, after[..end].trim()));
        }
        rest = &after[end..];
    }
    out
}

/// The path of `file` from the folder `from`, with `/` separators (both absolute, canonical).
fn relative(from: &Path, file: &Path) -> Option<String> {
    let a: Vec<Component> = from.components().collect();
    let b: Vec<Component> = file.components().collect();
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut parts: Vec<String> = vec!["..".to_string(); a.len() - common];
    for c in &b[common..] {
        parts.push(c.as_os_str().to_str()?.to_string());
    }
    Some(parts.join("/"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn existing_figures_are_linked_from_the_page_folder() {
        let dir = tempfile::tempdir().unwrap();
        let root = dir.path();
        std::fs::create_dir_all(root.join("results/a/analysis")).unwrap();
        std::fs::create_dir_all(root.join("results/history/page")).unwrap();
        std::fs::write(root.join("results/a/analysis/t.svg"), "<svg/>").unwrap();
        std::fs::write(
            root.join("REPORT.md"),
            "# R\n![time vs n](results/a/analysis/t.svg)\n![gone](results/a/analysis/x.svg)\n\
             ![again](results/a/analysis/t.svg) ![web](https://example.org/x.png)\n",
        )
        .unwrap();
        let found = figures(&root.join("REPORT.md"), &root.join("results/history/page")).unwrap();
        assert_eq!(
            found,
            [Figure {
                title: "time vs n".into(),
                path: "results/a/analysis/t.svg".into(),
                href: "../../a/analysis/t.svg".into()
            }]
        );
        assert!(figures(&root.join("missing.md"), root).unwrap().is_empty());
    }
}
