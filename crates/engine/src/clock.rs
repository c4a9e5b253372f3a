//! Time sources. Everything that times steps (`run`, the sweep's rounds, the reference
//! workload) reads a [`Clock`], so that tests can script the durations with [`MockClock`].

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// A monotonic time source; the runner and its tests are written against this trait so that
/// tests can script the durations.
pub trait Clock: Sync {
    /// Time since an arbitrary fixed origin.
    fn now(&self) -> Duration;
}

/// The real monotonic clock.
pub struct WallClock(Instant);

impl WallClock {
    /// A clock whose origin is now.
    pub fn new() -> Self {
        WallClock(Instant::now())
    }
}

impl Default for WallClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for WallClock {
    fn now(&self) -> Duration {
        self.0.elapsed()
    }
}

/// A scripted clock for tests: every reading advances time by `tick`.
pub struct MockClock {
    ns: AtomicU64,
    tick_ns: u64,
}

impl MockClock {
    /// A clock at 0 that advances by `tick` at every reading (the first reads `tick`).
    pub fn new(tick: Duration) -> Self {
        MockClock {
            ns: AtomicU64::new(0),
            tick_ns: tick.as_nanos() as u64,
        }
    }
}

impl Clock for MockClock {
    fn now(&self) -> Duration {
        Duration::from_nanos(self.ns.fetch_add(self.tick_ns, Ordering::Relaxed) + self.tick_ns)
    }
}

/// Seconds per clock reading (two readings bracket each timed step).
pub fn clock_cost<C: Clock>(clock: &C) -> f64 {
    let reps = 1000;
    let t0 = clock.now();
    for _ in 0..reps {
        std::hint::black_box(clock.now());
    }
    (clock.now() - t0).as_secs_f64() / (reps + 1) as f64
}
