//! The cost of a rayon fork/join region.

#[allow(unused_imports)]
use super::*;

// ---------------------------------------------------------------------------------------------
// Fork/join

/// How long a region's leaf waits for the other threads before giving up (a leaf can only
/// give up when some pool thread never got to it: an oversubscribed or very busy machine).
pub(super) const FORK_JOIN_TIMEOUT: Duration = Duration::from_millis(2);

/// A fork/join region as the kernels build them (a binary tree of `rayon::join`), split into
/// `leaves` leaves, each waiting until all `total` leaves have started. The wait makes every
/// pool thread take part: without it an empty region is usually run entirely by the calling
/// thread before any worker wakes up, which measures nothing a real region pays. Returns
/// whether every leaf saw all the others.
pub(super) fn region(
    leaves: usize,
    total: usize,
    arrived: &AtomicUsize,
    deadline: Instant,
) -> bool {
    if leaves <= 1 {
        arrived.fetch_add(1, Ordering::AcqRel);
        while arrived.load(Ordering::Acquire) < total {
            if Instant::now() >= deadline {
                return false;
            }
            // Yield rather than only spin: if the pool has more threads than CPUs, the threads
            // still to arrive need this CPU.
            std::thread::yield_now();
        }
        true
    } else {
        let half = leaves / 2;
        let (a, b) = rayon::join(
            || region(half, total, arrived, deadline),
            || region(leaves - half, total, arrived, deadline),
        );
        a && b
    }
}

/// Median wall time in µs of one fork/join region on a `p`-thread pool: `(cold, hot)`.
///
/// Cold: before each region the calling thread sleeps 1 ms, long enough for rayon's idle
/// workers to stop spinning and go to sleep, so the region pays for waking them; this is what
/// a step's parallel region costs after serial work. Hot: regions back to back, workers still
/// spinning. The median, not the minimum, because a cost (unlike a throughput) is best
/// described by its typical value, and wake-up latency has a long tail.
pub(super) fn measure_fork_join(p: usize, budget_s: f64, warnings: &mut Vec<String>) -> (f64, f64) {
    let pool = match rayon::ThreadPoolBuilder::new().num_threads(p).build() {
        Ok(pool) => pool,
        Err(e) => {
            warnings.push(format!(
                "fork/join not measured: {p}-thread rayon pool: {e}"
            ));
            return (0.0, 0.0);
        }
    };
    let timed_out = AtomicUsize::new(0);
    let once = || {
        let arrived = AtomicUsize::new(0);
        let t = Instant::now();
        let complete = region(p, p, &arrived, t + FORK_JOIN_TIMEOUT);
        let us = t.elapsed().as_secs_f64() * 1e6;
        if !complete {
            timed_out.fetch_add(1, Ordering::Relaxed);
        }
        us
    };
    let (cold, hot) = pool.install(|| {
        // Warm up: threads started, code and stacks touched.
        for _ in 0..10 {
            once();
        }
        timed_out.store(0, Ordering::Relaxed);
        let cold = repeat(budget_s / 2.0, 5, 1000, || {
            std::thread::sleep(Duration::from_millis(1));
            once()
        });
        let hot = repeat(budget_s / 2.0, 5, 10_000, once);
        (cold, hot)
    });
    // A few stragglers (another process held a CPU for a time slice) do not move the
    // medians; from 1% on they may, and from half on the figures are the timeout itself.
    let timed_out = timed_out.into_inner();
    let regions = cold.len() + hot.len();
    if timed_out * 100 >= regions {
        warnings.push(format!(
            "fork/join: {timed_out} of {regions} regions timed out after {} ms waiting for all \
             {p} threads (busy or oversubscribed machine)",
            FORK_JOIN_TIMEOUT.as_millis()
        ));
    }
    // `repeat` runs at least 5 times each, so there are medians.
    (median(&cold).unwrap_or(0.0), median(&hot).unwrap_or(0.0))
}
