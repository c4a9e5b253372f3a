//! Expands a sweep config into the list of cases to measure.

use super::config::{Study, SweepConfig, WeakRule};
use crate::decomp::Decomposition;
use crate::kernels::{KernelKind, Multipole};
use crate::scenario::{Precision, ScenarioKind};
use serde::{Deserialize, Serialize};

/// One measured configuration (SPEC §3): everything that changes the work or the machine use.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Case {
    pub scenario: ScenarioKind,
    pub kernel: KernelKind,
    pub n: usize,
    pub threads: usize,
    /// MPI ranks (1 without MPI).
    pub ranks: usize,
    /// Opening angle, for the octree only.
    pub theta: Option<f64>,
    /// Expansion order of the octree's nodes; absent (monopole) in files written before it.
    #[serde(default, skip_serializing_if = "is_monopole")]
    pub multipole: Multipole,
    pub seed: u64,
    pub precision: Option<Precision>,
    /// Simulated-time factor of a weak-by-time study (the run stands for this many times the
    /// steps of the one-thread case); 1 otherwise.
    pub time_factor: u64,
    /// How the case is split over MPI ranks (cases run under the config's MPI launcher).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub decomp: Option<Decomposition>,
}

impl Case {
    /// A stable identifier, used to match cases across runs (resume, gate).
    pub fn key(&self) -> String {
        let mut k = format!(
            "{}/{}/n={}/p={}/r={}/seed={}",
            self.scenario.name(),
            self.kernel.name(),
            self.n,
            self.threads,
            self.ranks,
            self.seed
        );
        if let Some(t) = self.theta {
            k.push_str(&format!("/theta={t}"));
        }
        // Only when not the default, so that the keys of earlier results stay valid.
        if self.multipole != Multipole::Monopole {
            k.push_str(&format!("/{}", self.multipole.name()));
        }
        if let Some(p) = self.precision {
            k.push_str(&format!("/{}", p.name()));
        }
        if self.time_factor != 1 {
            k.push_str(&format!("/time-x{}", self.time_factor));
        }
        if let Some(d) = self.decomp {
            k.push_str(&format!("/{}", d.name()));
        }
        k
    }
}

/// Whether `m` is the default order (left out of case files and keys).
pub fn is_monopole(m: &Multipole) -> bool {
    *m == Multipole::Monopole
}

/// The cases of a config, in a fixed order: scenario, kernel, n, threads, seed, θ, multipole.
pub fn cases(config: &SweepConfig) -> Vec<Case> {
    let mut out = Vec::new();
    for &scenario in &config.scenarios {
        for &kernel in config.kernels.iter().filter(|k| k.supports(scenario.law())) {
            let (thetas, orders): (Vec<Option<f64>>, Vec<Multipole>) =
                if kernel == KernelKind::Octree {
                    (
                        config.theta.iter().map(|&t| Some(t)).collect(),
                        config.multipole.clone(),
                    )
                } else {
                    (vec![None], vec![Multipole::Monopole])
                };
            // Without MPI one launch of one rank; under a launcher, every rank count with
            // every decomposition that runs this kernel.
            let launches: Vec<(usize, Option<Decomposition>)> = match &config.mpi {
                None => vec![(1, None)],
                Some(m) => m
                    .ranks
                    .iter()
                    .flat_map(|&r| {
                        m.decomp
                            .iter()
                            .filter(|d| d.supports(kernel))
                            .map(move |&d| (r, Some(d)))
                    })
                    .collect(),
            };
            for (&threads, &(ranks, decomp)) in config
                .threads
                .iter()
                .flat_map(|t| launches.iter().map(move |l| (t, l)))
            {
                let workers = threads * ranks;
                let sizes: Vec<(usize, u64)> = match (&config.study, &config.weak) {
                    (Study::Weak, Some(w)) => vec![weak_size(kernel, w.rule, w.base_n, workers)],
                    _ => config
                        .n
                        .as_ref()
                        .map(|n| n.values())
                        .unwrap_or_default()
                        .into_iter()
                        .map(|n| (n, 1))
                        .collect(),
                };
                for (n, time_factor) in sizes {
                    for &seed in &config.seeds {
                        for &theta in &thetas {
                            for &multipole in &orders {
                                out.push(Case {
                                    scenario,
                                    kernel,
                                    n,
                                    threads,
                                    ranks,
                                    theta,
                                    multipole,
                                    seed,
                                    precision: config.precision,
                                    time_factor,
                                    decomp,
                                });
                            }
                        }
                    }
                }
            }
        }
    }
    out.sort_by_key(|c| {
        let decomp = c.decomp.map_or(0, |d| d as u8 + 1);
        (
            c.scenario as u8,
            c.kernel as u8,
            decomp,
            c.n,
            c.threads,
            c.ranks,
            c.seed,
        )
    });
    out
}

/// n (and simulated-time factor) at `p` threads so that the work per thread stays that of
/// `base_n` on one thread.
pub fn weak_size(kernel: KernelKind, rule: WeakRule, base_n: usize, p: usize) -> (usize, u64) {
    let pf = p as f64;
    let b = base_n as f64;
    let n = match rule {
        WeakRule::Time => return (base_n, p as u64),
        WeakRule::Linear => b * pf,
        WeakRule::Sqrt => b * pf.sqrt(),
        WeakRule::CostModel => match kernel {
            KernelKind::CellList | KernelKind::Verlet => b * pf,
            KernelKind::Naive | KernelKind::Symmetric | KernelKind::PerThread => b * pf.sqrt(),
            KernelKind::Octree => solve_n_log_n(pf * b * b.max(2.0).ln()),
        },
    };
    (n.round().max(1.0) as usize, 1)
}

/// n with n·ln n = w (Newton's method; w ≥ 2 ln 2).
fn solve_n_log_n(w: f64) -> f64 {
    let mut n = (w / w.max(2.0).ln()).max(2.0);
    for _ in 0..50 {
        let f = n * n.ln() - w;
        n -= f / (n.ln() + 1.0);
        n = n.max(2.0);
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weak_sizes_follow_the_cost_model() {
        assert_eq!(
            weak_size(KernelKind::CellList, WeakRule::CostModel, 1000, 4),
            (4000, 1)
        );
        assert_eq!(
            weak_size(KernelKind::Naive, WeakRule::CostModel, 1000, 4),
            (2000, 1)
        );
        assert_eq!(
            weak_size(KernelKind::Naive, WeakRule::Time, 1000, 4),
            (1000, 4)
        );
        let (n, _) = weak_size(KernelKind::Octree, WeakRule::CostModel, 10_000, 2);
        let w = |n: f64| n * n.ln();
        assert!((w(n as f64) / w(10_000.0) - 2.0).abs() < 1e-3, "{n}");
        assert!(n > 18_000 && n < 20_000);
    }

    #[test]
    fn case_keys_are_distinct() {
        let text = r#"
            name = "t"
            study = "cartesian"
            scenarios = ["galaxy", "lj-box"]
            kernels = ["naive", "octree", "cell-list"]
            n = [100, 200]
            threads = [1, 2]
            theta = [0.3, 0.6]
        "#;
        let c = SweepConfig::parse(text, std::path::Path::new("t.toml")).unwrap();
        let cases = cases(&c);
        // galaxy: naive 2n×2p + octree 2n×2p×2θ; lj-box: naive + cell-list 2n×2p each.
        assert_eq!(cases.len(), 4 + 8 + 4 + 4);
        let mut keys: Vec<String> = cases.iter().map(Case::key).collect();
        keys.sort();
        keys.dedup();
        assert_eq!(keys.len(), cases.len());
        assert!(keys.contains(&"galaxy/octree/n=100/p=2/r=1/seed=1/theta=0.3".to_string()));
    }

    /// The expansion order multiplies the octree cases only, and only the quadrupole's keys
    /// (and case files) mention it, so results written before it keep their keys.
    #[test]
    fn multipole_is_a_dimension_of_octree_cases() {
        let text = r#"
            name = "t"
            study = "cartesian"
            scenarios = ["galaxy"]
            kernels = ["naive", "octree"]
            n = [100]
            theta = [0.3, 0.6]
            multipole = ["monopole", "quadrupole"]
        "#;
        let c = SweepConfig::parse(text, std::path::Path::new("t.toml")).unwrap();
        let cases = cases(&c);
        assert_eq!(cases.len(), 1 + 2 * 2);
        let keys: Vec<String> = cases.iter().map(Case::key).collect();
        for key in [
            "galaxy/naive/n=100/p=1/r=1/seed=1",
            "galaxy/octree/n=100/p=1/r=1/seed=1/theta=0.3",
            "galaxy/octree/n=100/p=1/r=1/seed=1/theta=0.3/quadrupole",
        ] {
            assert!(keys.contains(&key.to_string()), "{key} not in {keys:?}");
        }
        let mono = cases
            .iter()
            .find(|c| c.kernel == KernelKind::Octree)
            .unwrap();
        let json = serde_json::to_string(mono).unwrap();
        assert!(!json.contains("multipole"), "{json}");
        let quad = cases
            .iter()
            .find(|c| c.multipole == Multipole::Quadrupole)
            .unwrap();
        let back: Case = serde_json::from_str(&serde_json::to_string(quad).unwrap()).unwrap();
        assert_eq!(&back, quad);
        let bad = text.replace(r#"["monopole", "quadrupole"]"#, "[]");
        assert!(SweepConfig::parse(&bad, std::path::Path::new("t.toml")).is_err());
    }
}
