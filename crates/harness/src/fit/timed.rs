//! The serial fraction measured the way the Barnes-Hut report does: time the phases of a one-worker run
//! that stay serial, divide by the total, and compare with the serial fraction fitted to the
//! speedups. The fitted one is usually larger: the gap is the cost of running in parallel
//! (synchronisation, communication, memory contention) that a one-worker run does not have and
//! so cannot time, unless the machine was shared: then time-sharing with other processes is in
//! the gap too, and the comparison says so instead of naming any cost of the code.

use super::{Estimate, FitError, SharedMachine};
use serde::Serialize;

/// `f_timed = Σ serial / (Σ serial + Σ parallelisable)` of a one-worker run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct TimedSerialFraction {
    pub(crate) serial_s: f64,
    pub(crate) parallel_s: f64,
    /// The one-worker run's time, serial plus parallelisable phases, seconds.
    pub total_s: f64,
    /// The timed serial fraction, serial time over total, in [0, 1].
    pub fraction: f64,
}

/// The timed and the fitted serial fraction side by side.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub(crate) struct SerialFractionComparison {
    pub timed: f64,
    pub fitted: Estimate,
    /// `fitted − timed`, a fraction of the one-worker time.
    pub gap: f64,
    /// Whether the timed fraction lies inside the fitted one's 95% interval.
    pub agree: bool,
    /// A sentence for a report saying what the difference means.
    pub(crate) explanation: String,
}

/// The serial fraction of a one-worker run from its phase times (seconds): the phases that
/// stay serial and those that parallelise. When only the total was measured besides the serial
/// phases, pass `total − Σ serial` as the one parallel phase.
pub(crate) fn timed_serial_fraction(
    serial_s: &[f64],
    parallel_s: &[f64],
) -> Result<TimedSerialFraction, FitError> {
    let bad = |what: String| Err(FitError::BadPhases { what });
    for (kind, phases) in [("serial", serial_s), ("parallel", parallel_s)] {
        if let Some(t) = phases.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
            return bad(format!(
                "{kind} phase time {t} must be a finite number of seconds >= 0"
            ));
        }
    }
    let serial: f64 = serial_s.iter().sum();
    let parallel: f64 = parallel_s.iter().sum();
    let total = serial + parallel;
    if total <= 0.0 {
        return bad("the phases add up to 0 s; pass the measured phase times".into());
    }
    Ok(TimedSerialFraction {
        serial_s: serial,
        parallel_s: parallel,
        total_s: total,
        fraction: serial / total,
    })
}

/// Below this timed serial fraction, a series none of whose parallel runs is faster than its
/// one-worker run is read as a program that does not use its workers: Amdahl's law on the
/// timed phases would give it at least 1.6× on two.
const UNUSED_WORKERS_SERIAL: f64 = 0.25;

/// Compares the timed serial fraction with the one fitted to the speedups; `best_speedup` is
/// the largest measured speedup of the series' parallel runs, when it has any, and `shared`
/// the load of other processes when the machine was shared.
pub(crate) fn compare_serial_fractions(
    timed: &TimedSerialFraction,
    fitted: &Estimate,
    best_speedup: Option<f64>,
    shared: Option<&SharedMachine>,
) -> SerialFractionComparison {
    let t = timed.fraction;
    let gap = fitted.estimate - t;
    let agree = fitted.contains(t);
    let fitted_text = format!(
        "{} [{}, {}]",
        percent(fitted.estimate),
        percent(fitted.ci95[0]),
        percent(fitted.ci95[1])
    );
    let unused = best_speedup.filter(|&s| s <= 1.0 && t <= UNUSED_WORKERS_SERIAL);
    let explanation = if let Some(shared) = shared {
        // Time-sharing slows the parallel runs as much as any cost of the code would, and
        // can leave a program that uses its workers with no speedup at all.
        format!(
            "The fitted serial fraction {fitted_text} {} the {} of the one-worker time spent in \
             serial phases, but {}.",
            if agree { "agrees with" } else { "differs from" },
            percent(t),
            shared.sentence()
        )
    } else if let Some(best) = unused {
        format!(
            "No run on more workers is faster than the one-worker run (best speedup {best:.2}×), \
             though only {} of the one-worker time is in serial phases: the program most \
             likely does not use its workers (it ignores the thread or rank count it is given, \
             or its parallel loop runs serially). Check how the count reaches it (for OpenMP, \
             OMP_NUM_THREADS in `env`) before reading the fitted serial fraction {fitted_text} as \
             overhead.",
            percent(t)
        )
    } else if agree {
        format!(
            "The fitted serial fraction {fitted_text} agrees with the {} of the one-worker time \
             spent in serial phases: the serial code accounts for the loss of speedup.",
            percent(t)
        )
    } else if gap > 0.0 {
        format!(
            "The fitted serial fraction {fitted_text} exceeds the {} of the one-worker time spent \
             in serial phases; the difference, {} of the one-worker time, is overhead that phase \
             timing of a one-worker run does not see: synchronisation, communication and memory \
             contention that appear only with several workers.",
            percent(t),
            percent(gap)
        )
    } else {
        format!(
            "The fitted serial fraction {fitted_text} is below the {} of the one-worker time spent \
             in serial phases: the parallel runs gained more than the serial phases cost, e.g. \
             from more cache in total, or serial phases overlap with parallel work.",
            percent(t)
        )
    };
    SerialFractionComparison {
        timed: t,
        fitted: *fitted,
        gap,
        agree,
        explanation,
    }
}

/// A fraction as a percentage with two significant digits ("0.0034%", "5.2%", "12%").
fn percent(fraction: f64) -> String {
    let v = 100.0 * fraction;
    if v == 0.0 || !v.is_finite() {
        return format!("{v}%");
    }
    let decimals = (1 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.decimals$}%")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timed_phases_table_gives_0_0034_percent() {
        let serial = [0.0133631, 0.00107666, 0.00932205];
        let total = 690.016;
        let parallel = [total - serial.iter().sum::<f64>()];
        let f = timed_serial_fraction(&serial, &parallel).unwrap();
        assert!((f.total_s - total).abs() < 1e-9);
        assert_eq!(percent(f.fraction), "0.0034%");
    }

    #[test]
    fn comparison_explains_the_gap() {
        let timed = timed_serial_fraction(&[0.5], &[9.5]).unwrap();
        assert_eq!(timed.fraction, 0.05);
        let larger = Estimate {
            estimate: 0.12,
            ci95: [0.1, 0.14],
        };
        let c = compare_serial_fractions(&timed, &larger, Some(1.6), None);
        assert!(!c.agree && (c.gap - 0.07).abs() < 1e-12);
        assert!(
            c.explanation.contains("7.0% of the one-worker time"),
            "{}",
            c.explanation
        );
        assert!(c.explanation.contains("synchronisation"));
        let same = Estimate {
            estimate: 0.051,
            ci95: [0.04, 0.06],
        };
        assert!(compare_serial_fractions(&timed, &same, Some(1.9), None).agree);
        let smaller = Estimate {
            estimate: 0.01,
            ci95: [0.0, 0.02],
        };
        assert!(
            compare_serial_fractions(&timed, &smaller, None, None)
                .explanation
                .contains("below")
        );
    }

    #[test]
    fn a_program_that_ignores_its_threads_is_named_as_such() {
        // 0.09% of the time serial, f fitted to 100%, 0.91× on two threads.
        let timed = timed_serial_fraction(&[0.0009], &[0.9991]).unwrap();
        let all = Estimate {
            estimate: 1.0,
            ci95: [0.95, 1.0],
        };
        let c = compare_serial_fractions(&timed, &all, Some(0.91), None);
        assert!(
            c.explanation.contains("does not use its workers"),
            "{}",
            c.explanation
        );
        assert!(c.explanation.contains("0.91×"));
        assert!(!c.explanation.contains("contention"));
        // A speedup above 1 keeps the overhead reading; so does a mostly serial program.
        let c = compare_serial_fractions(&timed, &all, Some(1.2), None);
        assert!(c.explanation.contains("contention"), "{}", c.explanation);
        let serial = timed_serial_fraction(&[0.9], &[0.1]).unwrap();
        let c = compare_serial_fractions(&serial, &all, Some(0.99), None);
        assert!(!c.explanation.contains("does not use its workers"));
    }

    #[test]
    fn on_a_shared_machine_the_gap_is_not_put_on_the_code() {
        // f fitted to 100% on two CPUs with one busy: the runs time-shared, nothing more.
        let timed = timed_serial_fraction(&[0.0009], &[0.9991]).unwrap();
        let all = Estimate {
            estimate: 1.0,
            ci95: [0.95, 1.0],
        };
        let shared = SharedMachine {
            background_cpus: 1.0,
        };
        for best in [Some(0.91), Some(1.2), None] {
            let c = compare_serial_fractions(&timed, &all, best, Some(&shared));
            for blame in [
                "synchronisation",
                "communication",
                "contention",
                "does not use",
            ] {
                assert!(!c.explanation.contains(blame), "{}", c.explanation);
            }
            assert!(
                c.explanation.contains("other processes used 1.00 CPUs"),
                "{}",
                c.explanation
            );
        }
    }

    #[test]
    fn bad_phases_are_refused() {
        assert!(timed_serial_fraction(&[-1.0], &[2.0]).is_err());
        assert!(timed_serial_fraction(&[f64::NAN], &[2.0]).is_err());
        assert!(timed_serial_fraction(&[0.0], &[0.0]).is_err());
        assert_eq!(timed_serial_fraction(&[], &[2.0]).unwrap().fraction, 0.0);
        assert_eq!(percent(0.12), "12%");
        assert_eq!(percent(0.052), "5.2%");
    }
}
