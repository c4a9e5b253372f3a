//! What the ranks of one MPI job must agree on before their first collective: the subcommand
//! with its arguments, and the build of the program. Ranks started with different arguments
//! (mpirun's MPMD form `-n 1 prog A : -n 1 prog B`, or a wrapper script that varies them) would
//! otherwise enter different collectives and hang, abort inside MPI, or quietly compute
//! different things. The digest here is MPI-free (and tested without MPI); the exchange that
//! compares it is `crate::mpi` (`same_job`).
//!
//! The digest has a fixed size ([`JobDigest::BYTES`]), so that the broadcast that compares it
//! cannot itself hang whatever the ranks were given.

use siphasher::sip128::{Hasher128, SipHasher};
use std::fmt;
use std::hash::Hasher;
use std::io::Read;

/// What one process was started to do.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Job {
    /// The subcommand and its parsed arguments in a canonical form: `--steps 3` and
    /// `--steps=3` give the same text, any difference in a value a different one.
    pub command: String,
    /// The command line as typed, for messages.
    pub typed: String,
}

/// The digest of a job: its command and its build, hashed separately so that a mismatch can
/// say which of the two differs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JobDigest {
    command: [u8; 16],
    build: [u8; 16],
}

/// Keys of the two hashes (any fixed values: the digest detects mistakes, not forgeries).
const COMMAND_KEYS: (u64, u64) = (0x6e62_6f64_792d_6a6f, 0x622d_636f_6d6d_616e);
const BUILD_KEYS: (u64, u64) = (0x6e62_6f64_792d_6275, 0x696c_642d_6964_656e);

fn hash(keys: (u64, u64), text: &str) -> [u8; 16] {
    SipHasher::new_with_keys(keys.0, keys.1)
        .hash(text.as_bytes())
        .as_bytes()
}

impl JobDigest {
    /// Bytes of [`JobDigest::to_bytes`], the same on every rank and for every job.
    pub(crate) const BYTES: usize = 32;

    /// The digest of `job` run by the build described by `build` (see [`build_identity`]).
    pub fn of(job: &Job, build: &str) -> Self {
        JobDigest {
            command: hash(COMMAND_KEYS, &job.command),
            build: hash(BUILD_KEYS, build),
        }
    }

    pub(crate) fn to_bytes(self) -> [u8; Self::BYTES] {
        let mut out = [0u8; Self::BYTES];
        out[..16].copy_from_slice(&self.command);
        out[16..].copy_from_slice(&self.build);
        out
    }

    pub(crate) fn from_bytes(bytes: [u8; Self::BYTES]) -> Self {
        let mut d = JobDigest {
            command: [0; 16],
            build: [0; 16],
        };
        d.command.copy_from_slice(&bytes[..16]);
        d.build.copy_from_slice(&bytes[16..]);
        d
    }

    /// How this digest differs from `other`'s: a set of [`Difference`] bits, 0 if it does not.
    pub fn differences(&self, other: &JobDigest) -> u8 {
        let mut bits = 0;
        if self.command != other.command {
            bits |= Difference::COMMAND;
        }
        if self.build != other.build {
            bits |= Difference::BUILD;
        }
        bits
    }
}

/// Bits of [`JobDigest::differences`].
pub struct Difference;

impl Difference {
    /// The ranks were given different commands or arguments.
    pub const COMMAND: u8 = 1;
    pub(crate) const BUILD: u8 = 2;

    /// The differences in words: "arguments", "build", or both.
    fn describe(bits: u8) -> &'static str {
        match (bits & Self::COMMAND != 0, bits & Self::BUILD != 0) {
            (true, true) => "arguments and build",
            (false, true) => "build",
            _ => "arguments",
        }
    }
}

/// What identifies this program's build: version, compiler, target, features and a hash of
/// the executable itself (two builds of one version differ; two copies of one build on
/// different nodes agree). Read once per MPI job with more than one rank.
pub(crate) fn build_identity() -> String {
    let mut features = Vec::new();
    if cfg!(feature = "mpi") {
        features.push("mpi");
    }
    let executable = std::env::current_exe()
        .and_then(|path| {
            let mut file = std::fs::File::open(path)?;
            let mut hasher = SipHasher::new_with_keys(BUILD_KEYS.0, BUILD_KEYS.1);
            let mut buf = vec![0u8; 1 << 20];
            loop {
                match file.read(&mut buf)? {
                    0 => break,
                    k => hasher.write(&buf[..k]),
                }
            }
            Ok(format!("{:032x}", hasher.finish128().as_u128()))
        })
        .unwrap_or_else(|e| format!("unreadable ({e})"));
    format!(
        "nbody-bench {} ({}; {}-{}; features [{}]; executable {executable})",
        env!("CARGO_PKG_VERSION"),
        nbody_engine::RUSTC_VERSION,
        std::env::consts::ARCH,
        std::env::consts::OS,
        features.join(", "),
    )
}

/// The ranks of a job that were not started with rank 0's job, as one rank sees it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mismatch {
    /// The rank that reports.
    pub rank: usize,
    /// Every rank's [`JobDigest::differences`] from rank 0 (0 for rank 0 and the ranks that
    /// agree with it).
    pub differences: Vec<u8>,
    /// This rank's command line as typed.
    pub typed: String,
    /// This rank's [`build_identity`].
    pub build: String,
}

impl Mismatch {
    /// Rank 0 names the ranks that differ; each of those says what it ran. The others stay
    /// quiet: they ran rank 0's job.
    pub fn printed(&self) -> bool {
        self.rank == 0 || self.differences.get(self.rank).is_some_and(|&d| d != 0)
    }
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const FIX: &str = "every rank of an MPI job must run the same build of nbody-bench with \
                           the same subcommand and arguments; check the mpirun command line";
        let mine = self.differences.get(self.rank).copied().unwrap_or(0);
        if self.rank != 0 && mine != 0 {
            return write!(
                f,
                "rank {} was not started with rank 0's job (different {}): it ran `{}` \
                 with {}; {FIX}",
                self.rank,
                Difference::describe(mine),
                self.typed,
                self.build
            );
        }
        let differing: Vec<String> = self
            .differences
            .iter()
            .enumerate()
            .filter(|&(_, &d)| d != 0)
            .map(|(r, &d)| format!("rank {r} (different {})", Difference::describe(d)))
            .collect();
        write!(
            f,
            "the MPI ranks were not started with the same job: {} of {} differ from rank 0, \
             which ran `{}` with {}; {FIX}",
            differing.join(", "),
            self.differences.len(),
            self.typed,
            self.build
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job(command: &str) -> Job {
        Job {
            command: command.into(),
            typed: command.into(),
        }
    }

    #[test]
    fn the_same_job_and_build_give_the_same_digest() {
        let a = JobDigest::of(&job("run steps=3"), "b1");
        let b = JobDigest::of(&job("run steps=3"), "b1");
        assert_eq!(a, b);
        assert_eq!(a.differences(&b), 0);
        assert_eq!(JobDigest::from_bytes(a.to_bytes()), a);
    }

    #[test]
    fn any_difference_changes_the_digest_and_says_which_part() {
        let a = JobDigest::of(&job("run steps=3"), "b1");
        let steps = JobDigest::of(&job("run steps=30"), "b1");
        let build = JobDigest::of(&job("run steps=3"), "b2");
        let both = JobDigest::of(&job("run steps=30"), "b2");
        assert_eq!(a.differences(&steps), Difference::COMMAND);
        assert_eq!(a.differences(&build), Difference::BUILD);
        assert_eq!(
            a.differences(&both),
            Difference::COMMAND | Difference::BUILD
        );
        assert_ne!(a.to_bytes(), steps.to_bytes());
        assert_ne!(a.to_bytes(), build.to_bytes());
    }

    #[test]
    fn the_build_identity_names_the_version_and_the_executable() {
        let id = build_identity();
        assert!(id.contains(env!("CARGO_PKG_VERSION")), "{id}");
        assert!(id.contains("executable "), "{id}");
        assert!(!id.contains("unreadable"), "{id}");
        assert_eq!(id, build_identity());
    }

    #[test]
    fn rank_0_names_the_ranks_that_differ_and_they_say_what_they_ran() {
        let differences = vec![0, Difference::COMMAND, 0, Difference::BUILD];
        let at = |rank: usize, typed: &str| Mismatch {
            rank,
            differences: differences.clone(),
            typed: typed.into(),
            build: "b".into(),
        };
        let root = at(0, "run --steps 3");
        assert!(root.printed());
        let text = root.to_string();
        assert!(
            text.contains(
                "rank 1 (different arguments), rank 3 (different build) of 4 differ from rank 0"
            ),
            "{text}"
        );
        assert!(text.contains("`run --steps 3`"), "{text}");
        let one = at(1, "run --steps 30");
        assert!(one.printed());
        let text = one.to_string();
        assert!(
            text.contains("rank 1 was not started with rank 0's job"),
            "{text}"
        );
        assert!(text.contains("`run --steps 30`"), "{text}");
        assert!(!at(2, "run --steps 3").printed());
    }
}
