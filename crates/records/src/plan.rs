//! Expands a sweep config into the list of cases to measure.

use super::config::{Study, SweepConfig, WeakRule};
use super::kernel_or_program::KernelOrProgram;
use nbody_engine::decomp::Decomposition;
use nbody_engine::kernels::{KernelKind, KernelParams, Multipole};
use nbody_engine::scenario::{Precision, ScenarioKind};
use serde::{Deserialize, Serialize};

/// One measured configuration: everything that changes the work or the machine use.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Case {
    /// The initial state and force law simulated.
    pub scenario: ScenarioKind,
    /// A built-in kernel or an external program, by name.
    pub kernel: KernelOrProgram,
    /// Particle count of the whole system (in a weak study, derived from `weak.base_n`).
    pub n: usize,
    /// Worker threads of each rank (of the process without MPI).
    pub threads: usize,
    /// MPI ranks (1 without MPI).
    pub ranks: usize,
    /// Opening angle, for the octree and the fmm only.
    pub theta: Option<f64>,
    /// Expansion order of the octree's nodes; absent (monopole) in files written before it.
    #[serde(default, skip_serializing_if = "is_monopole")]
    pub multipole: Multipole,
    /// Expansion order p of the fmm's cells, for the fmm only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub order: Option<usize>,
    /// Neighbour-list skin, for verlet and cluster-pair when the config names one (else the
    /// kernel's default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub skin: Option<f64>,
    /// Seed of the initial state.
    pub seed: u64,
    /// Floating-point precision the config imposes; `None`: each scenario's own.
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
        if let Some(p) = self.order {
            k.push_str(&format!("/order={p}"));
        }
        if let Some(s) = self.skin {
            k.push_str(&format!("/skin={s}"));
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

    /// The kernel parameters the case runs with: its θ and expansion order, the defaults
    /// for the rest.
    pub fn kernel_params(&self) -> KernelParams {
        let defaults = KernelParams::default();
        KernelParams {
            theta: self.theta.unwrap_or(defaults.theta),
            multipole: self.multipole,
            order: self.order.unwrap_or(defaults.order),
            skin: self.skin.unwrap_or(defaults.skin),
            ..defaults
        }
    }
}

/// Whether `m` is the default order (left out of case files and keys).
pub fn is_monopole(m: &Multipole) -> bool {
    *m == Multipole::Monopole
}

/// The cases of `config`, refused when two share a key (an `[[external]]` named like a
/// built-in kernel, say): one would be measured and reported for both.
pub fn unique_cases(config: &SweepConfig) -> Result<Vec<Case>, String> {
    let planned = cases(config);
    let mut keys = std::collections::HashSet::new();
    if let Some(c) = planned.iter().find(|c| !keys.insert(c.key())) {
        return Err(format!(
            "config `{}`: two planned cases share the key `{}`; give each code its own name \
             and list each value once",
            config.name,
            c.key()
        ));
    }
    Ok(planned)
}

/// The cases of a config, in a fixed order: the externals' first, then per scenario, kernel,
/// n, threads, seed, θ, multipole or fmm order.
pub fn cases(config: &SweepConfig) -> Vec<Case> {
    let mut out = Vec::new();
    external_cases(config, &mut out);
    for &scenario in &config.scenarios {
        for &kernel in config.kernels.iter().filter(|k| k.supports(scenario.law())) {
            let thetas: Vec<Option<f64>> = match kernel {
                KernelKind::Octree => config.theta.iter().map(|&t| Some(t)).collect(),
                // The fmm's expansions converge for θ below 1 only (validation keeps one).
                k if k.is_fmm() => config
                    .theta
                    .iter()
                    .filter(|&&t| t < 1.0)
                    .map(|&t| Some(t))
                    .collect(),
                _ => vec![None],
            };
            // The expansion orders: the octree's multipoles, the fmm's p.
            let orders: Vec<(Multipole, Option<usize>)> = match kernel {
                KernelKind::Octree => config.multipole.iter().map(|&m| (m, None)).collect(),
                // The Cartesian fmm's orders stop at 8 (validation keeps one); the harmonic
                // one's go on.
                k if k.is_fmm() => config
                    .order
                    .iter()
                    .filter(|&&p| {
                        k == KernelKind::FmmHarmonic || p <= nbody_engine::kernels::MAX_FMM_ORDER
                    })
                    .map(|&p| (Multipole::Monopole, Some(p)))
                    .collect(),
                _ => vec![(Multipole::Monopole, None)],
            };
            let skins: Vec<Option<f64>> = match kernel {
                KernelKind::Verlet | KernelKind::ClusterPair if config.skin.is_some() => {
                    config.skin.iter().flatten().map(|&s| Some(s)).collect()
                }
                _ => vec![None],
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
                    (Study::Weak, Some(w)) => {
                        vec![weak_size(Some(kernel), w.rule, w.base_n, workers)]
                    }
                    _ => fixed_sizes(config),
                };
                for (n, time_factor) in sizes {
                    for &seed in &config.seeds {
                        for &theta in &thetas {
                            for &(multipole, order) in &orders {
                                for &skin in &skins {
                                    out.push(Case {
                                        scenario,
                                        kernel: KernelOrProgram::Kernel(kernel),
                                        n,
                                        threads,
                                        ranks,
                                        theta,
                                        multipole,
                                        order,
                                        skin,
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
    }
    out.sort_by_key(|c| {
        let decomp = c.decomp.map_or(0, |d| d as u8 + 1);
        (
            c.scenario as u8,
            c.kernel.order(),
            decomp,
            c.n,
            c.threads,
            c.ranks,
            c.seed,
        )
    });
    out
}

/// The n list of a study that is not weak, each with time factor 1.
fn fixed_sizes(config: &SweepConfig) -> Vec<(usize, u64)> {
    config
        .n
        .as_ref()
        .map(|n| n.values())
        .unwrap_or_default()
        .into_iter()
        .map(|n| (n, 1))
        .collect()
}

/// The cases of the `[[external]]` entries: each scenario, thread count, rank count, n and
/// seed, and each θ when the program is told θ.
fn external_cases(config: &SweepConfig, out: &mut Vec<Case>) {
    for ext in &config.external {
        let scenarios = ext.scenarios.clone().unwrap_or(config.scenarios.clone());
        let threads = ext.threads.clone().unwrap_or(config.threads.clone());
        let ranks = ext.ranks.clone().unwrap_or_else(|| match &config.mpi {
            Some(m) => m.ranks.clone(),
            None => vec![1],
        });
        let thetas: Vec<Option<f64>> = if ext.uses("theta") {
            config.theta.iter().map(|&t| Some(t)).collect()
        } else {
            vec![None]
        };
        for &scenario in &scenarios {
            for &t in &threads {
                for &r in &ranks {
                    let sizes = match (&config.study, &config.weak, &ext.n) {
                        (Study::Weak, Some(w), _) => {
                            vec![weak_size(None, w.rule, w.base_n, t * r)]
                        }
                        (_, _, Some(n)) => n.iter().map(|&n| (n, 1)).collect(),
                        _ => fixed_sizes(config),
                    };
                    for &(n, time_factor) in &sizes {
                        for &seed in &config.seeds {
                            for &theta in &thetas {
                                out.push(Case {
                                    scenario,
                                    kernel: KernelOrProgram::External(ext.name.clone()),
                                    n,
                                    threads: t,
                                    ranks: r,
                                    theta,
                                    multipole: Multipole::Monopole,
                                    order: None,
                                    skin: None,
                                    seed,
                                    precision: config.precision,
                                    time_factor,
                                    decomp: None,
                                });
                            }
                        }
                    }
                }
            }
        }
    }
}

/// n (and simulated-time factor) at `p` threads so that the work per thread stays that of
/// `base_n` on one thread. An external program (`None`) has no known cost model: its config
/// names a rule (validation refuses `cost-model` for it), and `cost-model` reads as linear.
pub(crate) fn weak_size(
    kernel: Option<KernelKind>,
    rule: WeakRule,
    base_n: usize,
    p: usize,
) -> (usize, u64) {
    let pf = p as f64;
    let b = base_n as f64;
    let n = match rule {
        WeakRule::Time => return (base_n, p as u64),
        WeakRule::Linear => b * pf,
        WeakRule::Sqrt => b * pf.sqrt(),
        WeakRule::CostModel => match kernel {
            None
            | Some(
                KernelKind::CellList
                | KernelKind::Verlet
                | KernelKind::ClusterPair
                | KernelKind::Fmm
                | KernelKind::FmmHarmonic,
            ) => b * pf,
            Some(KernelKind::Naive | KernelKind::Symmetric | KernelKind::PerThread) => {
                b * pf.sqrt()
            }
            Some(KernelKind::Octree) => solve_n_log_n(pf * b * b.max(2.0).ln()),
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
            weak_size(Some(KernelKind::CellList), WeakRule::CostModel, 1000, 4),
            (4000, 1)
        );
        assert_eq!(
            weak_size(Some(KernelKind::Naive), WeakRule::CostModel, 1000, 4),
            (2000, 1)
        );
        assert_eq!(
            weak_size(Some(KernelKind::Naive), WeakRule::Time, 1000, 4),
            (1000, 4)
        );
        let (n, _) = weak_size(Some(KernelKind::Octree), WeakRule::CostModel, 10_000, 2);
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
        // The default order is the quadrupole, which the keys name (a monopole case's key does
        // not, as before the order was recorded).
        assert!(
            keys.contains(&"galaxy/octree/n=100/p=2/r=1/seed=1/theta=0.3/quadrupole".to_string())
        );
    }

    /// Skins multiply the verlet and cluster-pair cases only; their keys name the skin, and a
    /// config without the key plans the keys it always did.
    #[test]
    fn skin_is_a_dimension_of_the_list_kernels() {
        let text = r#"
            name = "t"
            study = "cartesian"
            scenarios = ["lj-box"]
            kernels = ["cell-list", "verlet"]
            n = [100]
            skin = [0.003, 0.012]
        "#;
        let c = SweepConfig::parse(text, std::path::Path::new("t.toml")).unwrap();
        let keys: Vec<String> = cases(&c).iter().map(Case::key).collect();
        assert_eq!(
            keys,
            [
                "lj-box/cell-list/n=100/p=1/r=1/seed=1",
                "lj-box/verlet/n=100/p=1/r=1/seed=1/skin=0.003",
                "lj-box/verlet/n=100/p=1/r=1/seed=1/skin=0.012",
            ]
        );
        let verlet = cases(&c)
            .into_iter()
            .find(|c| c.skin == Some(0.012))
            .unwrap();
        assert_eq!(verlet.kernel_params().skin, 0.012);
        let without = SweepConfig::parse(
            &text.replace("skin = [0.003, 0.012]", ""),
            std::path::Path::new("t.toml"),
        )
        .unwrap();
        assert!(
            cases(&without)
                .iter()
                .all(|c| !c.key().contains("skin") && c.skin.is_none())
        );
        let wrong = text.replace(r#"["cell-list", "verlet"]"#, r#"["cell-list"]"#);
        assert!(SweepConfig::parse(&wrong, std::path::Path::new("t.toml")).is_err());
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
