//! The base side of an A/B gate: the binary of another git revision, built once in a git
//! worktree of its own and cached.
//!
//! Layout, under `<target>/gate-base/` (`<target>` is `$CARGO_TARGET_DIR` or the checkout's
//! `target/`): `<commit>-<toolchain>/nbody-bench` is the cached binary of a commit built by one
//! toolchain (`rustc -vV` and `RUSTFLAGS`, hashed); `target/` is the
//! target directory every base build shares (so a second base revision recompiles only what
//! changed); `worktree-<commit>/` exists only while that commit builds.

use crate::children::supervised::{self as child, ChildError};
use crate::git::{self, Rev};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;
use thiserror::Error;

/// Longest a git command may take (a worktree of a large checkout takes seconds).
const GIT_LIMIT: Duration = Duration::from_secs(300);
/// Longest the base revision's release build may take: a fresh build takes 1-10 minutes on
/// the 2-vCPU CI machines, so a build past an hour is stuck.
pub const BUILD_LIMIT: Duration = Duration::from_secs(3600);
/// Longest `rustc -vV` may take.
const RUSTC_LIMIT: Duration = Duration::from_secs(60);

/// Why the base revision's binary cannot be had.
#[derive(Debug, Error)]
pub enum BaseBuildError {
    /// The directory is not inside a git checkout, or git cannot be run.
    #[error(
        "the A/B gate builds the base revision with git, and {0}; run it inside a git \
         checkout of the project"
    )]
    NoRepository(String),
    /// The base revision does not resolve to a commit in this clone (often a shallow one).
    #[error(
        "base revision `{rev}` is not in this clone ({detail}); a shallow clone lacks older \
         commits: fetch them (git fetch --unshallow, or git fetch origin {rev}) or pass \
         --against a revision that is present"
    )]
    MissingRevision {
        /// The revision as given, e.g. `origin/main`.
        rev: String,
        /// Why git does not know it: the clone is shallow, or no such revision.
        detail: String,
    },
    /// The base revision is not one git may be given (it would be read as an option).
    #[error("the base revision {0}; pass --against a revision that is")]
    NotARevision(String),
    /// Git could not add the worktree the base revision is built in.
    #[error("cannot prepare the base revision {commit}: {detail}")]
    Worktree {
        /// Full hash of the base commit.
        commit: String,
        /// Git's error text.
        detail: String,
    },
    /// `cargo build --release` of the base revision failed or timed out.
    #[error(
        "the base revision {commit} does not build (cargo build --release; the log is {log}):\n{tail}"
    )]
    Build {
        /// Full hash of the base commit.
        commit: String,
        /// The build's log, `build.log` in the commit's cache directory.
        log: PathBuf,
        /// The last lines of the log, or why the build did not run.
        tail: String,
    },
    /// A directory or file of the build cache could not be created, copied or renamed.
    #[error("cannot write the base build's files under {path}: {source}")]
    Io {
        /// The directory or file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// A base binary ready to run.
#[derive(Clone, Debug)]
pub struct BaseBinary {
    /// The full commit hash.
    pub commit: String,
    /// The cached binary, `<target>/gate-base/<commit>-<toolchain>/nbody-bench`.
    pub path: PathBuf,
    /// It was built by this call (not taken from the cache).
    pub built: bool,
    /// Seconds spent building (0 when cached).
    pub build_s: f64,
}

/// Runs git with `args` and the revisions `revs` in `dir`; its trimmed standard output, or
/// its error text.
fn git(dir: &Path, args: &[&str], revs: &[&Rev]) -> Result<String, String> {
    run_git(git::command(dir, args, revs), args)
}

/// Runs a git command (`args` name it in messages), bounded by [`GIT_LIMIT`].
fn run_git(mut command: Command, args: &[&str]) -> Result<String, String> {
    let what = format!("`git {}`", args.join(" "));
    let out = child::output(&mut command, GIT_LIMIT, &what, "").map_err(|e| e.to_string())?;
    if out.status.success() {
        Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).trim().to_string())
    }
}

/// The root of the git checkout that contains `dir`.
pub fn repository_root(dir: &Path) -> Result<PathBuf, BaseBuildError> {
    git(dir, &["rev-parse", "--show-toplevel"], &[])
        .map(PathBuf::from)
        .map_err(|e| {
            BaseBuildError::NoRepository(format!("{} is not in a git checkout: {e}", dir.display()))
        })
}

/// The full hash of `rev` in `repo`.
pub fn resolve(repo: &Path, rev: &str) -> Result<String, BaseBuildError> {
    let given = Rev::given(rev).map_err(BaseBuildError::NotARevision)?;
    git(
        repo,
        &["rev-parse", "--verify", "--quiet"],
        &[&given.commit()],
    )
    .ok()
    .filter(|hash| !hash.is_empty())
    .ok_or_else(|| BaseBuildError::MissingRevision {
        rev: rev.to_string(),
        detail: if Path::new(&repo.join(".git/shallow")).exists() {
            "the clone is shallow".to_string()
        } else {
            "git rev-parse does not know it".to_string()
        },
    })
}

/// Where base builds live: `$CARGO_TARGET_DIR/gate-base`, else `<repo>/target/gate-base`.
pub fn cache_root(repo: &Path) -> PathBuf {
    std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .map(|t| if t.is_absolute() { t } else { repo.join(t) })
        .unwrap_or_else(|| repo.join("target"))
        .join("gate-base")
}

/// Whether `commit`'s binary, built by the toolchain at hand, is in the cache (no build
/// needed).
pub fn is_cached(repo: &Path, commit: &str) -> bool {
    cache_root(repo)
        .join(cache_key(commit))
        .join("nbody-bench")
        .is_file()
}

/// The binary of `commit`, from the cache or built now; `progress` hears what happens.
pub fn base_binary(
    repo: &Path,
    commit: &str,
    progress: &mut dyn FnMut(&str),
) -> Result<BaseBinary, BaseBuildError> {
    // The commit names the cache's folders and reaches git: a hash and nothing else.
    let rev = Rev::recorded(commit)
        .ok_or_else(|| BaseBuildError::NotARevision(format!("`{commit}` is not a commit hash")))?;
    let root = cache_root(repo);
    // One cached binary per commit and toolchain: a compiler upgrade between two gate runs
    // must not have the old compiler's base measured against the new one's build.
    let key = cache_key(commit);
    let cached = root.join(&key).join("nbody-bench");
    if cached.is_file() {
        return Ok(BaseBinary {
            commit: commit.to_string(),
            path: cached,
            built: false,
            build_s: 0.0,
        });
    }
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| BaseBuildError::Io { path, source }
    };
    nbody_engine::output::create_dir_all(root.join(&key)).map_err(io(&root.join(&key)))?;
    let worktree = root.join(format!("worktree-{commit}"));
    let worktree_error = |detail: String| BaseBuildError::Worktree {
        commit: commit.to_string(),
        detail,
    };
    // A worktree left by an interrupted build is stale: forget it and start again.
    let remove = || {
        let mut c = Command::new("git");
        c.arg("-C").arg(repo);
        c.args(["worktree", "remove", "--force", "--end-of-options"]);
        c.arg(&worktree);
        let _ = run_git(c, &["worktree", "remove"]);
    };
    remove();
    let _ = std::fs::remove_dir_all(&worktree);
    let _ = git(repo, &["worktree", "prune"], &[]);
    run_git(
        git::worktree_add(repo, &worktree, &rev),
        &["worktree", "add"],
    )
    .map_err(worktree_error)?;

    progress(&format!(
        "building the base revision {} in {} (cached for later runs)",
        super::prefix(commit, 12),
        worktree.display()
    ));
    let started = std::time::Instant::now();
    let log = root.join(&key).join("build.log");
    let result = build(&worktree, &root.join("target"), &log);
    remove();
    let _ = std::fs::remove_dir_all(&worktree);
    let built = result.map_err(|tail| BaseBuildError::Build {
        commit: commit.to_string(),
        log: log.clone(),
        tail,
    })?;
    // Copy, then rename: a cached binary is always whole.
    let partial = root.join(&key).join(".nbody-bench.partial");
    std::fs::copy(&built, &partial).map_err(io(&partial))?;
    std::fs::rename(&partial, &cached).map_err(io(&cached))?;
    Ok(BaseBinary {
        commit: commit.to_string(),
        path: cached,
        built: true,
        build_s: started.elapsed().as_secs_f64(),
    })
}

/// Makes the worktree at `dir` a workspace of its own. The worktree lies inside the checkout
/// (under its target folder), and cargo looks upwards for a workspace: a commit whose manifest
/// has no `[workspace]` table (the project before it had member crates) would be taken for a
/// stray member of the checkout's workspace and refused. The throwaway worktree's manifest gets
/// an empty table.
fn own_workspace(dir: &Path) -> Result<(), String> {
    let manifest = dir.join("Cargo.toml");
    let text = std::fs::read_to_string(&manifest)
        .map_err(|e| format!("cannot read {}: {e}", manifest.display()))?;
    if text.lines().any(|l| l.trim() == "[workspace]") {
        return Ok(());
    }
    std::fs::write(&manifest, format!("{text}\n[workspace]\n"))
        .map_err(|e| format!("cannot write {}: {e}", manifest.display()))
}

/// The cache directory name of `commit` built by the toolchain at hand.
pub fn cache_key(commit: &str) -> String {
    format!("{commit}-{}", toolchain_key())
}

/// A short hash of what else decides the base binary: `rustc -vV` and `RUSTFLAGS`.
fn toolchain_key() -> String {
    let rustc = std::env::var_os("RUSTC").unwrap_or_else(|| "rustc".into());
    let version = child::output(Command::new(rustc).arg("-vV"), RUSTC_LIMIT, "rustc -vV", "")
        .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
        .unwrap_or_default();
    let flags = std::env::var("RUSTFLAGS").unwrap_or_default();
    // FNV-1a: stable across runs and platforms, unlike the standard hasher.
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in version.bytes().chain([0]).chain(flags.bytes()) {
        h = (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
    }
    format!("{:08x}", h >> 32)
}

/// `cargo build --release` of the checkout in `dir` into `target`, output to `log`; the
/// binary's path, or the last lines of the log.
fn build(dir: &Path, target: &Path, log: &Path) -> Result<PathBuf, String> {
    own_workspace(dir)?;
    let file =
        std::fs::File::create(log).map_err(|e| format!("cannot create {}: {e}", log.display()))?;
    let err_file = file
        .try_clone()
        .map_err(|e| format!("cannot write {}: {e}", log.display()))?;
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let status = child::status(
        Command::new(cargo)
            .args(["build", "--release", "--bin", "nbody-bench"])
            .current_dir(dir)
            .env("CARGO_TARGET_DIR", target)
            .stdout(file)
            .stderr(err_file),
        BUILD_LIMIT,
        "the base revision's build",
        "a release build takes minutes, not an hour: look for what it waits on in the log",
    )
    .map_err(|e: ChildError| e.to_string())?;
    let binary = target.join("release").join("nbody-bench");
    if status.success() && binary.is_file() {
        Ok(binary)
    } else {
        let text = std::fs::read_to_string(log).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        Err(lines[lines.len().saturating_sub(15)..].join("\n"))
    }
}

#[cfg(test)]
mod tests {
    use super::own_workspace;

    #[test]
    fn a_manifest_without_a_workspace_gets_one_and_another_is_left_alone() {
        let dir = tempfile::tempdir().unwrap();
        let manifest = dir.path().join("Cargo.toml");
        std::fs::write(&manifest, "[package]\nname = \"old\"\n").unwrap();
        own_workspace(dir.path()).unwrap();
        let once = std::fs::read_to_string(&manifest).unwrap();
        assert_eq!(once, "[package]\nname = \"old\"\n\n[workspace]\n");
        own_workspace(dir.path()).unwrap();
        assert_eq!(std::fs::read_to_string(&manifest).unwrap(), once);
        assert!(own_workspace(&dir.path().join("missing")).is_err());
    }
}
