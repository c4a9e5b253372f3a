//! The reference workload: a fixed amount of work, independent of every kernel, timed next to
//! every sample of a case (`measure.reference_s`) so that `gate` can tell a slower kernel from
//! a slower machine.
//!
//! On a shared machine most of the noise is time-sharing: other processes take the CPU away
//! for whole scheduler slices, and the same code measures 2-4x apart from one minute to the
//! next. A reference that runs in short bursts, or only at the start and end of a sweep, sees
//! the machine's speed while it ran, not the share of the CPU the case got. So the reference is
//! run right before each sample, for about as long as a sample, on the same threads: the two
//! then see nearly the same share of the machine, and their ratio cancels it. The workload is
//! the calibration's FMA loop, a fixed number of iterations run by every thread of the case's
//! pool (a 2-thread case waits for its slowest thread at every step; so does the broadcast). It
//! shares no code with the kernels, so a kernel made slower cannot make the reference slower
//! and hide itself.

use super::measure::Clock;

/// Iterations of the FMA loop in one repetition: about 0.1 ms with AVX-512 on the reference
/// machine (12 chains of 16 lanes at ~110 GFLOP/s), long enough for the clock to be negligible,
/// short enough to fill a sample's duration closely.
pub const REFERENCE_ITERS: u64 = 50_000;

/// Fewest repetitions in one measurement, whatever the budget.
const MIN_REPETITIONS: usize = 3;

/// Runs repetitions of the reference workload on every thread of the current rayon pool until
/// `budget_s` has passed (at least [`MIN_REPETITIONS`]); returns the mean wall time of one
/// repetition, seconds.
pub fn time_reference<C: Clock>(clock: &C, budget_s: f64) -> f64 {
    let start = clock.now();
    let mut reps = 0;
    while reps < MIN_REPETITIONS || (clock.now() - start).as_secs_f64() < budget_s {
        rayon::broadcast(|_| std::hint::black_box(crate::calibrate::fma_burst(REFERENCE_ITERS)));
        reps += 1;
    }
    (clock.now() - start).as_secs_f64() / reps as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::measure::{MockClock, WallClock};
    use std::time::Duration;

    #[test]
    fn repeats_until_the_budget_with_a_minimum() {
        // Every clock reading advances 1 ms: one reading at the start, one budget check per
        // repetition once the minimum is done, one at the end.
        let clock = MockClock::new(Duration::from_millis(1));
        assert!((time_reference(&clock, 0.0) - 2e-3 / 3.0).abs() < 1e-12);
        // Checks 1, 2, ..., 10 ms after the start: 3 + 9 repetitions in 11 ms.
        let t = time_reference(&clock, 0.0095);
        assert!((t - 11e-3 / 12.0).abs() < 1e-12, "{t}");
    }

    #[test]
    fn real_repetitions_take_time() {
        let t = time_reference(&WallClock::new(), 0.0);
        assert!(t > 1e-6 && t < 1.0, "{t}");
    }
}
