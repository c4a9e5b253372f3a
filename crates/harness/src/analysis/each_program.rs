//! Our fastest kernel against every external program of the sweep, one program at a time: at
//! each scenario, n and worker count, the lowest median of our kernels set against the lowest
//! median of each external program (its cases of the same system and workers, however it split
//! them into threads and ranks). Where [`super::peers::ratios`] asks how each of our kernels
//! fares against the best of all the others, this asks where each other code stands against our
//! best: the question when several codes (LAMMPS, GROMACS, OpenMM) each have a target.

use super::groups::Point;
use super::peers::case_label;
use nbody_engine::scenario::ScenarioKind;
use nbody_engine::stats::{BOOTSTRAP_RESAMPLES, bootstrap_ratio_ci};

/// The seed of the ratio bootstraps: the same results give the same intervals.
const SEED: u64 = 0xEAC4;

/// One system (scenario, n, workers) with our fastest case and each program's fastest.
#[derive(Clone, Debug)]
pub(crate) struct System {
    pub scenario: ScenarioKind,
    pub n: usize,
    /// Threads × ranks, the same for every case of the system.
    pub workers: usize,
    /// Our fastest case: its label, and its median and 95% CI in ns per particle-step.
    pub ours: String,
    pub ours_ns: f64,
    pub ours_ci_ns: [f64; 2],
    /// Every external program that ran the system, in the order the sweep first lists them.
    pub programs: Vec<Program>,
}

/// One external program's fastest case of a system, against our fastest.
#[derive(Clone, Debug)]
pub(crate) struct Program {
    /// The program's name (its `[[external]]` entry's).
    pub name: String,
    /// Its fastest case's label (with its threads or ranks).
    pub label: String,
    /// Its median, ns per particle-step (its CI is in the peers table).
    pub ns: f64,
    /// Its median over ours (above 1: ours is faster), with the bootstrap 95% CI of that ratio.
    pub speedup: f64,
    pub speedup_ci: Option<[f64; 2]>,
    /// It or our case ran more workers than logical CPUs.
    pub oversubscribed: bool,
}

/// Every system that has at least one of our cases and one external case, in the order of
/// scenario, n and workers.
pub(crate) fn systems(cases: &[Point]) -> Vec<System> {
    let mut keys: Vec<(ScenarioKind, usize, usize)> = cases
        .iter()
        .filter(|p| p.case.kernel.is_external())
        .map(|p| (p.case.scenario, p.n, p.p()))
        .collect();
    keys.sort_by(|a, b| (a.0.name(), a.1, a.2).cmp(&(b.0.name(), b.1, b.2)));
    keys.dedup();
    let fastest = |of: &mut dyn Iterator<Item = &'_ Point>| {
        of.min_by(|a, b| a.median_s.total_cmp(&b.median_s)).cloned()
    };
    keys.into_iter()
        .filter_map(|(scenario, n, workers)| {
            let same = |p: &&Point| p.case.scenario == scenario && p.n == n && p.p() == workers;
            let ours = fastest(
                &mut cases
                    .iter()
                    .filter(same)
                    .filter(|p| !p.case.kernel.is_external()),
            )?;
            let mut names: Vec<&str> = Vec::new();
            for p in cases.iter().filter(same) {
                let name = p.case.kernel.name();
                if p.case.kernel.is_external() && !names.contains(&name) {
                    names.push(name);
                }
            }
            let programs = names
                .into_iter()
                .filter_map(|name| {
                    let t =
                        fastest(&mut cases.iter().filter(same).filter(|p| {
                            p.case.kernel.is_external() && p.case.kernel.name() == name
                        }))?;
                    Some(Program {
                        name: name.to_string(),
                        label: case_label(&t),
                        ns: ns(&t, t.median_s),
                        speedup: t.median_s / ours.median_s,
                        speedup_ci: bootstrap_ratio_ci(
                            &ours.samples,
                            &t.samples,
                            BOOTSTRAP_RESAMPLES,
                            SEED,
                        ),
                        oversubscribed: t.oversubscribed || ours.oversubscribed,
                    })
                })
                .collect();
            Some(System {
                scenario,
                n,
                workers,
                ours: case_label(&ours),
                ours_ns: ns(&ours, ours.median_s),
                ours_ci_ns: ours.ci95_s.map(|s| ns(&ours, s)),
                programs,
            })
        })
        .collect()
}

fn ns(p: &Point, seconds: f64) -> f64 {
    seconds * 1e9 / p.n.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::peers::tests::point;
    use ScenarioKind::LjMelt;

    #[test]
    fn each_program_meets_our_fastest_kernel_at_its_own_best() {
        // n = 1000 on 2 workers: two of our kernels, LAMMPS run two ways (2 ranks, and 2
        // threads of 1 rank), OpenMM once; on 1 worker ours alone, which makes no system.
        let cases = vec![
            point(LjMelt, "verlet", 1000, 2, 1, 4e-4),
            point(LjMelt, "cluster-pair", 1000, 2, 1, 2e-4),
            point(LjMelt, "lammps", 1000, 1, 2, 6e-4),
            point(LjMelt, "lammps", 1000, 2, 1, 5e-4),
            point(LjMelt, "openmm", 1000, 2, 1, 8e-4),
            point(LjMelt, "verlet", 1000, 1, 1, 7e-4),
        ];
        let systems = systems(&cases);
        assert_eq!(systems.len(), 1);
        let s = &systems[0];
        assert_eq!((s.scenario, s.n, s.workers), (LjMelt, 1000, 2));
        assert_eq!(s.ours, "cluster-pair, 2 threads");
        assert!((s.ours_ns - 200.0).abs() < 1e-9);
        let got: Vec<(&str, &str, f64)> = s
            .programs
            .iter()
            .map(|p| (p.name.as_str(), p.label.as_str(), p.speedup))
            .collect();
        assert_eq!(got.len(), 2);
        assert_eq!((got[0].0, got[0].1), ("lammps", "lammps, 2 threads"));
        assert!((got[0].2 - 2.5).abs() < 1e-12);
        assert_eq!((got[1].0, got[1].1), ("openmm", "openmm, 2 threads"));
        assert!((got[1].2 - 4.0).abs() < 1e-12);
        // Samples within 1% of each median: the ratio's interval holds the ratio, within 2%.
        for p in &s.programs {
            let [lo, hi] = p.speedup_ci.unwrap();
            assert!(lo <= p.speedup && p.speedup <= hi, "{p:?}");
            assert!(lo >= p.speedup * 0.979 && hi <= p.speedup * 1.021, "{p:?}");
        }
    }

    #[test]
    fn a_system_without_an_external_case_or_without_ours_is_left_out() {
        let cases = vec![
            point(LjMelt, "verlet", 1000, 1, 1, 4e-4),
            point(LjMelt, "lammps", 2000, 1, 1, 6e-4),
        ];
        assert!(systems(&cases).is_empty());
    }
}
