//! Running external programs in sweeps (`[[external]]`, configured as
//! [`nbody_records::external`] says): one process ([`process`]) and one measured round
//! ([`run`]). Each sample is one run of the program; what it measured, or why it failed, is
//! kept with the round in the results file.

pub mod process;
pub mod run;
pub mod trial;

use nbody_records::external::{External, ExternalVersion, placeholders};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A launch overhead above this share of a sample's wall time is warned about.
pub(crate) const OVERHEAD_WARN: f64 = 0.05;
/// The version command is killed after this many seconds.
const VERSION_TIMEOUT_S: f64 = 30.0;

/// Why an external program's case could not be run (a failed run is a sample's error, not this).
#[derive(Debug, Error)]
pub enum ExternalError {
    /// A program the entry names (its command, set-up, version or empty command, or the MPI
    /// launcher) is not an executable file, checked before the sweep starts.
    #[error(
        "external `{name}`: program `{program}` not found{where_}: {why}; install it (for the peers of \
         configs/vs-*.toml: scripts/install-peers.sh) or fix `command` (or the PATH its `env` \
         sets)"
    )]
    NotFound {
        /// The `[[external]]` entry's `name`.
        name: String,
        /// The program as written, placeholders substituted.
        program: String,
        /// Empty for the `command`, else which field named it, e.g. " (its `setup`)".
        where_: String,
        /// Why it cannot be started, from [`process::resolve`].
        why: String,
    },
    /// A placeholder in the command, set-up or `env` could not be substituted for the case.
    #[error("external `{name}`: {source}")]
    Placeholder {
        /// The `[[external]]` entry's `name`.
        name: String,
        /// Which placeholder and why.
        source: placeholders::PlaceholderError,
    },
    /// One of the entry's regular expressions (check, time, force error, phases) is invalid.
    #[error("external `{name}`: the regular expression `{regex}` does not compile: {source}")]
    Regex {
        /// The `[[external]]` entry's `name`.
        name: String,
        /// The expression as written.
        regex: String,
        /// The regex crate's error.
        source: regex::Error,
    },
    /// A case's work directory, under the results' `work/`, could not be created.
    #[error("cannot create the work directory {path}: {source}")]
    Workdir {
        /// The directory.
        path: PathBuf,
        /// The system's error.
        source: std::io::Error,
    },
}

/// Where externals find the sweep: the config's directory and this program (a batch job
/// reads it from its task file).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct Context {
    /// What `{config_dir}` stands for in commands: absolute, the current directory by default.
    pub config_dir: PathBuf,
    /// What `{nbody_bench}` stands for: this program, absolute (a batch job runs it too).
    pub nbody_bench: PathBuf,
    /// Case work directories are made under this one.
    pub(crate) work_root: PathBuf,
    /// The config's `initial` file of bodies, resolved: the built-in kernels' cases start from it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) initial: Option<PathBuf>,
    /// Its bodies as read before the sweep started (the ones its fingerprint describes), for the
    /// cases measured in this process.
    #[serde(skip)]
    pub(crate) bodies: Option<std::sync::Arc<nbody_engine::scenario::initial::InitialBodies>>,
}

impl Context {
    pub(crate) fn vars(&self) -> placeholders::Vars {
        placeholders::Vars::sweep(&self.config_dir, &self.nbody_bench)
    }
}

/// Checks that every program a case would start can be started, before anything runs: the
/// same [`process::resolve`] that each launch uses, with the `PATH` the program's `env` sets.
pub(crate) fn check_programs(
    ext: &External,
    launcher: Option<&str>,
    context: &Context,
) -> Result<(), ExternalError> {
    let vars = context.vars();
    // `None`: the env sets PATH from a case placeholder, known only per case.
    let path = match ext.env.get("PATH").map(|p| vars.substitute(p)) {
        None => Some(None),
        Some(Ok(p)) => Some(Some(p)),
        Some(Err(_)) => None,
    };
    let mut programs: Vec<(&str, String, Option<&str>)> = Vec::new();
    for (field, tokens) in [
        ("command", &ext.command),
        ("setup", &ext.setup),
        ("version", &ext.version),
        ("empty", &ext.empty),
    ] {
        let Some(first) = tokens.first() else {
            continue;
        };
        // A program named by a case placeholder ({workdir}/prog) is only known per case.
        let Ok(program) = vars.substitute(first) else {
            continue;
        };
        // The version command runs without the env.
        match (field, &path) {
            ("version", _) => programs.push((field, program, None)),
            (_, Some(p)) => programs.push((field, program, p.as_deref())),
            (_, None) => {}
        }
    }
    if let (Some(l), Some(p)) = (launcher, &path) {
        programs.push(("[mpi] launcher", l.to_string(), p.as_deref()));
    }
    for (field, program, path) in programs {
        if let Err(why) = process::resolve(&program, path) {
            return Err(ExternalError::NotFound {
                name: ext.name.clone(),
                program,
                where_: if field == "command" {
                    String::new()
                } else {
                    format!(" (its `{field}`)")
                },
                why,
            });
        }
    }
    Ok(())
}

/// The first line the version command prints (standard output, else standard error), or why
/// there is none.
pub(crate) fn version_line(ext: &External, context: &Context) -> ExternalVersion {
    let version = if ext.version.is_empty() {
        "(no version command)".to_string()
    } else {
        match context.vars().substitute_all(&ext.version) {
            Err(e) => format!("(version command: {e})"),
            Ok(argv) => {
                let dir = context.work_root.join(format!("version-{}", ext.name));
                let launch = process::Launch { argv, env: vec![] };
                match nbody_engine::output::create_dir_all(&dir)
                    .and_then(|()| process::run(&launch, &dir, VERSION_TIMEOUT_S))
                {
                    Err(e) => format!("(`{}` failed: {e})", launch.display()),
                    Ok(done) => (done.stdout.text + &done.stderr.text)
                        .lines()
                        .map(str::trim)
                        .find(|l| !l.is_empty())
                        .unwrap_or("(no output)")
                        .to_string(),
                }
            }
        }
    };
    ExternalVersion {
        name: ext.name.clone(),
        version,
    }
}

/// The work directory of a case: `<work_root>/<key with '/' as '_'>`.
pub fn workdir(root: &Path, key: &str) -> PathBuf {
    root.join(key.replace('/', "_"))
}
