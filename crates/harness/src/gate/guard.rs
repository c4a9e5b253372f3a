//! A baseline never absorbs a regression silently. `gate --save-baseline` replaces a machine
//! class's baseline only after an A/B run of this build against the commit of the baseline it
//! replaces; [`decide`] turns that run's report and the user's `--accept CASE... --reason TEXT`
//! into saving or refusing. Once a slower baseline is committed, every later gate run judges
//! against it and the slowdown is never flagged again, so a regression goes into a baseline
//! only when each regressed case is named on purpose, with a reason that the history keeps.

use super::{GateReport, Judged, Verdict};
use thiserror::Error;

/// A case the A/B run found slower, with the ratio it was judged on.
#[derive(Clone, Debug, PartialEq)]
pub struct Regression {
    /// The case key, as the gate prints it.
    pub key: String,
    /// This build / the replaced baseline's commit: the ratio the verdict comes from (raw or
    /// normalised, as the report was judged).
    pub ratio: f64,
    /// Bootstrap 95% interval of that ratio ([low, high]).
    pub ci95: [f64; 2],
}

impl Regression {
    /// `key: 1.482x (95% CI 1.401-1.560)`, as refusals and progress lines name it.
    pub fn describe(&self) -> String {
        format!(
            "{}: {:.3}x (95% CI {:.3}-{:.3})",
            self.key, self.ratio, self.ci95[0], self.ci95[1]
        )
    }
}

/// What the user accepts in advance: `--accept CASE...` and `--reason TEXT`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Acceptance {
    /// Case keys whose regression may go into the baseline.
    pub cases: Vec<String>,
    /// Why, kept in the history beside the cases; required when `cases` is not empty.
    pub reason: Option<String>,
}

impl Acceptance {
    /// Whether nothing is accepted.
    pub fn is_empty(&self) -> bool {
        self.cases.is_empty()
    }

    /// Checks what can be checked before measuring: a reason with every acceptance, and every
    /// accepted key a case the A/B run measures (`cases`: the replaced baseline's), so that a
    /// typo costs no A/B run. The trimmed reason when something is accepted.
    pub fn check(&self, cases: &[String]) -> Result<Option<String>, GuardError> {
        let reason = self.reason.as_deref().map(str::trim);
        if self.cases.is_empty() {
            return match reason {
                Some(_) => Err(GuardError::ReasonWithoutAccept),
                None => Ok(None),
            };
        }
        let reason = match reason {
            Some(r) if !r.is_empty() => r.to_string(),
            _ => return Err(GuardError::NoReason),
        };
        let unknown: Vec<String> = self
            .cases
            .iter()
            .filter(|k| !cases.contains(k))
            .cloned()
            .collect();
        if !unknown.is_empty() {
            return Err(GuardError::NotACase {
                unknown,
                cases: cases.to_vec(),
            });
        }
        Ok(Some(reason))
    }
}

/// What to do with the new baseline.
#[derive(Clone, Debug, PartialEq)]
pub enum Decision {
    /// Replace the old baseline: nothing regressed, or every regressed case was accepted
    /// (`accepted` holds them, for the history).
    Save {
        /// The regressed cases the user accepted (empty when nothing regressed).
        accepted: Vec<Regression>,
    },
    /// Keep the old baseline: these cases regressed (all of them, accepted or not) and at
    /// least one was not accepted.
    Refuse {
        /// Every regressed case.
        regressed: Vec<Regression>,
        /// Those of them not accepted.
        unaccepted: Vec<String>,
    },
}

/// Why a save cannot be decided: bad input (exit 2), never a regression.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum GuardError {
    /// `--accept` without a reason, or with an empty one.
    #[error(
        "--accept needs --reason \"TEXT\": say why the slowdown is intended (the history keeps \
         it beside the cases)"
    )]
    NoReason,
    /// `--reason` without `--accept`: nothing to give a reason for.
    #[error("--reason is only for --accept CASE...: name the regressed cases it explains")]
    ReasonWithoutAccept,
    /// An accepted key is not a case the A/B run measures.
    #[error(
        "--accept {}: not a case the A/B run against the replaced baseline measures; its cases \
         are: {}",
        .unknown.join(", "),
        super::listed(.cases)
    )]
    NotACase {
        /// The accepted keys that are no case.
        unknown: Vec<String>,
        /// The case keys the A/B run measures.
        cases: Vec<String>,
    },
    /// An accepted case did not regress in the A/B run: accepting it would say something false.
    #[error(
        "--accept {}: did not regress in the A/B run, so there is nothing to accept; {}",
        .unknown.join(", "),
        regressed_list(.regressed)
    )]
    NotRegressed {
        /// The accepted keys that did not regress.
        unknown: Vec<String>,
        /// Every case that did.
        regressed: Vec<Regression>,
    },
    /// `--accept` while the class has no baseline yet: no A/B run, nothing can have regressed.
    #[error(
        "--accept: this machine class has no baseline yet, so nothing is compared and nothing \
         can have regressed; save without --accept"
    )]
    NothingToCompare,
    /// Baseline cases the A/B run could not compare: the run cannot vouch for them.
    #[error(
        "the A/B run could not compare {}, so it cannot vouch for the new baseline: {}",
        if .0.len() == 1 { "a case".to_string() } else { format!("{} cases", .0.len()) },
        super::listed(.0)
    )]
    Incomplete(Vec<String>),
}

fn regressed_list(regressed: &[Regression]) -> String {
    if regressed.is_empty() {
        return "no case regressed".to_string();
    }
    let named: Vec<String> = regressed.iter().map(Regression::describe).collect();
    format!("the regressed cases are: {}", named.join("; "))
}

/// Every regressed case of `report`, with the ratio its verdict was judged on (the raw one
/// when the run judged raw times, else the normalised one, as the history's verdicts record).
pub fn regressions(report: &GateReport) -> Vec<Regression> {
    let raw = report.judged_on == Judged::Raw;
    report
        .cases
        .iter()
        .filter(|c| c.verdict == Verdict::Regressed)
        .map(|c| Regression {
            key: c.key.clone(),
            ratio: if raw { c.raw_ratio } else { c.ratio },
            ci95: if raw { c.raw_ci95 } else { c.ci95 },
        })
        .collect()
}

/// Saving or refusing, from the A/B run's `report` and what `accept` names: a case it could not
/// compare, or an accepted case that did not regress, is bad input; a regressed case not
/// accepted refuses the save; otherwise it proceeds with the accepted regressions.
pub fn decide(report: &GateReport, accept: &[String]) -> Result<Decision, GuardError> {
    if !report.missing.is_empty() {
        let missing = report
            .missing
            .iter()
            .map(|m| format!("{} ({})", m.key, m.reason))
            .collect();
        return Err(GuardError::Incomplete(missing));
    }
    let regressed = regressions(report);
    let is_regressed = |key: &String| regressed.iter().any(|r| &r.key == key);
    let unknown: Vec<String> = accept
        .iter()
        .filter(|k| !is_regressed(k))
        .cloned()
        .collect();
    if !unknown.is_empty() {
        return Err(GuardError::NotRegressed { unknown, regressed });
    }
    let unaccepted: Vec<String> = regressed
        .iter()
        .filter(|r| !accept.contains(&r.key))
        .map(|r| r.key.clone())
        .collect();
    if unaccepted.is_empty() {
        Ok(Decision::Save {
            accepted: regressed,
        })
    } else {
        Ok(Decision::Refuse {
            regressed,
            unaccepted,
        })
    }
}

/// The refusal's message: every regressed case with its ratio and CI, that the old baseline
/// stays, and the command that accepts them.
pub fn refusal(
    regressed: &[Regression],
    unaccepted: &[String],
    baseline: &std::path::Path,
    commit: &str,
) -> String {
    let mut text = format!(
        "the new baseline is refused: {} case(s) regressed against {} (commit {}), measured \
         side by side with this build:\n",
        regressed.len(),
        baseline.display(),
        super::prefix(commit, 12)
    );
    for r in regressed {
        let mark = if unaccepted.contains(&r.key) {
            ""
        } else {
            "  (accepted)"
        };
        text += &format!("  {}{mark}\n", r.describe());
    }
    let keys: Vec<&str> = unaccepted.iter().map(String::as_str).collect();
    text += &format!(
        "{} is unchanged. Saving now would make these slowdowns the new normal and hide them \
         from every later gate run. Find the cause (nbody-bench bisect), or, if the slowdown is \
         intended, accept it by name:\n  scripts/refresh-baseline.sh --accept {} --reason \
         \"why it is slower\"\n(or the same --accept and --reason after gate --save-baseline \
         RESULTS); the acceptance is kept in the history's gate verdicts.",
        baseline.display(),
        keys.join(" ")
    );
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gate::paired::LogRatio;
    use crate::gate::{Normalization, RunInfo};

    fn info(commit: &str) -> RunInfo {
        RunInfo {
            git_commit: commit.into(),
            git_dirty: false,
            started: "2026-12-05T12:00:00Z".into(),
            host: String::new(),
            cpu_model: None,
            cpu_signature: Some("AuthenticAMD 26/2/1".into()),
            logical_cpus: Some(2),
        }
    }

    /// An A/B report judged on raw times, one case per `(key, verdict, raw ratio)`: the
    /// normalised ratio is set apart so that the one judged on is seen to be taken.
    fn synthetic_report(cases: &[(&str, Verdict, f64)]) -> GateReport {
        GateReport {
            schema: crate::gate::GATE_SCHEMA.into(),
            threshold: 0.03,
            fail_on_work_change: false,
            baseline: info("0123456789abcdef"),
            current: info("fedcba9876543210"),
            cases: cases
                .iter()
                .map(|&(key, verdict, ratio)| {
                    let estimate = |r: f64| LogRatio {
                        mean: r.ln(),
                        se: 0.01,
                        df: 7.0,
                        units: [8, 8],
                    };
                    let options = crate::gate::GateOptions::default();
                    let mut c = crate::gate::judged_case(
                        key,
                        Normalization::None,
                        estimate(ratio + 7.0),
                        estimate(ratio),
                        &options,
                    );
                    c.verdict = verdict;
                    c.baseline_median_s = 1e-3;
                    c.current_median_s = 1e-3 * ratio;
                    c.raw_ci95 = [ratio * 0.97, ratio * 1.03];
                    c.ci95 = [ratio + 6.9, ratio + 7.1];
                    c.samples = [8, 8];
                    c.work_compared = true;
                    c
                })
                .collect(),
            missing: vec![],
            extra: vec![],
            warnings: vec![],
            judged_on: Judged::Raw,
            family_alpha: 0.025,
            pairing: crate::gate::paired::Pairing::Rounds,
            looks: 1,
            sides: None,
        }
    }

    fn keys(v: &[Regression]) -> Vec<&str> {
        v.iter().map(|r| r.key.as_str()).collect()
    }

    const A: &str = "lj-box/naive/n=1000/p=1/r=1/seed=1";
    const B: &str = "lj-box/symmetric/n=1000/p=1/r=1/seed=1";
    const C: &str = "lj-box/cell-list/n=1000/p=1/r=1/seed=1";

    #[test]
    fn nothing_regressed_saves_and_accepts_nothing() {
        let report =
            synthetic_report(&[(A, Verdict::Unchanged, 1.01), (B, Verdict::Improved, 0.8)]);
        assert_eq!(
            decide(&report, &[]).unwrap(),
            Decision::Save { accepted: vec![] }
        );
    }

    #[test]
    fn an_unaccepted_regression_refuses_naming_every_regressed_case() {
        let report = synthetic_report(&[
            (A, Verdict::Regressed, 1.3),
            (B, Verdict::Regressed, 1.5),
            (C, Verdict::Unchanged, 1.0),
        ]);
        for accept in [vec![], vec![A.to_string()]] {
            let Decision::Refuse {
                regressed,
                unaccepted,
            } = decide(&report, &accept).unwrap()
            else {
                panic!("saved with {accept:?}");
            };
            assert_eq!(keys(&regressed), [A, B]);
            assert!(unaccepted.contains(&B.to_string()));
            assert_eq!(unaccepted.contains(&A.to_string()), accept.is_empty());
            let text = refusal(
                &regressed,
                &unaccepted,
                "b/ci-x.json".as_ref(),
                "0123456789abcdef",
            );
            assert!(text.contains(&format!("{B}: 1.500x (95% CI")), "{text}");
            assert!(text.contains(&format!("{A}: 1.300x")), "{text}");
            assert!(text.contains("0123456789ab"), "{text}");
            assert!(
                text.contains(&format!("--accept {}", unaccepted.join(" "))),
                "{text}"
            );
            assert!(text.contains("--reason"), "{text}");
        }
    }

    #[test]
    fn every_regression_accepted_saves_with_them() {
        let report = synthetic_report(&[
            (A, Verdict::Regressed, 1.3),
            (B, Verdict::Regressed, 1.5),
            (C, Verdict::Unchanged, 1.0),
        ]);
        let Decision::Save { accepted } = decide(&report, &[B.into(), A.into()]).unwrap() else {
            panic!("refused");
        };
        assert_eq!(keys(&accepted), [A, B]);
        assert_eq!(accepted[1].ratio, 1.5);
    }

    #[test]
    fn accepting_a_case_that_did_not_regress_is_bad_input_listing_the_regressed() {
        let report =
            synthetic_report(&[(A, Verdict::Regressed, 1.3), (C, Verdict::Unchanged, 1.0)]);
        for wrong in [C, "no/such/case"] {
            let e = decide(&report, &[A.into(), wrong.into()]).unwrap_err();
            assert_eq!(
                e,
                GuardError::NotRegressed {
                    unknown: vec![wrong.into()],
                    regressed: regressions(&report)
                }
            );
            let text = e.to_string();
            assert!(
                text.contains(wrong) && text.contains(&format!("{A}: 1.300x")),
                "{text}"
            );
        }
        let clean = synthetic_report(&[(C, Verdict::Unchanged, 1.0)]);
        let text = decide(&clean, &[C.into()]).unwrap_err().to_string();
        assert!(text.contains("no case regressed"), "{text}");
    }

    #[test]
    fn a_case_the_a_b_run_could_not_compare_is_not_vouched_for() {
        let mut report = synthetic_report(&[(A, Verdict::Unchanged, 1.0)]);
        report.missing.push(crate::gate::MissingCase {
            key: B.into(),
            reason: "too few samples".into(),
        });
        let e = decide(&report, &[]).unwrap_err();
        assert!(matches!(e, GuardError::Incomplete(_)));
        assert!(e.to_string().contains(B), "{e}");
    }

    #[test]
    fn an_acceptance_needs_a_reason_and_real_cases_before_anything_is_measured() {
        let cases = vec![A.to_string(), B.to_string()];
        let accept = |keys: &[&str], reason: Option<&str>| Acceptance {
            cases: keys.iter().map(|k| k.to_string()).collect(),
            reason: reason.map(str::to_string),
        };
        assert_eq!(accept(&[], None).check(&cases), Ok(None));
        assert_eq!(
            accept(&[B], Some(" a slower, exact kernel ")).check(&cases),
            Ok(Some("a slower, exact kernel".into()))
        );
        assert_eq!(accept(&[B], None).check(&cases), Err(GuardError::NoReason));
        assert_eq!(
            accept(&[B], Some("  ")).check(&cases),
            Err(GuardError::NoReason)
        );
        assert_eq!(
            accept(&[], Some("why")).check(&cases),
            Err(GuardError::ReasonWithoutAccept)
        );
        let e = accept(&[B, "lj-box/nave"], Some("why"))
            .check(&cases)
            .unwrap_err();
        assert_eq!(
            e,
            GuardError::NotACase {
                unknown: vec!["lj-box/nave".into()],
                cases: cases.clone()
            }
        );
        assert!(e.to_string().contains(A), "the cases are listed: {e}");
    }
}
