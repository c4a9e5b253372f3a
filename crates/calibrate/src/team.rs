//! The cost of the engine's worker team ([`nbody_engine::par::team`]): one barrier crossing inside a
//! region, and one region started after serial work, next to the rayon fork/join it is meant
//! to replace in a step.

#[allow(unused_imports)]
use super::*;
use nbody_engine::par::team::Team;

/// Barriers crossed in one timed region: enough that starting the region is negligible.
const BARRIERS: usize = 200;

/// Median wall time in µs on a `p`-worker team: `(barrier, region)`.
///
/// Barrier: regions of [`BARRIERS`] back-to-back barriers, each region's time divided by their
/// number; what a step's passes pay between them when they run in one region. Region: one
/// region (with one barrier, so that every worker takes part) started after the caller slept
/// 1 ms, long enough for the workers to park; what starting a step's region costs after the
/// serial work between steps. `None` (with a warning) when the team cannot be started.
pub(super) fn measure_team(
    p: usize,
    budget_s: f64,
    warnings: &mut Vec<String>,
) -> (Option<f64>, Option<f64>) {
    let mut team = match Team::new(p) {
        Ok(team) => team,
        Err(e) => {
            warnings.push(format!("team barrier not measured: {p} workers: {e}"));
            return (None, None);
        }
    };
    let mut failed = None;
    let mut region = |team: &mut Team, barriers: usize| -> f64 {
        let t = Instant::now();
        let result = team.run(|w| {
            for _ in 0..barriers {
                w.barrier().map_err(|_| "stopped".to_string())?;
            }
            Ok(())
        });
        if let Err(e) = result {
            failed.get_or_insert(e.to_string());
        }
        t.elapsed().as_secs_f64() * 1e6
    };
    // Warm up: threads started, code touched.
    for _ in 0..10 {
        region(&mut team, BARRIERS);
    }
    let barrier = repeat(budget_s / 2.0, 5, 2000, || {
        region(&mut team, BARRIERS) / BARRIERS as f64
    });
    let cold = repeat(budget_s / 2.0, 5, 1000, || {
        std::thread::sleep(Duration::from_millis(1));
        region(&mut team, 1)
    });
    if let Some(why) = failed {
        warnings.push(format!("team barrier not measured: {why}"));
        return (None, None);
    }
    (median(&barrier), median(&cold))
}
