//! The `[scheduler]` table of a sweep config (run each case round as a batch job, today through
//! Slurm) and what a round's results keep of its job.

use serde::{Deserialize, Serialize};
use std::time::Duration;

crate::config_keys::documented_keys! {
    /// How a sweep submits its work to a batch system.
    #[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
    #[serde(deny_unknown_fields)]
    pub struct Scheduler {
        /// The batch system.
        ///
        /// Accepts "slurm".
        ///
        /// Example: `kind = "slurm"`
        pub kind: SchedulerKind,
        /// `sbatch --partition` (when left out: the cluster's default).
        ///
        /// Accepts a partition name, such as partition = "short".
        ///
        /// Example: `partition = "short"`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub partition: Option<String>,
        /// `sbatch --account` (when left out: the user's default).
        ///
        /// Accepts an account name, such as account = "proj42".
        ///
        /// Example: `account = "proj42"`
        #[serde(default, skip_serializing_if = "Option::is_none")]
        pub account: Option<String>,
        /// `sbatch --time` of each job; the sweep waits for a running job this long plus a margin
        /// (10 minutes; NBODY_BENCH_JOB_GRACE_S), then stops for --resume.
        ///
        /// Accepts a Slurm time limit per job, above zero: minutes, MM:SS, HH:MM:SS or
        /// D-HH[:MM[:SS]], such as time_limit = "10:00".
        ///
        /// Example: `time_limit = "10:00"`
        #[serde(default = "default_time_limit")]
        pub time_limit: String,
        /// More `sbatch` arguments, given to every job.
        ///
        /// Accepts a list of strings, such as sbatch_args = ["--qos=short"].
        ///
        /// Example: `sbatch_args = ["--qos=short"]`
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        pub sbatch_args: Vec<String>,
        /// Seconds between two looks at the queue while a job waits or runs.
        ///
        /// Accepts seconds above 0, at most 3600, such as poll_s = 5.
        ///
        /// Example: `poll_s = 5`
        #[serde(default = "default_poll_s")]
        pub poll_s: f64,
    }
}

/// The batch systems a sweep can submit to (`kind`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SchedulerKind {
    /// Slurm: jobs are submitted with `sbatch` and followed with `squeue` and `scontrol`.
    Slurm,
}

fn default_time_limit() -> String {
    "30:00".into()
}

fn default_poll_s() -> f64 {
    2.0
}

impl Scheduler {
    /// Checks what can be checked before a submission; `(key, problem)` on failure.
    pub(crate) fn validate(&self) -> Result<(), (String, String)> {
        if !valid_time_limit(&self.time_limit) {
            return Err((
                "scheduler.time_limit".into(),
                format!(
                    "is `{}`: give minutes, MM:SS, HH:MM:SS or D-HH[:MM[:SS]], such as \"10:00\"",
                    self.time_limit
                ),
            ));
        }
        if self.time_limit().is_some_and(|t| t.is_zero()) {
            return Err((
                "scheduler.time_limit".into(),
                format!(
                    "is `{}`: a limit of zero asks Slurm for no limit, and the sweep bounds its \
                     wait for a job by it; give one, such as \"10:00\"",
                    self.time_limit
                ),
            ));
        }
        if !(self.poll_s.is_finite() && self.poll_s > 0.0 && self.poll_s <= 3600.0) {
            return Err((
                "scheduler.poll_s".into(),
                format!("is {}: give seconds above 0, at most 3600", self.poll_s),
            ));
        }
        for (key, value) in [("partition", &self.partition), ("account", &self.account)] {
            if let Some(v) = value
                && (v.is_empty() || v.chars().any(|c| c.is_whitespace() || c == '\0'))
            {
                return Err((
                    format!("scheduler.{key}"),
                    format!("is `{v}`: it must be one word"),
                ));
            }
        }
        if let Some(a) = self.sbatch_args.iter().find(|a| a.contains('\0')) {
            return Err((
                "scheduler.sbatch_args".into(),
                format!("has a NUL byte in `{}`", a.escape_default()),
            ));
        }
        Ok(())
    }
}

impl Scheduler {
    /// The time limit of each job (Slurm's forms: "M", "M:S", "H:M:S", "D-H", "D-H:M",
    /// "D-H:M:S"); `None` if it is not in one of them.
    pub fn time_limit(&self) -> Option<Duration> {
        if !valid_time_limit(&self.time_limit) {
            return None;
        }
        let numbers =
            |s: &str| -> Option<Vec<u64>> { s.split(':').map(|p| p.parse::<u64>().ok()).collect() };
        let seconds = match self.time_limit.split_once('-') {
            Some((days, rest)) => {
                let d: u64 = days.parse().ok()?;
                let [h, m, s] = match numbers(rest)?.as_slice() {
                    [h] => [*h, 0, 0],
                    [h, m] => [*h, *m, 0],
                    [h, m, s] => [*h, *m, *s],
                    _ => return None,
                };
                ((d * 24 + h) * 60 + m) * 60 + s
            }
            None => match numbers(&self.time_limit)?.as_slice() {
                [m] => m * 60,
                [m, s] => m * 60 + s,
                [h, m, s] => (h * 60 + m) * 60 + s,
                _ => return None,
            },
        };
        Some(Duration::from_secs(seconds))
    }
}

/// Slurm's time forms: "M", "M:S", "H:M:S", "D-H", "D-H:M", "D-H:M:S" (whole numbers).
fn valid_time_limit(t: &str) -> bool {
    let numbers = |s: &str, most: usize| {
        let parts: Vec<&str> = s.split(':').collect();
        parts.len() <= most
            && parts
                .iter()
                .all(|p| !p.is_empty() && p.len() <= 9 && p.bytes().all(|b| b.is_ascii_digit()))
    };
    match t.split_once('-') {
        Some((days, rest)) => numbers(days, 1) && numbers(rest, 3),
        None => numbers(t, 3) && t != "0",
    }
}

/// The batch job that measured a round (or failed to).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JobRecord {
    /// The scheduler's job id.
    pub id: String,
    /// The node it ran on (its host name), when it started.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub node: Option<String>,
    /// Its final state as the scheduler gave it (COMPLETED, FAILED, TIMEOUT, CANCELLED, ...),
    /// when known.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<String>,
    /// Why the round has no samples: the job ended without a result.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<JobError>,
}

/// A job that ended without a result, with the last lines of its output.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct JobError {
    /// What happened: the job id, its final state and why its `result.json` is missing or refused.
    pub what: String,
    /// The last lines of the job's output file (`job.out`); empty if it cannot be read.
    pub output_tail: Vec<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slurm_time_forms_are_accepted_and_others_refused() {
        for ok in ["30", "10:00", "1:00:00", "1-0", "2-12:30", "1-00:00:30"] {
            assert!(valid_time_limit(ok), "{ok}");
        }
        for bad in [
            "",
            "0",
            "1h",
            "1:2:3:4",
            "-1",
            "1-",
            "1-2:3:4:5",
            "a:b",
            "1.5",
        ] {
            assert!(!valid_time_limit(bad), "{bad}");
        }
    }

    #[test]
    fn time_limits_are_read_as_slurm_reads_them() {
        let limit = |t: &str| {
            Scheduler {
                kind: SchedulerKind::Slurm,
                partition: None,
                account: None,
                time_limit: t.into(),
                sbatch_args: Vec::new(),
                poll_s: 1.0,
            }
            .time_limit()
            .map(|d| d.as_secs())
        };
        for (t, s) in [
            ("30", 1800),
            ("10:00", 600),
            ("0:1", 1),
            ("1:00:00", 3600),
            ("1-0", 86_400),
            ("2-12:30", 2 * 86_400 + 12 * 3600 + 1800),
            ("1-00:00:30", 86_430),
        ] {
            assert_eq!(limit(t), Some(s), "{t}");
        }
        assert_eq!(limit("1h"), None);
        assert_eq!(limit("0:0"), Some(0));
        let zero = Scheduler {
            kind: SchedulerKind::Slurm,
            partition: None,
            account: None,
            time_limit: "0:00:00".into(),
            sbatch_args: Vec::new(),
            poll_s: 1.0,
        };
        let (key, problem) = zero.validate().unwrap_err();
        assert_eq!(key, "scheduler.time_limit");
        assert!(problem.contains("no limit"), "{problem}");
    }
}
