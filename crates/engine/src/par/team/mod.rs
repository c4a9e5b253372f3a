//! A team of workers that lives for a whole run and meets at barriers, the way an OpenMP
//! parallel region does: a step can then be one region whose passes are separated by
//! barriers, instead of a rayon fork/join per pass (each of which wakes the pool's threads,
//! 3–12 µs on the 2-vCPU machines this project runs on).
//!
//! [`Team::run`] runs one closure on every worker (the caller is worker 0) and returns when all
//! have finished it, so the closure may borrow from the caller's stack. Inside, a
//! [`Worker`] knows its index, cuts a range into its own contiguous block
//! ([`Worker::block`]) and waits for the others at [`Worker::barrier`]: it spins briefly (the
//! others are usually a few hundred nanoseconds behind), then parks until the last one
//! arrives. A worker whose closure fails or panics stops the whole region: every other worker's
//! next (or current) barrier returns [`Stopped`] at once, so nobody waits for a worker that
//! will never come, and `run` returns the first failure.

pub mod shared;

pub use shared::SharedSlice;
use std::ops::Range;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::thread::JoinHandle;

/// Spins of a waiting worker before it parks: about 10–20 µs of checking, longer than the
/// usual skew between workers at a barrier and far shorter than a time slice.
const SPINS: u32 = 4000;

/// Yields of a waiting worker before it parks when the team has more workers than the machine
/// has CPUs: the worker it waits for may be the one that is not running, and spinning would
/// keep it off the CPU (as an OpenMP runtime turns to passive waiting when oversubscribed).
const YIELDS: u32 = 64;

/// The region was stopped by another worker's failure: return, nothing else is worth doing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Stopped;

/// Why a region ended without finishing.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum TeamError {
    /// A worker's closure returned this error.
    #[error("worker {worker}: {message}")]
    Failed {
        /// The worker's index in the team, from 0.
        worker: usize,
        /// The error, as text.
        message: String,
    },
    /// A worker panicked with this message.
    #[error("worker {worker} panicked: {message}")]
    Panicked {
        /// The worker's index in the team, from 0.
        worker: usize,
        /// The panic's message, or `(no message)` when it carried no text.
        message: String,
    },
    /// The team's threads could not be started.
    #[error("cannot start the team's threads: {0}")]
    Spawn(String),
}

/// The closure of the region in progress, its lifetime erased: [`Team::run`] does not return
/// before every worker is done with it.
type Job<'a> = dyn Fn(&Worker) -> Result<(), String> + Sync + 'a;

struct Shared {
    size: usize,
    /// More workers than CPUs: waiting workers yield instead of spinning.
    oversubscribed: bool,
    /// Counts the regions started; a helper runs the job when it sees it move.
    region: AtomicU64,
    job: Mutex<Option<&'static Job<'static>>>,
    /// Helpers done with the current region.
    finished: AtomicUsize,
    /// The barrier: workers arrived in this phase, and the phase (moved by the last arrival).
    arrived: AtomicUsize,
    phase: AtomicU64,
    stopped: AtomicBool,
    failure: Mutex<Option<TeamError>>,
    shutdown: AtomicBool,
    /// Helpers park at once after this region instead of spinning for the next one
    /// ([`Worker::rest_after`]).
    rest: AtomicBool,
    /// Parked workers sleep on `wake` under `lock`, which counts them; whoever moves a counter
    /// they wait on takes the lock before notifying, so that no wake-up is lost, and notifies
    /// only when someone sleeps (a wake-up is a system call, about 0.3 µs, five per step).
    lock: Mutex<usize>,
    wake: Condvar,
}

impl Shared {
    fn guard(&self) -> MutexGuard<'_, usize> {
        self.lock.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn notify(&self) {
        // Taking the lock (after the counter moved) waits out a worker between its check and
        // its wait; notifying after releasing it spares the woken worker a second wait for the
        // lock.
        let sleepers = *self.guard();
        if sleepers > 0 {
            self.wake.notify_all();
        }
    }

    /// Spins, then parks, until `done()`.
    fn wait_until(&self, done: impl Fn() -> bool) {
        self.wait_spinning(SPINS, done)
    }

    /// Spins `spins` times (yields, when oversubscribed), then parks, until `done()`.
    fn wait_spinning(&self, spins: u32, done: impl Fn() -> bool) {
        if self.oversubscribed {
            for _ in 0..spins.min(YIELDS) {
                if done() {
                    return;
                }
                std::thread::yield_now();
            }
        } else {
            for _ in 0..spins {
                if done() {
                    return;
                }
                std::hint::spin_loop();
            }
        }
        let mut g = self.guard();
        while !done() {
            *g += 1;
            g = self.wake.wait(g).unwrap_or_else(|p| p.into_inner());
            *g -= 1;
        }
    }

    fn stop(&self, error: TeamError) {
        {
            let mut f = self.failure.lock().unwrap_or_else(|p| p.into_inner());
            f.get_or_insert(error);
        }
        self.stopped.store(true, Ordering::Release);
        self.notify();
    }
}

/// One worker's view of the region in progress.
pub struct Worker {
    index: usize,
    shared: Arc<Shared>,
}

impl Worker {
    /// This worker's index, from 0 (the caller of [`Team::run`]).
    pub fn index(&self) -> usize {
        self.index
    }

    /// Workers in the team.
    pub fn size(&self) -> usize {
        self.shared.size
    }

    /// This worker's contiguous block of `0..len`: the blocks of the workers in order cover
    /// it, their lengths differing by at most one.
    pub fn block(&self, len: usize) -> Range<usize> {
        block(len, self.shared.size, self.index)
    }

    /// Asks the helpers to park as soon as this region ends rather than spin for the next
    /// one: the caller has other parallel work to do first (a rayon pass would share the
    /// CPUs with spinning helpers).
    pub fn rest_after(&self) {
        self.shared.rest.store(true, Ordering::Relaxed);
    }

    /// Waits until every worker has arrived here; `Err(Stopped)` at once when another worker
    /// failed (then return without further work). What a worker wrote before the barrier is
    /// visible to every worker after it.
    pub fn barrier(&self) -> Result<(), Stopped> {
        let s = &*self.shared;
        if s.stopped.load(Ordering::Acquire) {
            return Err(Stopped);
        }
        let phase = s.phase.load(Ordering::Acquire);
        if s.arrived.fetch_add(1, Ordering::AcqRel) + 1 == s.size {
            s.arrived.store(0, Ordering::Relaxed);
            s.phase.store(phase + 1, Ordering::Release);
            s.notify();
        } else {
            s.wait_until(|| {
                s.phase.load(Ordering::Acquire) != phase || s.stopped.load(Ordering::Acquire)
            });
        }
        if s.stopped.load(Ordering::Acquire) {
            Err(Stopped)
        } else {
            Ok(())
        }
    }
}

/// Worker `index`'s block of `0..len` split over `size` workers.
pub fn block(len: usize, size: usize, index: usize) -> Range<usize> {
    let (base, extra) = (len / size, len % size);
    let start = index * base + index.min(extra);
    start..start + base + usize::from(index < extra)
}

/// Workers that live until the team is dropped.
pub struct Team {
    shared: Arc<Shared>,
    helpers: Vec<JoinHandle<()>>,
}

impl Team {
    /// A team of `size` workers: the caller of [`Team::run`] and `size − 1` threads started now.
    pub fn new(size: usize) -> Result<Team, TeamError> {
        let size = size.max(1);
        let cpus = std::thread::available_parallelism().map_or(1, |c| c.get());
        let shared = Arc::new(Shared {
            size,
            oversubscribed: size > cpus,
            region: AtomicU64::new(0),
            job: Mutex::new(None),
            finished: AtomicUsize::new(0),
            arrived: AtomicUsize::new(0),
            phase: AtomicU64::new(0),
            stopped: AtomicBool::new(false),
            failure: Mutex::new(None),
            shutdown: AtomicBool::new(false),
            rest: AtomicBool::new(false),
            lock: Mutex::new(0),
            wake: Condvar::new(),
        });
        let mut team = Team {
            shared: shared.clone(),
            helpers: Vec::with_capacity(size - 1),
        };
        for index in 1..size {
            let worker = Worker {
                index,
                shared: shared.clone(),
            };
            let handle = std::thread::Builder::new()
                .name(format!("nbody-team-{index}"))
                .spawn(move || helper(worker))
                .map_err(|e| TeamError::Spawn(e.to_string()))?;
            team.helpers.push(handle);
        }
        Ok(team)
    }

    /// Workers in the team.
    pub fn size(&self) -> usize {
        self.shared.size
    }

    /// Runs `job` on every worker, this thread being worker 0, and returns when all are done:
    /// the first failure (an error returned, or a panic) if a worker failed.
    pub fn run<F>(&mut self, job: F) -> Result<(), TeamError>
    where
        F: Fn(&Worker) -> Result<(), String> + Sync,
    {
        let s = &*self.shared;
        s.stopped.store(false, Ordering::Relaxed);
        s.rest.store(false, Ordering::Relaxed);
        s.arrived.store(0, Ordering::Relaxed);
        *s.failure.lock().unwrap_or_else(|p| p.into_inner()) = None;
        s.finished.store(0, Ordering::Relaxed);
        let job: &Job<'_> = &job;
        // SAFETY: the reference is only used by workers of this region, and this function
        // waits below until every one of them is finished with it (a panicking one included:
        // helpers catch their panics), before `job` goes out of scope.
        let job: &'static Job<'static> =
            unsafe { std::mem::transmute::<&Job<'_>, &'static Job<'static>>(job) };
        *s.job.lock().unwrap_or_else(|p| p.into_inner()) = Some(job);
        s.region.fetch_add(1, Ordering::AcqRel);
        s.notify();
        let me = Worker {
            index: 0,
            shared: self.shared.clone(),
        };
        execute(&me, job);
        let helpers = s.size - 1;
        s.wait_until(|| s.finished.load(Ordering::Acquire) == helpers);
        *s.job.lock().unwrap_or_else(|p| p.into_inner()) = None;
        match s.failure.lock().unwrap_or_else(|p| p.into_inner()).take() {
            Some(error) => Err(error),
            None => Ok(()),
        }
    }
}

impl Drop for Team {
    fn drop(&mut self) {
        self.shared.shutdown.store(true, Ordering::Release);
        self.shared.region.fetch_add(1, Ordering::AcqRel);
        self.shared.notify();
        for h in self.helpers.drain(..) {
            let _ = h.join();
        }
    }
}

/// Runs the job on `worker`; a failure or a panic stops the region for everyone.
fn execute(worker: &Worker, job: &Job<'_>) {
    let failure = match catch_unwind(AssertUnwindSafe(|| job(worker))) {
        Ok(Ok(())) => None,
        Ok(Err(message)) => Some(TeamError::Failed {
            worker: worker.index,
            message,
        }),
        Err(panic) => Some(TeamError::Panicked {
            worker: worker.index,
            message: panic_message(&*panic),
        }),
    };
    if let Some(error) = failure {
        worker.shared.stop(error);
    }
}

fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "(no message)".to_string())
}

/// A helper thread: waits for a region, runs it, says so, until the team is dropped.
fn helper(worker: Worker) {
    let s = worker.shared.clone();
    let mut seen = 0;
    loop {
        let spins = if s.rest.load(Ordering::Relaxed) {
            0
        } else {
            SPINS
        };
        s.wait_spinning(spins, || s.region.load(Ordering::Acquire) != seen);
        seen = s.region.load(Ordering::Acquire);
        if s.shutdown.load(Ordering::Acquire) {
            return;
        }
        let job = *s.job.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(job) = job {
            execute(&worker, job);
        }
        s.finished.fetch_add(1, Ordering::AcqRel);
        s.notify();
    }
}

#[cfg(test)]
mod tests;
