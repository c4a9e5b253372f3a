//! Reads the cases of a results file as series: the same code over n (complexity), over p at
//! fixed n (strong scaling), over p with the work per worker held (weak scaling), and over θ
//! (octree accuracy, one series per expansion order; an external family's settings likewise).
//! Pure data; the fits and plots are elsewhere.

use nbody_engine::decomp::Decomposition;
use nbody_engine::engine::PhaseTimes;
use nbody_engine::kernels::{KernelKind, Multipole};
use nbody_engine::scenario::{Precision, ScenarioKind};
use nbody_engine::stats::StepPercentiles;
use nbody_records::config::Study;
use nbody_records::external::{External, PhaseKind};
use nbody_records::kernel_or_program::KernelOrProgram;
use nbody_records::results::{CaseRecord, ResultsFile};
use serde::Serialize;

/// One measured case as the analysis sees it.
#[derive(Clone, Debug, Serialize)]
pub struct Point {
    /// The case itself, typed; consumers read kernel, scenario and precision from here, never
    /// from the key.
    #[serde(skip)]
    pub case: nbody_records::plan::Case,
    /// The case's key in the results file, unique there; what tables and figures name it by.
    pub key: String,
    /// Particles simulated.
    pub n: usize,
    /// Threads per rank.
    pub threads: usize,
    /// MPI ranks (1 without MPI).
    pub ranks: usize,
    /// Simulated-time factor of a weak-by-time case (1 otherwise).
    pub time_factor: u64,
    /// The opening angle θ (octree and fmm cases only).
    pub theta: Option<f64>,
    /// MPI decomposition of a case run under a launcher.
    pub decomp: Option<Decomposition>,
    /// Mean over ranks of the time inside MPI calls and of the bytes sent, per step (MPI cases);
    /// for an external program, its `comm` phases as it reports them.
    pub comm_s_per_step: Option<f64>,
    pub(crate) bytes_per_step: Option<f64>,
    /// Of `comm_s_per_step`, the part left after the estimated wait for slower ranks: moving
    /// data and MPI overhead (MPI cases).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) transfer_s_per_step: Option<f64>,
    /// Mean over the rounds of max/mean over ranks of the compute time (MPI cases).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compute_imbalance: Option<f64>,
    /// Seconds per step: every raw sample, the median and its bootstrap 95% CI.
    #[serde(skip)]
    pub samples: Vec<f64>,
    /// The median of `samples`, seconds per step.
    pub median_s: f64,
    /// The bootstrap 95% CI of that median, `[low, high]` seconds per step.
    pub ci95_s: [f64; 2],
    /// Threads × ranks exceeded the machine's logical CPUs (time-sharing, left out of fits).
    pub oversubscribed: bool,
    /// The median step time per particle, nanoseconds.
    pub ns_per_particle_step: f64,
    /// `None` when the code counted no pair (an external program).
    pub pair_evals_per_s: Option<f64>,
    /// Candidate pairs examined per step, the work counter that rate is of (whether a step
    /// was worth a fork is decided on it); `None` when the code counted no pair.
    #[serde(skip)]
    pub pair_checks_per_step: Option<f64>,
    /// Seconds per step in each of the engine's phases, averaged over rounds; `None` (`null`)
    /// where no timer of ours ran (an external program, which may time its own: `named_phases`).
    pub phases: Option<PhaseTimes>,
    /// The phases an external program timed itself (`phases`), by name.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub named_phases: Vec<NamedPhase>,
    /// `None` when no step was timed alone (an external program is timed per run).
    pub step_ns: Option<StepPercentiles>,
    /// Median and largest relative force error, `[median, max]`; `None` when not measured.
    pub force_error: Option<[f64; 2]>,
    /// `None` when nothing measured the energy (an external program).
    pub max_energy_drift: Option<f64>,
    /// Whether that drift stayed within the config's `max_energy_drift`; `None` without a drift.
    pub sanity_ok: Option<bool>,
}

impl Point {
    /// Workers: threads × ranks.
    pub fn p(&self) -> usize {
        self.threads * self.ranks
    }

    /// For a member of the external family `series` (a series named after the family, not
    /// after this case's program), its setting: the program's name without the family's
    /// ("eps1e-2" of "fmm3d-eps1e-2"), or the whole name; `None` when the case is the series'
    /// own code.
    pub(crate) fn family_setting(&self, series: &str) -> Option<String> {
        let name = self.case.kernel.name();
        if name == series {
            return None;
        }
        let short = name
            .strip_prefix(series)
            .map(|s| s.trim_start_matches(['-', '_', '.']))
            .filter(|s| !s.is_empty());
        Some(short.unwrap_or(name).to_string())
    }

    /// The mean of the samples: the step time the means over runs (an external program's phases)
    /// are shares of.
    pub(crate) fn mean_step_s(&self) -> f64 {
        self.samples.iter().sum::<f64>() / self.samples.len().max(1) as f64
    }

    /// Whether this case ran with `p` workers, `p` as a fit gives it back (a float).
    pub(crate) fn has_workers(&self, p: f64) -> bool {
        p.is_finite() && p >= 0.0 && self.p() == p.round() as usize
    }
}

/// A phase an external program timed: seconds per step, the mean over its successful runs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NamedPhase {
    /// The phase's name as the program's `[[external]]` entry gives it.
    pub name: String,
    /// Whether the phase is parallel, serial or communication.
    pub kind: PhaseKind,
    /// Seconds per step in the phase, the mean over successful runs.
    pub s_per_step: f64,
}

/// The phases of an external case, per step, from every successful run of every round.
fn named_phases(r: &CaseRecord, ext: Option<&External>) -> Vec<NamedPhase> {
    let Some(ext) = ext else {
        return Vec::new();
    };
    ext.phases
        .iter()
        .filter_map(|(name, source)| {
            let per_step: Vec<f64> = r
                .rounds
                .iter()
                .filter_map(|round| Some((round.external.as_ref()?, round.steps_per_sample)))
                .flat_map(|(e, steps)| {
                    e.runs
                        .iter()
                        .filter(|run| run.error.is_none())
                        .filter_map(move |run| Some(run.phases.get(name)? / steps.max(1) as f64))
                })
                .collect();
            (!per_step.is_empty()).then(|| NamedPhase {
                name: name.clone(),
                kind: source.kind,
                s_per_step: per_step.iter().sum::<f64>() / per_step.len() as f64,
            })
        })
        .collect()
}

/// What a series holds fixed. `None` fields vary along the series or do not apply.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SeriesKey {
    /// The scenario every case of the series simulates.
    pub scenario: ScenarioKind,
    /// The kernel or external program; an external family's name for a θ series of its members.
    pub kernel: KernelOrProgram,
    /// The floating-point precision (the scenario's default when the case set none).
    pub precision: Precision,
    /// The opening angle; `None` along a θ series or for codes without one.
    pub theta: Option<f64>,
    /// The octree's expansion order (absent from the JSON when monopole, as in case keys).
    #[serde(skip_serializing_if = "nbody_records::plan::is_monopole")]
    pub multipole: Multipole,
    /// The fmm's expansion order.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub order: Option<usize>,
    /// The neighbour-list skin, when the config set one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skin: Option<f64>,
    /// The particle count; `None` along a complexity series and a weak-scaling one.
    pub n: Option<usize>,
    /// Threads per rank; `None` along a strong- or weak-scaling series.
    pub threads: Option<usize>,
    /// MPI ranks; `None` along a strong- or weak-scaling series.
    pub ranks: Option<usize>,
    /// The MPI decomposition; `None` for cases run without a launcher.
    pub decomp: Option<Decomposition>,
}

impl SeriesKey {
    /// A short legend label, e.g. "octree θ=0.5" or "naive, 2 threads".
    pub(crate) fn label(&self) -> String {
        let mut s = self.kernel.name().to_string();
        if let Some(t) = self.theta {
            s.push_str(&format!(" θ={t}"));
        }
        if self.multipole != Multipole::Monopole {
            s.push_str(&format!(" {}", self.multipole.name()));
        }
        // "order", not "p=": the case keys' p= is the threads.
        if let Some(p) = self.order {
            s.push_str(&format!(" order {p}"));
        }
        if let Some(skin) = self.skin {
            s.push_str(&format!(" skin {skin}"));
        }
        if let Some(d) = self.decomp {
            s.push_str(&format!(" ({})", d.name()));
        }
        if let (Some(t), Some(r)) = (self.threads, self.ranks) {
            s.push_str(&workers_suffix(t, r));
        }
        s
    }
}

/// The workers of a label: nothing for one, else ", 2 threads", ", 2 ranks" or
/// ", 2 threads × 2 ranks".
pub(crate) fn workers_suffix(threads: usize, ranks: usize) -> String {
    match (threads, ranks) {
        (1, 1) => String::new(),
        (t, 1) => format!(", {t} threads"),
        (1, r) => format!(", {r} ranks"),
        (t, r) => format!(", {t} threads × {r} ranks"),
    }
}

/// What the p of a scaling series counts, for an axis, from its cases' `(threads, ranks)`:
/// "threads" when every case ran one rank, "ranks" when every case ran one thread, else
/// "workers (threads × ranks)".
pub(crate) fn workers_noun(cases: impl IntoIterator<Item = (usize, usize)>) -> &'static str {
    let (mut threads, mut ranks) = (false, false);
    for (t, r) in cases {
        threads |= t > 1;
        ranks |= r > 1;
    }
    match (threads, ranks) {
        (false, true) => "ranks",
        (true, true) => "workers (threads × ranks)",
        _ => "threads",
    }
}

/// Cases that differ only in the quantity the series varies, sorted by it.
#[derive(Clone, Debug, Serialize)]
pub struct Series {
    /// What the cases have in common.
    pub key: SeriesKey,
    /// The cases, sorted by the quantity the series varies (n, p, θ or force error).
    pub points: Vec<Point>,
}

/// The series a results file supports.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Groups {
    /// Over n at fixed threads and ranks (two or more distinct n).
    pub complexity: Vec<Series>,
    /// Over p at fixed n, from p = 1 (not in weak studies).
    pub strong: Vec<Series>,
    /// Over p with n or simulated time grown by the weak rule (weak studies only).
    pub weak: Vec<Series>,
    /// Tree cases over θ at fixed n and p, and the members of an external family (one code at
    /// several accuracy settings) as one series named after the family.
    pub theta: Vec<Series>,
    /// Every complete case, in file order.
    pub cases: Vec<Point>,
}

/// Reads the complete cases of `results` into series.
pub fn group(results: &ResultsFile) -> Groups {
    let point = |r: &CaseRecord| {
        let ext = results
            .config
            .external
            .iter()
            .find(|e| r.case.kernel.kernel().is_none() && e.name == r.case.kernel.name());
        point(r, ext)
    };
    let cases: Vec<Point> = results.cases.iter().filter_map(point).collect();
    let weak = results.config.study == Study::Weak;
    let base = |c: &Point, r: &CaseRecord| SeriesKey {
        scenario: r.case.scenario,
        kernel: r.case.kernel.clone(),
        precision: precision_of(r),
        theta: c.theta,
        multipole: r.case.multipole,
        order: r.case.order,
        skin: r.case.skin,
        n: Some(c.n),
        threads: Some(c.threads),
        ranks: Some(c.ranks),
        decomp: c.decomp,
    };
    // Each complete case with its record (`cases` was built from these records, in order).
    let records: Vec<(&Point, &CaseRecord)> = cases
        .iter()
        .zip(results.cases.iter().filter(|r| point(r).is_some()))
        .collect();
    let series = |vary: &dyn Fn(&mut SeriesKey), order: &dyn Fn(&Point) -> f64| {
        let mut out: Vec<Series> = Vec::new();
        for &(c, r) in &records {
            let mut key = base(c, r);
            vary(&mut key);
            match out.iter_mut().find(|s| s.key == key) {
                Some(s) => s.points.push(c.clone()),
                None => out.push(Series {
                    key,
                    points: vec![c.clone()],
                }),
            }
        }
        for s in &mut out {
            s.points.sort_by(|a, b| order(a).total_cmp(&order(b)));
        }
        out
    };
    let distinct = |s: &Series, f: &dyn Fn(&Point) -> f64| {
        let mut v: Vec<f64> = s.points.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v.len()
    };
    let by_n = |p: &Point| p.n as f64;
    let by_p = |p: &Point| p.p() as f64;
    let by_theta = |p: &Point| p.theta.unwrap_or(0.0);
    let complexity = series(&|k| k.n = None, &by_n)
        .into_iter()
        .filter(|s| !weak && distinct(s, &by_n) >= 2)
        .collect();
    let parallel = series(
        &|k| {
            k.threads = None;
            k.ranks = None;
            if weak {
                k.n = None;
            }
        },
        &by_p,
    );
    let from_one = |s: &Series| s.points.iter().any(|c| c.p() == 1) && distinct(s, &by_p) >= 2;
    let (weak_series, strong) = if weak {
        (parallel.into_iter().filter(from_one).collect(), Vec::new())
    } else {
        (Vec::new(), parallel.into_iter().filter(from_one).collect())
    };
    // Over θ, or over the members of an external family (one point each, in order of error).
    let family = |k: &KernelOrProgram| {
        results
            .config
            .external
            .iter()
            .find(|e| e.name == k.name())
            .and_then(|e| e.family.clone())
    };
    let by_accuracy = |p: &Point| match family(&p.case.kernel) {
        Some(_) => p.force_error.map_or(0.0, |e| e[0]),
        None => by_theta(p),
    };
    let theta = series(
        &|k| {
            k.theta = None;
            if let Some(f) = family(&k.kernel) {
                k.kernel = KernelOrProgram::External(f);
            }
        },
        &by_accuracy,
    )
    .into_iter()
    .filter(|s| {
        (s.key.kernel == KernelKind::Octree
            || s.key.kernel.kernel().is_some_and(KernelKind::is_fmm)
            || s.key.kernel.is_external())
            && distinct(s, &by_accuracy) >= 2
    })
    .collect();
    Groups {
        complexity,
        strong,
        weak: weak_series,
        theta,
        cases,
    }
}

fn precision_of(r: &CaseRecord) -> Precision {
    r.case
        .precision
        .unwrap_or(r.case.scenario.defaults().precision)
}

/// The analysis view of a complete case (`ext`: its program's entry, for an external one);
/// `None` for a case still being measured.
fn point(r: &CaseRecord, ext: Option<&External>) -> Option<Point> {
    let s = r.summary.as_ref()?;
    if !r.is_complete() || s.samples == 0 {
        return None;
    }
    let named_phases = named_phases(r, ext);
    // A program's own communication phases stand where an MPI driver's counted time does.
    let own_comm = named_phases
        .iter()
        .filter(|p| p.kind == PhaseKind::Comm)
        .map(|p| p.s_per_step)
        .reduce(|a, b| a + b);
    Some(Point {
        case: r.case.clone(),
        key: r.key.clone(),
        n: r.n,
        threads: r.case.threads,
        ranks: r.case.ranks,
        time_factor: r.case.time_factor,
        theta: r.case.theta,
        decomp: r.case.decomp,
        comm_s_per_step: mpi_mean(r, &|m| m.reduced.comm_s.mean).or(own_comm),
        bytes_per_step: mpi_mean(r, &|m| m.reduced.bytes_sent.mean),
        transfer_s_per_step: mpi_mean(r, &|m| m.reduced.transfer_s.mean),
        compute_imbalance: {
            let per_round: Vec<f64> = r
                .rounds
                .iter()
                .filter_map(|round| Some(round.mpi.as_ref()?.reduced.compute_imbalance))
                .collect();
            (!per_round.is_empty()).then(|| per_round.iter().sum::<f64>() / per_round.len() as f64)
        },
        samples: r
            .rounds
            .iter()
            .flat_map(|round| round.samples_s.iter().copied())
            .collect(),
        median_s: s.median_s,
        ci95_s: s.ci95_s,
        oversubscribed: r.oversubscribed,
        ns_per_particle_step: s.ns_per_particle_step,
        pair_evals_per_s: s.pair_evals_per_s,
        pair_checks_per_step: s.pair_evals_per_s.and(s.pair_checks_per_step),
        phases: s.phases,
        named_phases,
        step_ns: s.step_ns,
        force_error: s.force_error,
        max_energy_drift: s.max_energy_drift,
        sanity_ok: s.sanity_ok,
    })
}

/// Mean over the rounds of an MPI statistic (a total over the round's steps), per step.
fn mpi_mean(
    r: &CaseRecord,
    f: &dyn Fn(&nbody_engine::decomp::stats::MpiReport) -> f64,
) -> Option<f64> {
    let per_step: Vec<f64> = r
        .rounds
        .iter()
        .filter_map(|round| Some(f(round.mpi.as_ref()?) / round.steps.max(1) as f64))
        .collect();
    (!per_step.is_empty()).then(|| per_step.iter().sum::<f64>() / per_step.len() as f64)
}

#[cfg(test)]
mod tests {
    use super::{SeriesKey, workers_noun, workers_suffix};
    use nbody_engine::kernels::{KernelKind, Multipole};
    use nbody_engine::scenario::{Precision, ScenarioKind};
    use nbody_records::kernel_or_program::KernelOrProgram;

    #[test]
    fn the_fmm_order_is_named_apart_from_the_threads() {
        let key = SeriesKey {
            scenario: ScenarioKind::Coulomb,
            kernel: KernelOrProgram::Kernel(KernelKind::Fmm),
            precision: Precision::F64,
            theta: Some(0.5),
            multipole: Multipole::Monopole,
            order: Some(4),
            skin: None,
            n: None,
            threads: Some(2),
            ranks: Some(1),
            decomp: None,
        };
        assert_eq!(key.label(), "fmm θ=0.5 order 4, 2 threads");
    }

    #[test]
    fn workers_are_named_in_labels() {
        assert_eq!(workers_suffix(1, 1), "");
        assert_eq!(workers_suffix(2, 1), ", 2 threads");
        assert_eq!(workers_suffix(1, 2), ", 2 ranks");
        assert_eq!(workers_suffix(2, 2), ", 2 threads × 2 ranks");
    }

    #[test]
    fn scaling_axes_name_what_p_counts() {
        assert_eq!(workers_noun([(1, 1), (2, 1), (4, 1)]), "threads");
        assert_eq!(workers_noun([(1, 1), (1, 2), (1, 4)]), "ranks");
        assert_eq!(
            workers_noun([(1, 1), (2, 1), (1, 2)]),
            "workers (threads × ranks)"
        );
        assert_eq!(workers_noun([]), "threads");
    }
}
