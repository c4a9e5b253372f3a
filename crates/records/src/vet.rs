//! Measured values are checked where they enter a results file ([`CaseRecord`]'s rounds, new or
//! loaded): a value JSON cannot hold (NaN, ±inf: serde_json writes them as `null`, which no
//! reader then accepts) or one no measurement can give (a step of zero, negative or absurdly
//! long time, a negative force error) never reaches a summary or a saved file. A bad sample is
//! taken out of its round and kept as a [`Rejected`] entry with the reason, so nothing a program
//! printed is lost and every figure that remains is real.
//!
//! [`CaseRecord`]: super::results::CaseRecord

use super::external::ExternalRound;
use super::round::RoundOutcome;
use serde::{Deserialize, Serialize};

/// The longest time a step can take, seconds (about 116 days): a longer one is a unit or
/// parsing error, and would overflow the nanosecond figures derived from it.
pub(crate) const MAX_STEP_S: f64 = 1e7;
/// The shortest (a picosecond, under one clock cycle): a shorter one is a unit error, and the
/// rates derived from it (particle-steps per second) would overflow.
pub(crate) const MIN_STEP_S: f64 = 1e-12;

/// A value taken out of a round, and why.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Rejected {
    /// The round it came from (0-based).
    pub round: usize,
    /// What it was, e.g. `sample 3` or `force error`.
    pub what: String,
    /// The value as measured (text: it may be NaN or infinite).
    pub value: String,
    /// Why no measurement can give it, e.g. "not a finite number".
    pub reason: String,
}

/// `seconds` as a time per step, or why it cannot be one.
pub(crate) fn step_time(seconds: f64) -> Result<f64, String> {
    if !seconds.is_finite() {
        Err("not a finite number".into())
    } else if seconds <= 0.0 {
        Err("a step takes more than zero time".into())
    } else if seconds < MIN_STEP_S {
        Err(format!(
            "shorter than {MIN_STEP_S:e} s per step: a unit or parsing error"
        ))
    } else if seconds > MAX_STEP_S {
        Err(format!(
            "longer than {MAX_STEP_S:e} s per step: a unit or parsing error"
        ))
    } else {
        Ok(seconds)
    }
}

/// A relative force error `[median, max]`, or why it cannot be one.
pub fn force_error(e: [f64; 2]) -> Result<[f64; 2], String> {
    if !e.iter().all(|v| v.is_finite()) {
        Err("not a finite number".into())
    } else if e.iter().any(|&v| v < 0.0) {
        Err("a relative error is not negative".into())
    } else {
        Ok(e)
    }
}

/// `x` if finite, else 0: for secondary figures (phase times, clock overhead) whose loss
/// affects no sample.
fn finite_or_zero(x: &mut f64) {
    if !x.is_finite() {
        *x = 0.0;
    }
}

/// Takes every impossible value out of `round` (the `index`-th of its case), returning what was
/// taken out. Samples go with their reference timing (same order); a non-finite energy drift
/// becomes the largest finite number, so the sanity check flags the case instead of the file
/// losing it.
pub fn round(index: usize, round: &mut RoundOutcome) -> Vec<Rejected> {
    // An external program's round measured none of ours, whatever an older file wrote there.
    round.forget_unmeasured();
    let mut rejected = Vec::new();
    let paired = round.reference_s.len() == round.samples_s.len();
    let mut keep = Vec::with_capacity(round.samples_s.len());
    let mut reference = Vec::with_capacity(round.reference_s.len());
    for (i, &s) in round.samples_s.iter().enumerate() {
        match step_time(s) {
            Ok(s) => {
                keep.push(s);
                if paired {
                    reference.push(round.reference_s[i]);
                }
            }
            Err(reason) => rejected.push(Rejected {
                round: index,
                what: format!("sample {i}"),
                value: format!("{s:e} s per step"),
                reason,
            }),
        }
    }
    round.samples_s = keep;
    if paired {
        round.reference_s = reference;
    }
    // A reference timing is a time too; a bad one leaves its sample without a reference.
    if round.reference_s.iter().any(|r| step_time(*r).is_err()) {
        round.reference_s.clear();
    }
    if let Some(e) = round.force_error
        && let Err(reason) = force_error(e)
    {
        rejected.push(Rejected {
            round: index,
            what: "force error".into(),
            value: format!("{:e}, {:e}", e[0], e[1]),
            reason,
        });
        round.force_error = None;
    }
    if let Some(drift) = round.energy_drift
        && !drift.is_finite()
    {
        rejected.push(Rejected {
            round: index,
            what: "energy drift".into(),
            value: format!("{drift}"),
            reason: "not a finite number: the sanity check fails".into(),
        });
        round.energy_drift = Some(f64::MAX);
    }
    if let Some(external) = &mut round.external {
        rejected.extend(external_phases(index, external));
    }
    if let Some(p) = &mut round.phases {
        for x in [
            &mut p.force_build,
            &mut p.force_interact,
            &mut p.integrate,
            &mut p.boundary,
            &mut p.output,
        ] {
            finite_or_zero(x);
        }
    }
    finite_or_zero(&mut round.clock_overhead);
    rejected
}

/// A phase an external program printed, in seconds over its run of `run_s` seconds (wall), or
/// why it cannot be one: a phase is part of the run, so it is no longer than the run (with a
/// margin for the two clocks' readings and rounding in the printed number).
pub fn phase_time(seconds: f64, run_s: f64) -> Result<f64, String> {
    if !seconds.is_finite() {
        Err("not a finite number".into())
    } else if seconds < 0.0 {
        Err("a duration is not negative".into())
    } else if seconds > run_s * PHASE_MARGIN + PHASE_SLACK_S {
        Err(format!(
            "longer than the run it is part of ({run_s:.3e} s): a unit or parsing error"
        ))
    } else {
        Ok(seconds)
    }
}

/// How much longer than its run a printed phase may read: the program's clock and ours differ
/// by their readings, and the printed number is rounded.
const PHASE_MARGIN: f64 = 1.05;
const PHASE_SLACK_S: f64 = 0.01;

/// Takes out of every run the phases it cannot have taken (a file written before the runs were
/// checked, or edited): the analysis then averages the phase over the runs that keep it.
fn external_phases(index: usize, round: &mut ExternalRound) -> Vec<Rejected> {
    let mut rejected = Vec::new();
    for (i, run) in round.runs.iter_mut().enumerate() {
        let wall_s = run.wall_s;
        run.phases
            .retain(|name, &mut t| match phase_time(t, wall_s) {
                Ok(_) => true,
                Err(reason) => {
                    rejected.push(Rejected {
                        round: index,
                        what: format!("run {i}, phase `{name}`"),
                        value: format!("{t:e} s"),
                        reason,
                    });
                    false
                }
            });
    }
    rejected
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn impossible_times_and_errors_are_named() {
        assert_eq!(step_time(1e-6), Ok(1e-6));
        for bad in [f64::NAN, f64::INFINITY, -1.0, 0.0, 1e-300, 1e300] {
            assert!(step_time(bad).is_err(), "{bad}");
        }
        assert!(step_time(-0.0).unwrap_err().contains("more than zero"));
        assert_eq!(force_error([1e-4, 1e-3]), Ok([1e-4, 1e-3]));
        assert!(force_error([f64::NAN, 1.0]).is_err());
        assert!(force_error([1e-4, -1.0]).is_err());
        assert_eq!(phase_time(0.4, 0.5), Ok(0.4));
        assert_eq!(phase_time(0.0, 0.5), Ok(0.0));
        for bad in [100.0, f64::MAX, f64::INFINITY, f64::NAN, -1e-3] {
            assert!(phase_time(bad, 0.5).is_err(), "{bad}");
        }
        assert!(
            phase_time(100.0, 0.5)
                .unwrap_err()
                .contains("longer than the run")
        );
    }
}
