//! The placeholders of external commands: `{n}`, `{threads}`, ... replaced inside argv tokens
//! and environment values. Nothing goes through a shell: a token stays one argument whatever
//! characters it holds. `{{` and `}}` stand for literal braces.

use std::collections::BTreeMap;
use std::path::Path;
use thiserror::Error;

/// Placeholders that depend on the case.
pub(crate) const CASE_PLACEHOLDERS: [&str; 8] = [
    "n", "threads", "ranks", "steps", "seed", "theta", "scenario", "workdir",
];
/// Placeholders known before any case (the only ones `version` may use).
pub(crate) const SWEEP_PLACEHOLDERS: [&str; 2] = ["config_dir", "nbody_bench"];

/// Why a command token's placeholders cannot be replaced; each names the token as written.
#[derive(Debug, Error, PartialEq)]
pub enum PlaceholderError {
    /// A `{name}` that is not a placeholder, or not one available there (a case's in `version`).
    #[error("`{token}` has an unknown placeholder `{{{name}}}`; known: {known}")]
    Unknown {
        /// The token as written in the config.
        token: String,
        /// The name between the braces.
        name: String,
        /// The placeholders allowed there, braced and space-separated.
        known: String,
    },
    /// A `{` with no `}` after it.
    #[error("`{token}` has an unclosed `{{`; write `{{{{` for a literal brace")]
    Unclosed {
        /// The token as written in the config.
        token: String,
    },
    /// A `}` that closes nothing and is not doubled.
    #[error("`{token}` has a lone `}}`; write `}}}}` for a literal brace")]
    LoneClose {
        /// The token as written in the config.
        token: String,
    },
}

/// Values of the placeholders.
#[derive(Clone, Debug, Default)]
pub struct Vars {
    values: BTreeMap<&'static str, String>,
}

impl Vars {
    /// The placeholders known before any case.
    pub fn sweep(config_dir: &Path, nbody_bench: &Path) -> Vars {
        let mut v = Vars::default();
        v.values
            .insert("config_dir", config_dir.display().to_string());
        v.values
            .insert("nbody_bench", nbody_bench.display().to_string());
        v
    }

    /// Adds or replaces a value (`name` must be one of the placeholders).
    pub fn set(&mut self, name: &'static str, value: impl ToString) -> &mut Vars {
        debug_assert!(CASE_PLACEHOLDERS.contains(&name) || SWEEP_PLACEHOLDERS.contains(&name));
        self.values.insert(name, value.to_string());
        self
    }

    /// `token` with every placeholder replaced.
    pub fn substitute(&self, token: &str) -> Result<String, PlaceholderError> {
        expand(token, &mut |name| self.values.get(name).cloned()).map_err(|e| match e {
            PlaceholderError::Unknown { token, name, .. } => PlaceholderError::Unknown {
                token,
                name,
                known: self
                    .values
                    .keys()
                    .map(|k| format!("{{{k}}}"))
                    .collect::<Vec<_>>()
                    .join(" "),
            },
            other => other,
        })
    }

    /// Every token of a command with its placeholders replaced; the first error otherwise.
    pub fn substitute_all(&self, tokens: &[String]) -> Result<Vec<String>, PlaceholderError> {
        tokens.iter().map(|t| self.substitute(t)).collect()
    }
}

/// The placeholder names `token` uses, checked against `known`.
pub fn check(token: &str, known: &[&str]) -> Result<Vec<String>, PlaceholderError> {
    let mut used = Vec::new();
    expand(token, &mut |name| {
        known.contains(&name).then(|| {
            used.push(name.to_string());
            String::new()
        })
    })
    .map_err(|e| match e {
        PlaceholderError::Unknown { token, name, .. } => PlaceholderError::Unknown {
            token,
            name,
            known: known
                .iter()
                .map(|k| format!("{{{k}}}"))
                .collect::<Vec<_>>()
                .join(" "),
        },
        other => other,
    })?;
    Ok(used)
}

fn expand(
    token: &str,
    value: &mut dyn FnMut(&str) -> Option<String>,
) -> Result<String, PlaceholderError> {
    let mut out = String::with_capacity(token.len());
    let mut rest = token;
    while let Some(i) = rest.find(['{', '}']) {
        out.push_str(&rest[..i]);
        let tail = &rest[i..];
        if let Some(after) = tail.strip_prefix("{{") {
            out.push('{');
            rest = after;
        } else if let Some(after) = tail.strip_prefix("}}") {
            out.push('}');
            rest = after;
        } else if tail.starts_with('}') {
            return Err(PlaceholderError::LoneClose {
                token: token.into(),
            });
        } else {
            let Some(end) = tail.find('}') else {
                return Err(PlaceholderError::Unclosed {
                    token: token.into(),
                });
            };
            let name = &tail[1..end];
            match value(name) {
                Some(v) => out.push_str(&v),
                None => {
                    return Err(PlaceholderError::Unknown {
                        token: token.into(),
                        name: name.into(),
                        known: String::new(),
                    });
                }
            }
            rest = &tail[end + 1..];
        }
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placeholders_are_replaced_inside_tokens() {
        let mut v = Vars::sweep(Path::new("/cfg"), Path::new("/bin/nb"));
        v.set("n", 1000).set("workdir", "/w");
        assert_eq!(
            v.substitute("{workdir}/gas-{n}.data").unwrap(),
            "/w/gas-1000.data"
        );
        assert_eq!(v.substitute("{{n}} $(x); {n}").unwrap(), "{n} $(x); 1000");
        assert!(matches!(
            v.substitute("{steps}"),
            Err(PlaceholderError::Unknown { name, .. }) if name == "steps"
        ));
        assert!(matches!(
            v.substitute("{n"),
            Err(PlaceholderError::Unclosed { .. })
        ));
        assert!(matches!(
            v.substitute("a}b"),
            Err(PlaceholderError::LoneClose { .. })
        ));
    }

    #[test]
    fn check_lists_the_names_used() {
        assert_eq!(
            check("-var t {threads}x{n}", &CASE_PLACEHOLDERS).unwrap(),
            vec!["threads", "n"]
        );
        let e = check("{config_dir}", &CASE_PLACEHOLDERS).unwrap_err();
        assert!(e.to_string().contains("{config_dir}"), "{e}");
    }
}
