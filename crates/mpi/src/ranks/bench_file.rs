//! The results file of `nbody-bench mpi-bench`: raw timings of point-to-point messages and of
//! Allgatherv over message sizes, from which the analysis fits the α-β model
//! (`t = α + β · bytes`) and predicts communication at rank counts beyond the machine.
//! Layout in `docs/howto/run-mpi-studies.md`.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use thiserror::Error;

pub(crate) const MPI_BENCH_SCHEMA: &str = "nbody-bench/mpi-bench/v1";

/// An `mpi-bench` results file: who ran it where, and the two timing series.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MpiBenchFile {
    /// Always `nbody-bench/mpi-bench/v1` in a file this version loads.
    pub schema: String,
    /// The nbody-bench version that wrote the file.
    pub tool_version: String,
    /// `git rev-parse HEAD` where it ran; "unknown" outside a git checkout.
    pub git_commit: String,
    /// UTC, ISO 8601.
    pub started: String,
    /// Ranks in the run.
    pub ranks: usize,
    /// Rank 0's processor name, and every rank's.
    pub host: String,
    /// Every rank's processor name, by rank.
    pub hosts: Vec<String>,
    /// The MPI library's version string and the MPI standard version it implements.
    pub mpi_library: String,
    /// The MPI standard version, "major.minor".
    pub mpi_standard: String,
    /// Logical CPUs of rank 0's machine.
    pub logical_cpus: usize,
    /// More ranks than logical CPUs: timings include time-sharing of the CPUs.
    pub oversubscribed: bool,
    /// The Open MPI byte-transfer layers the run was restricted to (`OMPI_MCA_btl`, e.g.
    /// `tcp,self`); absent when the library chose (shared memory between ranks of one node).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub transport: Option<String>,
    /// Ranks 0 and 1 (on the first two slots): one-way time of a message of `bytes`, taken as
    /// half the round trip of a ping-pong.
    pub ping_pong: Series,
    /// All ranks: time of one `MPI_Allgatherv` in which every rank contributes `bytes`
    /// (the slowest rank's time; the ranks start together after a barrier).
    pub allgatherv: Series,
}

/// Timings of one operation over message sizes.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Series {
    /// What a timing is, in words.
    pub definition: String,
    /// Ranks taking part.
    pub ranks: usize,
    /// Untimed repetitions before the timed ones, per size.
    pub warmup: usize,
    /// One entry per message size, smallest first.
    pub points: Vec<SizeTimings>,
}

/// Every timed repetition at one message size.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SizeTimings {
    /// The message size, bytes (per rank, for Allgatherv).
    pub bytes: u64,
    /// Each timed repetition, seconds (finite and >= 0 in a loaded file).
    pub seconds: Vec<f64>,
}

/// Why an `mpi-bench` file could not be loaded; every variant names the file.
#[derive(Debug, Error)]
pub enum BenchFileError {
    /// The file could not be read (missing, unreadable, not UTF-8).
    #[error("cannot read {path}: {source}")]
    Read {
        /// The mpi-bench file.
        path: PathBuf,
        /// The I/O error reading it.
        source: std::io::Error,
    },
    /// The text is not JSON, not the file's shape, or has a missing or impossible timing.
    #[error(
        "{path} is not a valid mpi-bench file ({detail}); it may be truncated or from another tool"
    )]
    Corrupt {
        /// The mpi-bench file.
        path: PathBuf,
        /// What is wrong, from the JSON parser or the timing check.
        detail: String,
    },
    /// The file's `schema` is not this version's ("(none)" when it has none).
    #[error("{path} has schema `{found}`, this version reads `{MPI_BENCH_SCHEMA}`")]
    Schema {
        /// The mpi-bench file.
        path: PathBuf,
        /// The schema it declares.
        found: String,
    },
}

/// The byte-transfer layers this process's MPI runs were restricted to, if any.
pub(crate) fn transport_from_env() -> Option<String> {
    std::env::var("OMPI_MCA_btl")
        .ok()
        .filter(|v| !v.trim().is_empty())
}

impl MpiBenchFile {
    /// Whether the run went over TCP (`--mca btl tcp,self`).
    pub fn over_tcp(&self) -> bool {
        self.transport
            .as_deref()
            .is_some_and(|t| t.split(',').any(|l| l.trim() == "tcp"))
    }

    /// Reads and checks an mpi-bench file ([`MpiBenchFile::parse`]).
    pub fn load(path: &Path) -> Result<MpiBenchFile, BenchFileError> {
        let text = crate::input::read_text(path).map_err(|source| BenchFileError::Read {
            path: path.into(),
            source,
        })?;
        Self::parse(&text, path)
    }

    /// Parses and checks file text; `path` is only used in messages.
    pub fn parse(text: &str, path: &Path) -> Result<MpiBenchFile, BenchFileError> {
        let corrupt = |detail: String| BenchFileError::Corrupt {
            path: path.into(),
            detail,
        };
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| corrupt(e.to_string()))?;
        let found = value
            .get("schema")
            .and_then(|s| s.as_str())
            .unwrap_or("(none)");
        if found != MPI_BENCH_SCHEMA {
            return Err(BenchFileError::Schema {
                path: path.into(),
                found: found.into(),
            });
        }
        let file: MpiBenchFile =
            serde_json::from_value(value).map_err(|e| corrupt(e.to_string()))?;
        for (name, series) in [
            ("ping_pong", &file.ping_pong),
            ("allgatherv", &file.allgatherv),
        ] {
            for p in &series.points {
                if p.seconds.is_empty() || p.seconds.iter().any(|s| !(s.is_finite() && *s >= 0.0)) {
                    return Err(corrupt(format!(
                        "{name} at {} bytes: timings must be finite, non-negative and present",
                        p.bytes
                    )));
                }
            }
        }
        Ok(file)
    }
}

/// Messages up to this size get the full repetition count.
const FULL_REPS_UP_TO: u64 = 64 * 1024;

/// 1, 4, 16, … up to `max`.
pub fn sizes(max: u64) -> Vec<u64> {
    std::iter::successors(Some(1u64), |s| s.checked_mul(4))
        .take_while(|&s| s <= max.max(1))
        .collect()
}

/// Timed repetitions at message size `bytes`.
pub(crate) fn reps_at(bytes: u64, reps: usize) -> usize {
    let scaled = reps as u64 * FULL_REPS_UP_TO / bytes.max(FULL_REPS_UP_TO);
    (scaled as usize).max(10.min(reps)).max(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_and_repetitions() {
        assert_eq!(sizes(64), vec![1, 4, 16, 64]);
        assert_eq!(sizes(100), vec![1, 4, 16, 64]);
        assert_eq!(sizes(0), vec![1]);
        assert_eq!(reps_at(8, 200), 200);
        assert_eq!(reps_at(256 * 1024, 200), 50);
        assert_eq!(reps_at(64 << 20, 200), 10);
        assert_eq!(reps_at(64 << 20, 3), 3);
    }

    fn sample() -> MpiBenchFile {
        let series = |ranks| Series {
            definition: "test".into(),
            ranks,
            warmup: 2,
            points: vec![
                SizeTimings {
                    bytes: 8,
                    seconds: vec![1e-6, 1.1e-6],
                },
                SizeTimings {
                    bytes: 1 << 20,
                    seconds: vec![1e-4],
                },
            ],
        };
        MpiBenchFile {
            schema: MPI_BENCH_SCHEMA.into(),
            tool_version: "0.1.0".into(),
            git_commit: "abc".into(),
            started: "2026-01-01T00:00:00Z".into(),
            ranks: 4,
            host: "h".into(),
            hosts: vec!["h".into(); 4],
            mpi_library: "Open MPI v4.1.4".into(),
            mpi_standard: "3.1".into(),
            logical_cpus: 2,
            oversubscribed: true,
            transport: None,
            ping_pong: series(2),
            allgatherv: series(4),
        }
    }

    #[test]
    fn a_tcp_run_says_so() {
        let mut b = sample();
        assert!(!b.over_tcp());
        b.transport = Some("tcp,self".into());
        assert!(b.over_tcp());
        b.transport = Some("self,vader".into());
        assert!(!b.over_tcp());
    }

    #[test]
    fn round_trips_and_refuses_bad_files() {
        let path = Path::new("b.json");
        let file = sample();
        let text = serde_json::to_string(&file).unwrap();
        assert_eq!(MpiBenchFile::parse(&text, path).unwrap(), file);
        let other = text.replace(MPI_BENCH_SCHEMA, "nbody-bench/results/v1");
        assert!(matches!(
            MpiBenchFile::parse(&other, path),
            Err(BenchFileError::Schema { .. })
        ));
        assert!(matches!(
            MpiBenchFile::parse(&text[..text.len() / 2], path),
            Err(BenchFileError::Corrupt { .. })
        ));
        let mut bad = sample();
        bad.allgatherv.points[1].seconds = vec![];
        let text = serde_json::to_string(&bad).unwrap();
        let err = MpiBenchFile::parse(&text, path).unwrap_err().to_string();
        assert!(err.contains("allgatherv at 1048576 bytes"), "{err}");
    }
}
