//! Choosing the Verlet skin by measurement (`run --skin auto`): the skin trades the list's
//! rebuilds (fewer as it grows: the list stays exact until a particle has moved half of it)
//! against the pairs evaluated every step (more as it grows). Which side wins depends on the
//! density, the temperature, the machine and the thread count, so each candidate is timed on
//! the run's own system and threads, and the fastest is kept. The run that follows uses one
//! fixed skin, so its results do not depend on the timing beyond that choice, which is reported.

use nbody_engine::kernels::{KernelKind, KernelParams};
use nbody_engine::scenario::Setup;
use std::time::Instant;

/// Candidate skins, as multiples of the default (0.3σ): the default and up to six times it.
pub const SKIN_FACTORS: [f64; 6] = [1.0, 1.5, 2.0, 3.0, 4.0, 6.0];

/// Steps of each trial after its warm-up: enough for several rebuilds at the largest skin of
/// the systems the scenarios build.
pub const TRIAL_STEPS: u64 = 100;
const WARMUP_STEPS: u64 = 10;

/// One candidate skin, timed.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct SkinTrial {
    /// The candidate skin: `params.skin` times one of [`SKIN_FACTORS`], in length units.
    pub skin: f64,
    /// Wall time per particle-step over the trial, nanoseconds.
    pub ns_per_particle_step: f64,
    /// Steps per list rebuild over the trial (`None` when none happened).
    pub steps_per_rebuild: Option<f64>,
}

/// Times every candidate skin (`params.skin` times [`SKIN_FACTORS`]) on `setup` with `kernel`
/// on `threads` threads for `steps` steps each (after a short warm-up); the trials in the
/// candidates' order.
pub fn tune(
    setup: &Setup,
    kernel: KernelKind,
    params: &KernelParams,
    threads: usize,
    steps: u64,
) -> anyhow::Result<Vec<SkinTrial>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| anyhow::anyhow!("cannot start {threads} threads: {e}"))?;
    let mut trials = Vec::new();
    for factor in SKIN_FACTORS {
        let params = KernelParams {
            // Six significant digits: the skin reported and recorded reads as it was meant.
            skin: format!("{:.5e}", params.skin * factor)
                .parse()
                .unwrap_or(params.skin * factor),
            ..*params
        };
        let trial = pool.install(|| -> anyhow::Result<SkinTrial> {
            let mut sim = nbody_engine::stepper::stepper(setup, kernel, &params)??;
            for _ in 0..WARMUP_STEPS {
                sim.step()?;
            }
            let before = sim.work().rebuilds;
            let t = Instant::now();
            for _ in 0..steps {
                sim.step()?;
            }
            let seconds = t.elapsed().as_secs_f64();
            let rebuilds = sim.work().rebuilds - before;
            Ok(SkinTrial {
                skin: params.skin,
                ns_per_particle_step: seconds * 1e9 / (steps.max(1) * sim.len() as u64) as f64,
                steps_per_rebuild: (rebuilds > 0).then(|| steps as f64 / rebuilds as f64),
            })
        })?;
        trials.push(trial);
    }
    Ok(trials)
}

/// The fastest trial (the smaller skin of two equally fast).
pub fn fastest(trials: &[SkinTrial]) -> Option<&SkinTrial> {
    trials
        .iter()
        .min_by(|a, b| a.ns_per_particle_step.total_cmp(&b.ns_per_particle_step))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_candidate_runs_and_the_fastest_is_one_of_them() {
        let mut setup = Setup::new(nbody_engine::scenario::ScenarioKind::LjBox);
        setup.n = Some(400);
        let params = KernelParams::default();
        let trials = tune(&setup, KernelKind::Verlet, &params, 1, 20).unwrap();
        let skins: Vec<f64> = trials.iter().map(|t| t.skin).collect();
        for (skin, factor) in skins.iter().zip(SKIN_FACTORS) {
            assert!((skin / (params.skin * factor) - 1.0).abs() < 1e-5, "{skin}");
        }
        assert!(trials.iter().all(|t| t.ns_per_particle_step > 0.0));
        // A larger skin never rebuilds more often.
        let every: Vec<f64> = trials
            .iter()
            .map(|t| t.steps_per_rebuild.unwrap_or(f64::INFINITY))
            .collect();
        assert!(every.windows(2).all(|w| w[0] <= w[1]), "{every:?}");
        let best = fastest(&trials).unwrap();
        assert!(trials.contains(best));
    }
}
