//! The tables a sweep prints: before it, the planned cases with their estimates (`--dry-run`);
//! when it ends, each case's time per step, and the speedup of each multi-thread case over its
//! one-thread twin, raw and against the calibrated ceiling (the throughput ratio of an
//! embarrassingly parallel loop at the same thread count).

use super::tables::{Align, NONE, Table};
use crate::analysis::forking::{self, OneThread};
use crate::experiment::estimate::Estimate;
use crate::units::{Duration, WallTime};
use nbody_records::config::SweepConfig;
use nbody_records::results::ResultsFile;

/// The planned cases: the built-in kernels' with their estimated step and case times, then
/// the external programs', which are not estimated (the steps of one run stand in the step's
/// column).
pub fn plan(config: &SweepConfig, est: &Estimate) -> Table {
    let r = Align::Right;
    let header = [
        "case",
        "n",
        "p",
        "ranks",
        "theta",
        "rounds",
        "samples",
        "step (est.)",
        "case (est.)",
    ];
    let mut t = Table::new(header).aligned([Align::Default, r, r, r, r, r, r, r, r]);
    let theta = |t: Option<f64>| t.map_or("-".to_string(), |t| t.to_string());
    for c in &est.cases {
        t.row([
            c.case.key(),
            c.case.n.to_string(),
            c.case.threads.to_string(),
            c.case.ranks.to_string(),
            theta(c.case.theta),
            c.rounds.to_string(),
            c.samples.to_string(),
            Duration(c.step_s).to_string(),
            WallTime(c.wall_s).to_string(),
        ]);
    }
    for c in external_cases(config) {
        let tried = est.external.iter().find(|e| e.case.key() == c.key());
        let steps = config
            .external
            .iter()
            .find(|e| e.name == c.kernel.name())
            .map_or("-".to_string(), |e| {
                format!("{} steps", crate::experiment::external::run::steps(e, &c))
            });
        if let Some(e) = tried {
            t.row([
                c.key(),
                c.n.to_string(),
                c.threads.to_string(),
                c.ranks.to_string(),
                theta(c.theta),
                e.rounds.to_string(),
                e.samples.to_string(),
                format!("{} ({steps})", Duration(e.step_s)),
                WallTime(e.wall_s).to_string(),
            ]);
            continue;
        }
        t.row([
            c.key(),
            c.n.to_string(),
            c.threads.to_string(),
            c.ranks.to_string(),
            theta(c.theta),
            config.measure.rounds.to_string(),
            config.measure.samples.to_string(),
            steps,
            "external".to_string(),
        ]);
    }
    t
}

/// The cases of `config` that run external programs.
pub fn external_cases(config: &SweepConfig) -> Vec<nbody_records::plan::Case> {
    let all = nbody_records::plan::cases(config);
    all.into_iter().filter(|c| c.kernel.is_external()).collect()
}

/// Every case of `results`: median time per step with its 95% interval, ns per particle-step,
/// pair evaluations per second and the energy check.
pub fn cases(results: &ResultsFile) -> Table {
    let right = Align::Right;
    let mut t = Table::new([
        "case",
        "per step",
        "95% CI",
        "ns/p-step",
        "pairs/s",
        "sanity",
        "",
    ])
    .aligned([
        Align::Default,
        right,
        right,
        right,
        right,
        right,
        Align::Default,
    ]);
    for c in &results.cases {
        let Some(s) = &c.summary else {
            let what = match c.failed() {
                true => "FAILED: no sample succeeded",
                false => "not measured",
            };
            t.row([c.key.as_str(), what, "", "", "", "", ""]);
            continue;
        };
        t.row([
            c.key.clone(),
            Duration(s.median_s).to_string(),
            format!("[{}, {}]", Duration(s.ci95_s[0]), Duration(s.ci95_s[1])),
            format!("{:.1}", s.ns_per_particle_step),
            // An external program counts no pairs and checks no energy: "–", not 0 or "ok".
            s.pair_evals_per_s
                .map_or(NONE.to_string(), |r| format!("{r:.2e}")),
            match s.sanity_ok {
                Some(true) => "ok",
                Some(false) => "DRIFT",
                None => NONE,
            }
            .to_string(),
            (if c.oversubscribed {
                "(oversubscribed)"
            } else {
                ""
            })
            .to_string(),
        ]);
    }
    t
}

/// A multi-thread case against the same case on one thread.
#[derive(Clone, Debug, PartialEq)]
pub struct Speedup {
    /// The multi-thread case's key.
    pub key: String,
    /// Its threads.
    pub threads: usize,
    /// One-thread median over this case's median.
    pub speedup: f64,
    /// The calibrated parallel ceiling at these threads, when measured.
    pub ceiling: Option<f64>,
    /// More threads than logical CPUs: not a parallel measurement.
    pub oversubscribed: bool,
    /// Why the case ran on one thread although given several; `None` when it forked (or the
    /// work counters cannot tell).
    pub one_thread: Option<OneThread>,
}

/// Each multi-thread case with a measured one-thread twin, in the results' order.
pub fn speedups(results: &ResultsFile) -> Vec<Speedup> {
    let calibration = results.calibration.start.as_ref();
    let mut out = Vec::new();
    for c in results.cases.iter().filter(|c| c.case.threads > 1) {
        let mut one = c.case.clone();
        one.threads = 1;
        let twin = results.cases.iter().find(|o| o.case == one);
        let base = twin.and_then(|o| o.summary.as_ref());
        let (Some(base), Some(s)) = (base, c.summary.as_ref()) else {
            continue;
        };
        if s.median_s > 0.0 {
            out.push(Speedup {
                key: c.key.clone(),
                threads: c.case.threads,
                speedup: base.median_s / s.median_s,
                ceiling: calibration.and_then(|cal| cal.ceiling(c.case.threads)),
                oversubscribed: c.oversubscribed,
                one_thread: c.case.kernel.kernel().and_then(|k| {
                    // An external program counts no pairs: nothing to decide on.
                    s.pair_evals_per_s?;
                    forking::one_thread(k, c.case.threads, c.case.ranks, s.pair_checks_per_step?)
                }),
            });
        }
    }
    out
}

/// The speedups as a table: raw, per thread (efficiency), and over the ceiling.
pub fn speedups_table(speedups: &[Speedup]) -> Table {
    let right = Align::Right;
    let header = [
        "speedup over the same case on 1 thread",
        "raw",
        "eff.",
        "/ceiling",
        "ceiling",
        "",
    ];
    let mut t =
        Table::new(header).aligned([Align::Default, right, right, right, right, Align::Default]);
    for s in speedups {
        let ceiling = s.ceiling.filter(|h| *h > 0.0);
        t.row([
            s.key.clone(),
            format!("{:.2}x", s.speedup),
            format!("{:.2}", s.speedup / s.threads as f64),
            ceiling.map_or(NONE.to_string(), |h| format!("{:.2}", s.speedup / h)),
            ceiling.map_or(NONE.to_string(), |h| format!("{h:.2}x")),
            note(s),
        ]);
    }
    t
}

/// The last column of a speedup's row: what keeps it from being a parallel speedup.
fn note(s: &Speedup) -> String {
    let mut notes: Vec<&str> = s.one_thread.iter().map(|o| o.label()).collect();
    if s.oversubscribed {
        notes.push("oversubscribed: not a parallel measurement");
    }
    notes.join("; ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed results of `configs/quick.toml`.
    fn quick() -> ResultsFile {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../results/quick/results.json"
        );
        ResultsFile::load(std::path::Path::new(path)).unwrap()
    }

    /// The committed results of `configs/seeds.toml` (n from 500, where steps are too small
    /// to fork).
    fn seeds() -> ResultsFile {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../results/seeds/results.json"
        );
        ResultsFile::load(std::path::Path::new(path)).unwrap()
    }

    #[test]
    fn speedups_are_against_the_one_thread_twin_and_the_ceiling() {
        let results = quick();
        let found = speedups(&results);
        assert!(!found.is_empty(), "quick has 2-thread cases");
        for s in &found {
            let twin = s.key.replace("/p=2/", "/p=1/");
            let median = |key: &str| {
                let case = results.cases.iter().find(|c| c.key == key).unwrap();
                case.summary.as_ref().unwrap().median_s
            };
            assert_eq!(s.threads, 2);
            assert_eq!(s.speedup, median(&twin) / median(&s.key));
        }
        let text = speedups_table(&found).text();
        assert_eq!(text.lines().count(), found.len() + 1);
        // Quick's n = 2000 forks, symmetric never does, and the cell list's counters tell
        // nothing.
        let label =
            |found: &[Speedup], key: &str| found.iter().find(|s| s.key == key).unwrap().one_thread;
        let key = |kernel: &str, n: usize| format!("lj-box/{kernel}/n={n}/p=2/r=1/seed=1");
        assert_eq!(
            label(&found, &key("symmetric", 2000)),
            Some(OneThread::SerialKernel)
        );
        assert_eq!(label(&found, &key("naive", 2000)), None);
        assert_eq!(label(&found, &key("per-thread", 2000)), None);
        assert_eq!(label(&found, &key("cell-list", 2000)), None);
        assert!(
            text.starts_with("speedup over the same case on 1 thread"),
            "{text}"
        );
        // The seeds' n = 500 is under the fork threshold: naive and per-thread say so.
        let small = speedups(&seeds());
        assert_eq!(label(&small, &key("naive", 500)), Some(OneThread::TooSmall));
        assert_eq!(
            label(&small, &key("per-thread", 500)),
            Some(OneThread::TooSmall)
        );
        assert_eq!(label(&small, &key("cell-list", 500)), None);
        let row = speedups_table(&small)
            .text()
            .lines()
            .find(|l| l.starts_with(&key("naive", 500)))
            .unwrap()
            .to_string();
        assert!(
            row.ends_with("ran on 1 thread (too small to fork)"),
            "{row}"
        );
    }

    #[test]
    fn every_case_has_a_row_and_a_missing_value_is_a_dash() {
        let results = quick();
        let text = cases(&results).text();
        assert_eq!(text.lines().count(), results.cases.len() + 1);
        assert!(
            text.lines()
                .skip(1)
                .all(|l| l.contains("ok") || l.contains('–')),
            "{text}"
        );
    }
}
