//! The reference workload: a fixed amount of work, independent of every kernel, timed around
//! each case of a sweep (`measure.reference_s`) so that `gate` can tell a slower kernel from a
//! slower machine.
//!
//! Shared CI machines change speed from minute to minute (other tenants, the SMT sibling of a
//! vCPU, frequency): the same code can measure 2-4x apart. Dividing a case's step time by the
//! time of a fixed workload measured on the same threads, just before and just after the case,
//! cancels what the two have in common. The workload is the calibration's FMA loop, a fixed
//! number of iterations run by every thread of the case's pool; it shares no code with the
//! kernels, so a kernel made slower cannot make the reference slower and hide itself.

use super::measure::Clock;

/// Iterations of the FMA loop in one repetition: about 0.3 ms with AVX-512 on the reference
/// machine (12 chains of 16 lanes, ~110 GFLOP/s), long enough for the clock and a rayon
/// broadcast (~20 us) to be small, short enough for many repetitions in a few milliseconds.
pub const REFERENCE_ITERS: u64 = 100_000;

/// Fewest repetitions on each side of a case, whatever the budget.
const MIN_REPETITIONS: usize = 3;

/// Times repetitions of the reference workload on every thread of the current rayon pool until
/// `budget_s` has passed (at least [`MIN_REPETITIONS`]); returns the wall time of each, seconds.
pub fn time_reference<C: Clock>(clock: &C, budget_s: f64) -> Vec<f64> {
    let start = clock.now();
    let mut times = Vec::new();
    while times.len() < MIN_REPETITIONS || (clock.now() - start).as_secs_f64() < budget_s {
        let t = clock.now();
        rayon::broadcast(|_| std::hint::black_box(crate::calibrate::fma_burst(REFERENCE_ITERS)));
        times.push((clock.now() - t).as_secs_f64());
        if times.len() >= 100_000 {
            break;
        }
    }
    times
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::measure::{MockClock, WallClock};
    use std::time::Duration;

    #[test]
    fn repeats_until_the_budget_with_a_minimum() {
        // Every clock reading advances 1 ms: a repetition reads twice (1 ms), plus one budget
        // check per repetition.
        let clock = MockClock::new(Duration::from_millis(1));
        let t = time_reference(&clock, 0.0);
        assert_eq!(t.len(), MIN_REPETITIONS);
        assert!(t.iter().all(|&x| (x - 1e-3).abs() < 1e-12), "{t:?}");
        let t = time_reference(&clock, 0.02);
        assert!(t.len() >= 6 && t.len() <= 11, "{}", t.len());
    }

    #[test]
    fn real_repetitions_take_time() {
        let t = time_reference(&WallClock::new(), 0.0);
        assert_eq!(t.len(), MIN_REPETITIONS);
        assert!(t.iter().all(|&x| x > 1e-6 && x < 1.0), "{t:?}");
    }
}
