//! Offline analysis of a sweep: the series of a results file ([`groups`]) and the models fitted
//! to them (complexity in n, strong and weak scaling, crossovers). Pure computation: no file is
//! read or written here; `crate::render` turns an [`Analysis`] into tables, figures and files.
//! Everything is recomputed from the raw samples, with seeded bootstraps, so the same results
//! file always gives the same analysis.

pub mod comm_model;
pub mod crossover;
pub(crate) mod each_program;
pub mod family;
pub mod forking;
pub mod groups;
pub mod peers;
pub mod tree_comm;
mod views;

use crate::fit::{
    self, ComplexityClass, PowerFit, Samples, SerialFractionComparison, SharedMachine, StrongFit,
    TimedSerialFraction, WeakFit, WeakSamples,
};
use crossover::Crossover;
use groups::{Groups, Point, Series, SeriesKey};
use nbody_calibrate::Calibration;
use nbody_engine::kernels::KernelKind;
use nbody_records::config::{Study, WeakRule};
use nbody_records::external::PhaseKind;
use nbody_records::kernel_or_program::KernelOrProgram;
use nbody_records::results::{Metadata, ResultsFile};
use serde::Serialize;
use std::path::{Path, PathBuf};
use thiserror::Error;

pub(crate) const FITS_SCHEMA: &str = "nbody-bench/fits/v1";

/// A fit, or why there is none (too few points, …): a series is never dropped silently.
#[derive(Clone, Debug, Serialize)]
pub struct Fitted<T> {
    /// The fit; `None` when it was refused.
    pub fit: Option<T>,
    /// Why the fit was refused (a [`fit::FitError`]'s message); `None` when there is a fit.
    pub error: Option<String>,
}

impl<T> Fitted<T> {
    fn of(result: Result<T, fit::FitError>) -> Self {
        match result {
            Ok(fit) => Fitted {
                fit: Some(fit),
                error: None,
            },
            Err(e) => Fitted {
                fit: None,
                error: Some(e.to_string()),
            },
        }
    }
}

/// A series over n at fixed workers and the power law and complexity class fitted to it.
#[derive(Clone, Debug, Serialize)]
pub struct ComplexityAnalysis {
    /// What the series' cases have in common.
    pub series: SeriesKey,
    pub(crate) label: String,
    /// The cases, in increasing n.
    pub points: Vec<Point>,
    /// The power law and complexity class fitted to their step times.
    pub fit: Fitted<PowerFit>,
}

/// A series over p at fixed n (from p = 1) and the strong-scaling models fitted to it.
#[derive(Clone, Debug, Serialize)]
pub struct StrongAnalysis {
    /// What the series' cases have in common.
    pub series: SeriesKey,
    pub(crate) label: String,
    /// The cases, in increasing p (threads × ranks), oversubscribed ones included.
    pub points: Vec<Point>,
    /// Speedup and efficiency at every measured p, oversubscribed ones included.
    pub measured: Vec<fit::StrongPoint>,
    /// The models, fitted to the cases that had a logical CPU per worker only: an
    /// oversubscribed case measures time-sharing, not parallel speedup.
    pub fit: Fitted<StrongFit>,
    /// The serial fraction from the one-worker case's phase timers (the Barnes-Hut report's method),
    /// and how it compares with the fitted one.
    pub timed_serial: Option<TimedSerialFraction>,
    pub(crate) serial_comparison: Option<SerialFractionComparison>,
    /// Other processes' load when the machine was shared while the sweep ran (its
    /// calibrations measured it): every reading of this series then says so, and none puts the
    /// loss of speedup on the code. Absent on a quiet machine.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shared_machine: Option<SharedMachine>,
}

/// A weak-scaling series over p (from p = 1) and Gustafson's model fitted to it.
#[derive(Clone, Debug, Serialize)]
pub struct WeakAnalysis {
    /// What the series' cases have in common.
    pub series: SeriesKey,
    pub(crate) label: String,
    /// How the sweep's config grows the problem with p; `None` when it has no `[weak]` table.
    pub rule: Option<WeakRule>,
    /// The cases, in increasing p, oversubscribed ones included.
    pub points: Vec<Point>,
    /// Efficiency at every measured p, oversubscribed ones included.
    pub measured: Vec<fit::EfficiencyPoint>,
    /// Gustafson's model, fitted to the cases that had a logical CPU per worker only.
    pub fit: Fitted<WeakFit>,
    /// Other processes' load when the machine was shared while the sweep ran, as for
    /// [`StrongAnalysis::shared_machine`]. Absent on a quiet machine.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shared_machine: Option<SharedMachine>,
}

/// A tree code over θ (or an external family over its accuracy settings) at fixed n and p.
#[derive(Clone, Debug, Serialize)]
pub struct ThetaAnalysis {
    /// What the series' cases have in common.
    pub series: SeriesKey,
    pub(crate) label: String,
    /// The cases, in increasing θ (a family's members in increasing force error).
    pub points: Vec<Point>,
}

/// Everything `analyze` derives from one results file (`fits.json`).
#[derive(Clone, Debug, Serialize)]
pub struct Analysis {
    /// The format of `fits.json`: `nbody-bench/fits/v1`.
    pub schema: String,
    /// The path of the results file analysed, as given.
    pub source: String,
    /// The sweep's name from its config.
    pub name: String,
    /// What the sweep studies (strong, weak, complexity or every combination).
    pub study: Study,
    /// The machine, build and commit the results were measured with.
    pub metadata: Metadata,
    /// The machine's calibrated peaks and parallel ceilings (start and end readings merged);
    /// `None` when the sweep ran without a calibration.
    pub calibration: Option<Calibration>,
    /// Every series over n, with its fit.
    pub complexity: Vec<ComplexityAnalysis>,
    pub(crate) crossovers: Vec<Crossover>,
    /// Every strong-scaling series, with its fits.
    pub strong: Vec<StrongAnalysis>,
    /// Every weak-scaling series, with its fit.
    pub weak: Vec<WeakAnalysis>,
    /// Every accuracy series (over θ or an external family's settings).
    pub theta: Vec<ThetaAnalysis>,
    /// The O(n²) family (naive, symmetric, per-thread) side by side at each scenario and n
    /// that has at least two of them.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub family: Vec<family::Family>,
    /// Our kernels next to the external programs of the same sweep.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub peers: Vec<peers::PeerRatio>,
    /// Tree codes at equal median force error ([`peers::EQUAL_ERROR`], and tighter where the
    /// other code reaches it).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub(crate) peers_equal_error: Vec<peers::EqualErrorCost>,
    /// How each external program was run: its `[[external]]` entry as the sweep's config
    /// gives it (command, environment, steps, timing), so that a comparison says what it
    /// compares against.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub external_runs: Vec<nbody_records::external::External>,
    /// The tokens the config's `[mpi]` launcher puts before an external program's command
    /// (`mpirun ARGS -n {ranks}`); empty without one.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub(crate) external_launcher: Vec<String>,
    /// Every complete case, with its summary figures and physics checks.
    pub cases: Vec<Point>,
    /// Cases of the file still unmeasured or partly measured (left out of the analysis).
    pub incomplete: Vec<String>,
    /// Cases measured without one successful sample, each with why (left out of the analysis,
    /// but never out of its summary).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub failed: Vec<FailedCase>,
}

/// A case every sample of which failed.
#[derive(Clone, Debug, Serialize)]
pub struct FailedCase {
    /// The case's key.
    pub key: String,
    /// Why its samples failed: the first reasons the results file records (empty when it
    /// records none).
    pub reasons: Vec<String>,
}

impl Analysis {
    /// The pair rate of `p` as a share of the calibrated FMA peak of its workers (f64 at half
    /// the f32 rate), at the law's nominal flops per pair; `None` without a calibration or a
    /// pair rate.
    pub(crate) fn peak_share(
        &self,
        p: &Point,
        law: nbody_engine::physics::LawKind,
        precision: nbody_engine::scenario::Precision,
    ) -> Option<f64> {
        let c = self.calibration.as_ref()?;
        let pair_evals_per_s = p.pair_evals_per_s?;
        let per_number = match precision {
            nbody_engine::scenario::Precision::F32 => 1.0,
            nbody_engine::scenario::Precision::F64 => 0.5,
        };
        let flops = c.fma_gflops_1t * 1e9 * p.p() as f64 * per_number;
        Some(pair_evals_per_s * law.flops_per_pair() / flops)
    }
}

/// Why a results file could not be analysed.
#[derive(Debug, Error)]
pub enum AnalysisError {
    /// The results file has no complete case yet (a sweep interrupted before any finished).
    #[error(
        "{path} has no complete case to analyse yet: finish its run with `nbody-bench sweep \
         --config <its config> --resume {}`",
        path.parent().unwrap_or(Path::new(".")).display()
    )]
    Empty {
        /// The results file.
        path: PathBuf,
    },
    /// Every case the results file measured failed: resuming would measure nothing more.
    #[error(
        "{path} has no successful sample to analyse: all {failed} measured case(s) failed \
         ({}); each one's errors are kept in the file",
        first_of(reasons)
    )]
    AllFailed {
        /// The results file.
        path: PathBuf,
        /// How many cases failed.
        failed: usize,
        /// Each failed case with its first reason.
        reasons: Vec<String>,
    },
}

/// Fits every series of `results` (read from `source`, for the record).
pub fn analyze(results: &ResultsFile, source: &Path) -> Result<Analysis, AnalysisError> {
    let groups: Groups = groups::group(results);
    let failed = failed_cases(results);
    if groups.cases.is_empty() {
        // A run with nothing left to measure is not asked to be finished.
        if !failed.is_empty() && results.cases.iter().all(|c| c.is_complete()) {
            return Err(AnalysisError::AllFailed {
                path: source.into(),
                failed: failed.len(),
                reasons: failed
                    .iter()
                    .map(|f| match f.reasons.first() {
                        Some(r) => format!("{}: {r}", f.key),
                        None => f.key.clone(),
                    })
                    .collect(),
            });
        }
        return Err(AnalysisError::Empty {
            path: source.into(),
        });
    }
    let calibration = results.calibration.for_analysis();
    // The most load either calibration measured: the sweep ran between them.
    let shared = SharedMachine::of(
        [&results.calibration.start, &results.calibration.end]
            .into_iter()
            .flatten()
            .filter_map(|c| c.background_cpus)
            .reduce(f64::max),
    );
    let complexity: Vec<ComplexityAnalysis> = groups.complexity.iter().map(complexity).collect();
    let crossovers = crossover::crossovers(&complexity);
    let strong = groups
        .strong
        .iter()
        .map(|s| strong(s, calibration.as_ref(), shared))
        .collect();
    let rule = results.config.weak.as_ref().map(|w| w.rule);
    let weak = groups.weak.iter().map(|s| weak(s, rule, shared)).collect();
    let theta = groups
        .theta
        .iter()
        .map(|s| ThetaAnalysis {
            series: s.key.clone(),
            label: s.key.label(),
            points: s.points.clone(),
        })
        .collect::<Vec<_>>();
    let peers_equal_error = peers::equal_error(&theta);
    let family = family::families(&groups.cases, calibration.as_ref());
    Ok(Analysis {
        schema: FITS_SCHEMA.into(),
        source: source.display().to_string(),
        name: results.config.name.clone(),
        study: results.config.study,
        metadata: results.metadata.clone(),
        calibration,
        complexity,
        crossovers,
        strong,
        weak,
        theta,
        family,
        peers: peers::ratios(&groups.cases),
        peers_equal_error,
        external_runs: results.config.external.clone(),
        external_launcher: results
            .config
            .mpi
            .as_ref()
            .filter(|_| !results.config.external.is_empty())
            .map(|m| {
                let mut v = vec![m.launcher.clone()];
                v.extend(m.args.iter().cloned());
                v.extend([m.rank_flag.clone(), "{ranks}".to_string()]);
                v
            })
            .unwrap_or_default(),
        incomplete: results
            .cases
            .iter()
            .filter(|c| !c.is_complete())
            .map(|c| c.key.clone())
            .collect(),
        cases: groups.cases,
        failed,
    })
}

/// The first few of `items`, with how many more.
fn first_of(items: &[String]) -> String {
    const SHOWN: usize = 3;
    let mut text = items[..items.len().min(SHOWN)].join("; ");
    if items.len() > SHOWN {
        text += &format!("; and {} more", items.len() - SHOWN);
    }
    text
}

/// The cases of `results` measured without one successful sample, with why.
fn failed_cases(results: &ResultsFile) -> Vec<FailedCase> {
    results
        .cases
        .iter()
        .filter(|c| c.failed())
        .map(|c| FailedCase {
            key: c.key.clone(),
            reasons: c.failures(),
        })
        .collect()
}

fn samples_by(
    points: &[Point],
    x: impl Fn(&Point) -> f64,
    scale: impl Fn(&Point) -> f64,
) -> Vec<Samples> {
    let mut out: Vec<Samples> = Vec::new();
    for p in points {
        let values = p.samples.iter().map(|v| v * scale(p));
        match out.iter_mut().find(|s| s.x == x(p)) {
            Some(s) => s.values.extend(values),
            None => out.push(Samples::new(x(p), values.collect())),
        }
    }
    out
}

fn complexity(s: &Series) -> ComplexityAnalysis {
    let data = samples_by(&s.points, |p| p.n as f64, |_| 1.0);
    ComplexityAnalysis {
        series: s.key.clone(),
        label: s.key.label(),
        points: s.points.clone(),
        fit: Fitted::of(fit::fit_power(&data, fit::DEFAULT_SEED)),
    }
}

/// Kernels whose force interaction runs on the rayon pool; their build, integration and
/// boundary phases stay serial. (The Verlet list also splits its list builds over the pool,
/// which the timed serial fraction counts as serial: for it, that fraction is an upper bound.)
fn parallel_interaction(kernel: KernelKind) -> bool {
    !matches!(kernel, KernelKind::Symmetric)
}

fn kernel_of(s: &Series) -> Option<KernelKind> {
    s.key.kernel.kernel()
}

/// The serial fraction of a built-in kernel's one-worker case from its phase timers.
fn engine_serial_fraction(
    one: &Point,
    kernel: KernelKind,
    dim: usize,
) -> Option<fit::TimedSerialFraction> {
    let ph = one.phases.as_ref()?;
    // Which phases ran on the pool's threads: the per-particle passes (kick, drift, walls)
    // and the cell and Verlet lists' binning fork from a size on; the interactions of
    // every kernel but `symmetric` do.
    let passes_fork = one.n * dim >= nbody_engine::par::MIN_FORK_ELEMENTS;
    let build_forks = passes_fork && kernel.parallel_build();
    let (mut serial, mut parallel) = (vec![ph.output], vec![]);
    let mut put = |t: f64, forks: bool| {
        if forks {
            parallel.push(t)
        } else {
            serial.push(t)
        }
    };
    put(ph.force_interact, parallel_interaction(kernel));
    put(ph.force_build, build_forks);
    put(ph.integrate, passes_fork);
    put(ph.boundary, passes_fork);
    fit::timed_serial_fraction(&serial, &parallel).ok()
}

/// The serial fraction of an external program's one-worker case from the phases it timed: its
/// `serial` phases against its whole step (the mean step time of the runs the phases are means
/// of), so that time no phase covers counts as the parallel part it most likely is.
fn external_serial_fraction(one: &Point) -> Option<fit::TimedSerialFraction> {
    let serial: Vec<f64> = one
        .named_phases
        .iter()
        .filter(|p| p.kind == PhaseKind::Serial)
        .map(|p| p.s_per_step)
        .collect();
    if serial.is_empty() {
        return None;
    }
    let rest = (one.mean_step_s() - serial.iter().sum::<f64>()).max(0.0);
    fit::timed_serial_fraction(&serial, &[rest]).ok()
}

fn strong(
    s: &Series,
    calibration: Option<&Calibration>,
    shared: Option<SharedMachine>,
) -> StrongAnalysis {
    let real: Vec<Point> = s
        .points
        .iter()
        .filter(|p| !p.oversubscribed)
        .cloned()
        .collect();
    let data = samples_by(&real, |p| p.p() as f64, |_| 1.0);
    let all = samples_by(&s.points, |p| p.p() as f64, |_| 1.0);
    let ceiling: Vec<(f64, f64)> = match calibration {
        Some(c) => s
            .points
            .iter()
            .filter(|p| p.ranks == 1)
            .filter_map(|p| {
                // One thread is the reference of the ceiling by definition.
                let r = if p.threads == 1 {
                    Some(1.0)
                } else {
                    c.ceiling(p.threads)
                };
                r.map(|r| (p.threads as f64, r))
            })
            .collect(),
        None => Vec::new(),
    };
    let mut ceiling = ceiling;
    ceiling.dedup_by(|a, b| a.0 == b.0);
    let fit = Fitted::of(fit::fit_strong_on(
        &data,
        &ceiling,
        fit::DEFAULT_SEED,
        shared,
    ));
    let measured = match fit::fit_strong_on(&all, &ceiling, fit::DEFAULT_SEED, shared) {
        Ok(f) => f.points,
        Err(_) => fit
            .fit
            .as_ref()
            .map(|f| f.points.clone())
            .unwrap_or_default(),
    };
    let one = s.points.iter().find(|p| p.p() == 1);
    let timed_serial = one.and_then(|one| match kernel_of(s) {
        Some(kernel) => engine_serial_fraction(one, kernel, s.key.scenario.dim()),
        // An external program's serial fraction comes from the phases it timed, if any.
        None => external_serial_fraction(one),
    });
    let serial_comparison = match (&timed_serial, &fit.fit) {
        (Some(t), Some(f)) => {
            // Only a program's use of its workers is in doubt: a built-in kernel is known to
            // use them (no speedup there is the cost of running in parallel at this n).
            let best = measured
                .iter()
                .filter(|m| m.p > 1.0 && kernel_of(s).is_none())
                .map(|m| m.speedup.estimate)
                .reduce(f64::max);
            Some(fit::compare_serial_fractions(
                t,
                &f.serial_fraction,
                best,
                shared.as_ref(),
            ))
        }
        _ => None,
    };
    StrongAnalysis {
        series: s.key.clone(),
        label: s.key.label(),
        points: s.points.clone(),
        measured,
        fit,
        timed_serial,
        serial_comparison,
        shared_machine: shared,
    }
}

/// The cost model a kernel's work per worker is held constant under; for an external
/// program, the one of the weak rule its config names (linear or sqrt).
fn cost_class(kernel: &KernelOrProgram, rule: Option<WeakRule>) -> ComplexityClass {
    match (kernel.kernel(), rule) {
        (Some(KernelKind::Naive | KernelKind::Symmetric | KernelKind::PerThread), _) => {
            ComplexityClass::N2
        }
        (
            Some(
                KernelKind::CellList
                | KernelKind::Verlet
                | KernelKind::ClusterPair
                | KernelKind::Fmm
                | KernelKind::FmmHarmonic,
            ),
            _,
        ) => ComplexityClass::N,
        (Some(KernelKind::Octree), _) => ComplexityClass::NLogN,
        (None, Some(WeakRule::Sqrt)) => ComplexityClass::N2,
        (None, _) => ComplexityClass::N,
    }
}

fn weak(s: &Series, rule: Option<WeakRule>, shared: Option<SharedMachine>) -> WeakAnalysis {
    let real: Vec<Point> = s
        .points
        .iter()
        .filter(|p| !p.oversubscribed)
        .cloned()
        .collect();
    let fit = Fitted::of(fit_weak_points(&real, &s.key.kernel, rule));
    let measured = match fit_weak_points(&s.points, &s.key.kernel, rule) {
        Ok(f) => f.efficiency,
        Err(_) => fit
            .fit
            .as_ref()
            .map(|f| f.efficiency.clone())
            .unwrap_or_default(),
    };
    WeakAnalysis {
        series: s.key.clone(),
        label: s.key.label(),
        rule,
        points: s.points.clone(),
        measured,
        fit,
        shared_machine: shared,
    }
}

fn fit_weak_points(
    points: &[Point],
    kernel: &KernelOrProgram,
    rule: Option<WeakRule>,
) -> Result<WeakFit, fit::FitError> {
    if rule == Some(WeakRule::Time) {
        // n is fixed and the simulated time grows with p: the time of the scaled work is the
        // step time times the time factor.
        let data = samples_by(points, |p| p.p() as f64, |p| p.time_factor as f64);
        fit::fit_weak(&data, fit::DEFAULT_SEED)
    } else {
        let mut data: Vec<WeakSamples> = Vec::new();
        for p in points {
            match data.iter_mut().find(|w| w.p == p.p() as f64) {
                Some(w) => w.values.extend(&p.samples),
                None => data.push(WeakSamples {
                    p: p.p() as f64,
                    n: p.n as f64,
                    values: p.samples.clone(),
                }),
            }
        }
        fit::fit_weak_with_n(&data, cost_class(kernel, rule), fit::DEFAULT_SEED)
    }
}
