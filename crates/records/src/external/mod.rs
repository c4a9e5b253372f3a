//! External programs in sweeps (`[[external]]`): their config ([`config`]), the placeholders
//! of their commands ([`placeholders`]), and what the results file keeps of them: each round's
//! runs with what they measured or why they failed, and each program's version line.

pub mod config;
pub mod placeholders;

pub use config::External;
pub use config::PhaseKind;
pub use config::TimeSource;

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The longest timeout a config may give a program: a week.
pub const MAX_TIMEOUT_S: f64 = 7.0 * 24.0 * 3600.0;

/// What one round of an external case measured, sample by sample (raw values).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ExternalRound {
    /// Every timed run, failed ones included, in order.
    pub runs: Vec<ExternalRun>,
    /// Median wall time of the empty run (wall timing only), seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub launch_overhead_s: Option<f64>,
    /// That overhead over the median successful run's wall time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overhead_share: Option<f64>,
    /// The set-up command failed: no sample was taken.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub setup_error: Option<SampleError>,
    /// Problems worth a reader's attention (launch overhead unknown or too large a share).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// One run of the program.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExternalRun {
    /// Wall time of the process, seconds.
    pub wall_s: f64,
    /// The time it printed (regex timing), seconds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reported_s: Option<f64>,
    /// The median (and largest) relative force error it printed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub force_error: Option<[f64; 2]>,
    /// The phases it printed (`phases`): each its time over the whole run, seconds.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub phases: BTreeMap<String, f64>,
    /// The relative change of the total energy it printed between its first and last match
    /// of `energy` (`None`: no `energy` pattern, or a start energy of zero).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub energy_drift: Option<f64>,
    /// Why the run is not a sample.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<SampleError>,
}

/// A failed run: what went wrong and the program's last lines of output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SampleError {
    /// What went wrong, as a sentence ("timed out after 600 s and was killed").
    pub what: String,
    /// The command line that ran, as a person would type it (for messages only).
    pub command: String,
    /// The last lines of its standard error, else of its standard output (at most 20).
    pub output_tail: Vec<String>,
}

/// An external's version line, in the results metadata.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ExternalVersion {
    /// The program's name in the config (`[[external]] name`).
    pub name: String,
    /// The first line its version command printed, or why there is none, in parentheses.
    pub version: String,
}
