//! The reference workload: a fixed amount of work, independent of every kernel, timed next to
//! every sample of a case (`measure.reference_s`) so that `gate` can tell a slower kernel from
//! a slower machine.
//!
//! On a shared machine most of the noise is time-sharing: other processes take the CPU away
//! for whole scheduler slices, and the same code measures up to 1.5x apart from one minute to
//! the next. A reference that runs in short bursts, or only at the start and end of a sweep, sees
//! the machine's speed while it ran, not the share of the CPU the case got. So the reference is
//! run right before each sample, for about as long as a sample, on the same threads: the two
//! then see nearly the same share of the machine, and their ratio cancels it.
//!
//! The workload is a small force loop of the kernels' kind — a softened 1/r² direct sum in f32
//! lane arrays with a square root and a division per pair, at the kernels' SIMD level — written
//! here, not taken from `kernels`, so that a kernel made slower cannot make the reference
//! slower and hide itself. Under load it still slows down a little more than the kernels (about
//! 3.4x against 2.9x with two busy loops beside it; a peak-rate FMA loop, tried first, did the
//! same), so a run under more load than its baseline reads slightly faster, and a baseline
//! should be measured on a quiet machine (docs/explanation/gate.md). Every thread of the case's pool
//! runs it (a 2-thread case waits for its slowest thread at every step; so does the
//! broadcast); a 1-thread pool runs it on the calling thread.

use nbody_engine::clock::Clock;
use nbody_engine::simd::{self, LANES};
use std::sync::OnceLock;

/// Target and source particles of one repetition: 128 × 1024 pairs, about 0.1-0.2 ms with
/// AVX-512 on the reference machine, in a working set of 12 KB (L1).
const TARGETS: usize = 128;
const SOURCES: usize = 1024;
const _: () = assert!(TARGETS <= SOURCES && SOURCES.is_multiple_of(LANES));

/// Fewest repetitions in one measurement, whatever the budget.
const MIN_REPETITIONS: usize = 3;

/// Runs repetitions of the reference workload on every thread of the current rayon pool until
/// `budget_s` has passed (at least [`MIN_REPETITIONS`]); returns the mean wall time of one
/// repetition, seconds.
pub(crate) fn time_reference<C: Clock>(clock: &C, budget_s: f64) -> f64 {
    let start = clock.now();
    let mut reps = 0;
    while reps < MIN_REPETITIONS || (clock.now() - start).as_secs_f64() < budget_s {
        if rayon::current_num_threads() > 1 {
            rayon::broadcast(|_| std::hint::black_box(reference_work()));
        } else {
            // On the calling thread: a broadcast's hand-off can sleep and wait to be woken,
            // which on a busy machine costs whole scheduler slices the case never pays.
            std::hint::black_box(reference_work());
        }
        reps += 1;
    }
    (clock.now() - start).as_secs_f64() / reps as f64
}

/// Fixed particles: positions in the unit cube from a linear congruential generator (the
/// same on every machine), as structure-of-arrays rows padded to whole lanes.
struct Particles {
    pos: [Vec<f32>; 3],
}

fn particles() -> &'static Particles {
    static PARTICLES: OnceLock<Particles> = OnceLock::new();
    PARTICLES.get_or_init(|| {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        let pos = std::array::from_fn(|_| (0..SOURCES).map(|_| next()).collect());
        Particles { pos }
    })
}

/// One repetition: the softened 1/r² field at the first [`TARGETS`] particles from all
/// [`SOURCES`], compiled for the kernels' instruction set; returns a checksum.
pub(crate) fn reference_work() -> f32 {
    let p = particles();
    simd::dispatch(
        #[inline(always)]
        || field_sum(&p.pos),
    )
}

#[inline(always)]
fn field_sum(pos: &[Vec<f32>; 3]) -> f32 {
    const SOFTENING2: f32 = 1e-4;
    let mut total = 0.0;
    for i in 0..TARGETS {
        let xi = [pos[0][i], pos[1][i], pos[2][i]];
        let mut acc = [[0.0f32; LANES]; 3];
        for j0 in (0..SOURCES).step_by(LANES) {
            for l in 0..LANES {
                let d = [
                    pos[0][j0 + l] - xi[0],
                    pos[1][j0 + l] - xi[1],
                    pos[2][j0 + l] - xi[2],
                ];
                let r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + SOFTENING2;
                let inv = 1.0 / (r2 * r2.sqrt());
                for k in 0..3 {
                    acc[k][l] += d[k] * inv;
                }
            }
        }
        total += acc.iter().flatten().sum::<f32>();
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use nbody_engine::clock::MockClock;
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
    fn the_workload_is_fixed_and_finite() {
        let a = reference_work();
        assert!(a.is_finite(), "{a}");
        assert_eq!(a, reference_work(), "same particles, same order");
        assert_eq!(particles().pos[0].len(), SOURCES);
    }
}
