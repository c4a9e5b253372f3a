//! An external program that fails the same way on its first rounds (a wrong path, a missing
//! library, an option it does not take) would fail that way on every size and round that
//! follows, each after its own set-up and up to its timeout: the sweep stops running it and
//! says so, and its remaining rounds are left for `--resume` once the program is fixed.

use nbody_records::round::RoundOutcome;
use std::collections::HashMap;

/// Rounds of a program that must fail the same way, with no success before them, to stop it.
pub(crate) const SAME_FAILURES: usize = 2;

/// What each external program's rounds have done so far in this sweep.
#[derive(Default)]
pub(crate) struct FailureWatch {
    programs: HashMap<String, Program>,
}

#[derive(Default)]
struct Program {
    /// A round of it took a sample: its failures are then the case's, not the program's.
    succeeded: bool,
    /// Its latest failure and how many rounds in a row failed that way.
    last: Option<(String, usize)>,
    /// Stopped: its remaining rounds are not run.
    stopped: bool,
}

impl FailureWatch {
    /// Whether `program`'s rounds are no longer run.
    pub(crate) fn stopped(&self, program: &str) -> bool {
        self.programs.get(program).is_some_and(|p| p.stopped)
    }

    /// Notes a measured round of `program`; the failure it stopped on, when this round
    /// stops it.
    pub(crate) fn note(&mut self, program: &str, outcome: &RoundOutcome) -> Option<String> {
        let p = self.programs.entry(program.to_string()).or_default();
        if p.succeeded || p.stopped {
            return None;
        }
        let Some(why) = failure(outcome) else {
            p.succeeded = true;
            p.last = None;
            return None;
        };
        let count = match &p.last {
            Some((last, count)) if *last == why => count + 1,
            _ => 1,
        };
        p.last = Some((why.clone(), count));
        p.stopped = count >= SAME_FAILURES;
        p.stopped.then_some(why)
    }
}

/// Why a round of an external program took no sample, in words that do not depend on the
/// case (its command line, with n and the work directory in it, is left out), so that the
/// same fault at two sizes reads the same; `None` when it took one.
fn failure(outcome: &RoundOutcome) -> Option<String> {
    if !outcome.samples_s.is_empty() {
        return None;
    }
    let ext = outcome.external.as_ref()?;
    let error = ext
        .setup_error
        .as_ref()
        .map(|e| ("its set-up", e))
        .or_else(|| {
            ext.runs
                .iter()
                .find_map(|r| Some(("it", r.error.as_ref()?)))
        })?;
    let (who, e) = error;
    Some(match e.output_tail.last() {
        Some(line) => format!("{who} {}; last line: {line}", e.what),
        None => format!("{who} {}", e.what),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use nbody_records::external::{ExternalRound, ExternalRun, SampleError};

    fn round(sample: Option<f64>, what: &str, command: &str) -> RoundOutcome {
        let run = ExternalRun {
            wall_s: 0.1,
            reported_s: None,
            force_error: None,
            phases: Default::default(),
            energy_drift: None,
            error: sample.is_none().then(|| SampleError {
                what: what.into(),
                command: command.into(),
                output_tail: vec!["boom".into()],
            }),
        };
        RoundOutcome {
            steps_per_sample: 1,
            samples_s: sample.into_iter().collect(),
            step_ns: Vec::new(),
            steps: 1,
            warmup_steps: 0,
            phases: None,
            work: None,
            pairs_interacting: None,
            energy_drift: None,
            force_error: None,
            n: 50,
            clock_overhead: 0.0,
            reference_s: Vec::new(),
            initial_work: None,
            mpi: None,
            external: Some(ExternalRound {
                runs: vec![run],
                ..Default::default()
            }),
            job: None,
        }
    }

    #[test]
    fn the_same_failure_twice_stops_a_program_that_never_succeeded() {
        let mut w = FailureWatch::default();
        let fail = |n: &str| round(None, "failed (exit status: 3)", &format!("prog {n}"));
        assert_eq!(w.note("prog", &fail("50")), None);
        assert!(!w.stopped("prog"));
        let stopped = w.note("prog", &fail("100")).unwrap();
        assert_eq!(stopped, "it failed (exit status: 3); last line: boom");
        assert!(w.stopped("prog") && !w.stopped("other"));
    }

    #[test]
    fn different_failures_or_an_earlier_success_do_not_stop_it() {
        let mut w = FailureWatch::default();
        w.note("a", &round(None, "failed (exit status: 3)", "a"));
        w.note(
            "a",
            &round(None, "timed out after 600 s and was killed", "a"),
        );
        assert!(!w.stopped("a"));
        w.note("b", &round(Some(1e-3), "", "b"));
        for _ in 0..3 {
            w.note("b", &round(None, "failed (exit status: 3)", "b"));
        }
        assert!(!w.stopped("b"));
    }
}
