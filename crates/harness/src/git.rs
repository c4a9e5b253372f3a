//! Revisions handed to git. A commit read from a results or history file (`git_commit`) and
//! a revision a user types (`--base`, `--against`, a bisection's GOOD and BAD, a backfill's
//! range) reach git's command line; one that starts with `-` would be read as an option, and
//! `--output=FILE` makes `git show` overwrite FILE. So git receives a revision only as a
//! [`Rev`], which is checked when it is made (a recorded commit is hexadecimal, a typed
//! revision does not start with `-`), and only through [`command`], which puts every revision
//! after `--end-of-options` (git 2.24 and later), where git reads nothing as an option.

use std::path::Path;
use std::process::Command;

/// A revision git may be given.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rev(String);

/// Hex digits in a commit as the project records it: git abbreviates to 4 at the least, a
/// SHA-256 object name has 64.
const HEX_DIGITS: std::ops::RangeInclusive<usize> = 4..=64;

impl Rev {
    /// A revision as a user typed it (`HEAD~3`, `origin/main`, `v1.2`, a hash): refused when
    /// it is empty, starts with `-` or holds white space or control characters, which no
    /// revision name has; `Err` says why, naming it.
    pub fn given(text: &str) -> Result<Rev, String> {
        let why = if text.is_empty() {
            "is empty"
        } else if text.starts_with('-') {
            "starts with `-`, as an option does"
        } else if text.chars().any(|c| c.is_whitespace() || c.is_control()) {
            "holds white space or control characters"
        } else {
            return Ok(Rev(text.to_string()));
        };
        Err(format!(
            "`{}` is not a revision: it {why}; give a commit hash, a branch, a tag or a \
             revision such as HEAD~3",
            nbody_engine::output::neutral::control::visible(text)
        ))
    }

    /// A commit as a file records it: 4 to 64 hexadecimal digits; `None` for anything else
    /// (`unknown` outside a git checkout, or text that is not a commit at all).
    pub fn recorded(text: &str) -> Option<Rev> {
        (HEX_DIGITS.contains(&text.len()) && text.chars().all(|c| c.is_ascii_hexdigit()))
            .then(|| Rev(text.to_string()))
    }

    /// `A..B`: the commits after `from` up to `to`.
    pub fn range(from: &Rev, to: &Rev) -> Rev {
        Rev(format!("{}..{}", from.0, to.0))
    }

    /// The commit this revision names (`REV^{commit}`: a tag peeled to its commit).
    pub fn commit(&self) -> Rev {
        Rev(format!("{}^{{commit}}", self.0))
    }

    /// The first parent of this revision's commit (`REV^`).
    pub fn parent(&self) -> Rev {
        Rev(format!("{}^", self.0))
    }

    /// The revision as git reads it.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Display for Rev {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// `A..B` as a user typed it, both sides checked as in [`Rev::given`].
pub fn given_range(text: &str) -> Result<(Rev, Rev), String> {
    match text.split_once("..") {
        Some((from, to)) if !from.is_empty() && !to.is_empty() && !to.starts_with('.') => {
            Ok((Rev::given(from)?, Rev::given(to)?))
        }
        _ => Err(format!(
            "`{}` is not a range: give A..B (the commits after A up to B)",
            nbody_engine::output::neutral::control::visible(text)
        )),
    }
}

/// `git -C repo ARGS --end-of-options REVS`: `args` are the command and its options (the
/// caller's own words), `revs` its revisions, which git then cannot read as options. With no
/// revision there is no `--end-of-options` (`rev-parse` would echo it as an argument).
pub fn command(repo: &Path, args: &[&str], revs: &[&Rev]) -> Command {
    let mut c = Command::new("git");
    c.arg("-C").arg(repo).args(args);
    if !revs.is_empty() {
        c.arg("--end-of-options");
        c.args(revs.iter().map(|r| r.as_str()));
    }
    c
}

/// `git -C repo worktree add --detach --force --end-of-options PATH REV`: a detached
/// worktree of `rev` at `path`, replacing a stale one.
pub fn worktree_add(repo: &Path, path: &Path, rev: &Rev) -> Command {
    let mut c = Command::new("git");
    c.arg("-C").arg(repo);
    c.args(["worktree", "add", "--detach", "--force", "--end-of-options"]);
    c.arg(path).arg(rev.as_str());
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typed_revisions_that_git_would_read_as_options_are_refused() {
        for ok in [
            "HEAD~3",
            "origin/main",
            "v1.2",
            "abc1234",
            "HEAD^",
            "main@{1}",
        ] {
            assert_eq!(Rev::given(ok).unwrap().as_str(), ok);
        }
        for bad in ["--output=/tmp/x", "-p", "", "a b", "a\u{1b}b"] {
            let e = Rev::given(bad).unwrap_err();
            assert!(e.contains("is not a revision"), "{e}");
        }
        assert!(Rev::given("a\u{1b}b").unwrap_err().contains("a\\u{1b}b"));
    }

    #[test]
    fn only_hexadecimal_commits_are_taken_from_files() {
        let full = "46b82584afc6edb5204b2979b9a0833e74fba15a";
        assert_eq!(Rev::recorded(full).unwrap().as_str(), full);
        assert!(Rev::recorded("46b8").is_some());
        for bad in [
            "--output=/tmp/x",
            "unknown",
            "",
            "46b",
            "HEAD",
            &"a".repeat(65),
        ] {
            assert_eq!(Rev::recorded(bad), None, "{bad}");
        }
    }

    #[test]
    fn ranges_are_checked_side_by_side() {
        let (a, b) = given_range("v1..HEAD").unwrap();
        assert_eq!(Rev::range(&a, &b).as_str(), "v1..HEAD");
        assert!(given_range("HEAD").is_err());
        assert!(given_range("..HEAD").is_err());
        assert!(given_range("v1...HEAD").is_err());
        assert!(given_range("--output=x..HEAD").unwrap_err().contains("`-`"));
    }

    #[test]
    fn revisions_come_after_the_end_of_the_options() {
        let r = Rev::recorded("abcd1234").unwrap();
        let c = command(Path::new("/repo"), &["show", "-s", "--format=%cI"], &[&r]);
        let args: Vec<_> = c
            .get_args()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            args,
            [
                "-C",
                "/repo",
                "show",
                "-s",
                "--format=%cI",
                "--end-of-options",
                "abcd1234"
            ]
        );
        let c = command(Path::new("/repo"), &["rev-parse", "--show-toplevel"], &[]);
        assert_eq!(c.get_args().count(), 4);
    }
}
