//! Force validation: every applicable kernel against the naive sum computed in f64.

pub mod periodic;

use crate::kernels::CompiledKernels;
use crate::kernels::{ForceKernel, KernelKind, KernelParams, Naive};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::scenario::{System, SystemJob};
use crate::state::{Field, State, zero_field};
use crate::stats::median;
use serde::Serialize;

/// Exact kernels may differ from naive in the same precision by rounding only: per particle,
/// |ΔF| ≤ EXACT_ULPS · ε · Σ_j |F_ij| (ε of the run's precision). The bound covers the
/// rounding of the sums in a different order; a missing or doubled pair exceeds it. In a
/// periodic box it adds twice the change of the particle's force when its pairs' distances are
/// off by the rounding of a pair through a face ([`periodic::image_rounding`]).
pub const EXACT_ULPS: f64 = 1000.0;

/// Largest median relative error the octree may have at opening angle θ, for a law.
///
/// Monopole Barnes-Hut error grows roughly as θ²; the bound is 4e-3·θ² for gravity
/// (1e-3 at θ = 0.5, the octree's accuracy target) and ten times that for mixed-sign charges, whose net
/// forces are small differences of large opposing sums. At θ = 0 the octree is exact and
/// is held to the exact-kernel bound instead.
pub fn octree_tolerance(law: crate::physics::LawKind, theta: f64) -> f64 {
    let base = 4e-3 * theta * theta;
    match law {
        crate::physics::LawKind::Coulomb => 10.0 * base,
        _ => base,
    }
}

/// Largest median relative error the fmm may have at opening angle θ and order p: `0.25 θ^p`.
///
/// Its error falls as θ^p: the measured median error over θ^p was at most 0.14 (galaxy and
/// coulomb at n = 5000, θ 0.3 to 0.8, p 1 to 8; the largest at p = 1, falling to 4e-3 and
/// 1e-2 at p = 8). At θ = 0 the fmm is exact and is held to the exact-kernel bound instead.
pub fn fmm_tolerance(theta: f64, order: usize) -> f64 {
    0.25 * theta.powi(order as i32)
}

/// Agreement of one kernel with the reference.
#[derive(Clone, Debug, Serialize)]
pub struct KernelCheck {
    /// Kernel name, as `--kernel` takes it.
    pub kernel: &'static str,
    /// Max and median over particles of |F − F_ref| / |F_ref| (|F_ref| floored at 1e-6 of its RMS).
    pub max_rel_error: f64,
    /// Median over particles of the same relative error.
    pub median_rel_error: f64,
    /// Max over particles of |F − F_naive| / Σ_j |F_ij| (naive in the run's precision): the
    /// difference relative to the rounding scale.
    pub(crate) max_rounding_ratio: f64,
    /// Whether the kernel met its bound (rounding for exact kernels, θ's tolerance for the tree
    /// codes).
    pub passed: bool,
    /// Not run because the kernel refuses these parameters (the fmm at θ ≥ 1): neither passed
    /// nor failed, the errors NaN (null in JSON), the reason in `criterion`.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub skipped: bool,
    /// Why it passed or failed, in words.
    pub criterion: String,
}

impl KernelCheck {
    fn skipped(kind: KernelKind, why: &str) -> Self {
        KernelCheck {
            kernel: kind.name(),
            max_rel_error: f64::NAN,
            median_rel_error: f64::NAN,
            max_rounding_ratio: f64::NAN,
            passed: false,
            skipped: true,
            criterion: format!("skipped ({why})"),
        }
    }
}

/// What `validate` found for one scenario.
#[derive(Clone, Debug, Serialize)]
pub struct ScenarioCheck {
    /// Scenario name.
    pub scenario: &'static str,
    /// Particles in the system.
    pub n: usize,
    /// Precision of the kernels checked, `f32` or `f64` (the reference is always f64).
    pub precision: &'static str,
    /// Opening angle θ the tree kernels were checked at.
    pub theta: f64,
    /// One check per kernel that applies to the law, in [`KernelKind::ALL`] order.
    pub kernels: Vec<KernelCheck>,
    /// The force dump text, when asked for.
    #[serde(skip)]
    pub dump: Option<String>,
}

/// `job` on the system of `setup` (not generic: see [`crate::run::run_setup`]).
pub fn validate_setup(
    setup: &crate::scenario::Setup,
    job: ValidateJob,
) -> Result<Result<ScenarioCheck, crate::run::RunError>, crate::scenario::SetupError> {
    setup.dispatch(job)
}

/// Runs every kernel that applies to the system's law and compares it to the reference.
pub struct ValidateJob {
    /// Kernel parameters every kernel is built with (θ, leaf size, skin, order).
    pub params: KernelParams,
    /// Threads of the pool the kernels run on.
    pub threads: usize,
    /// Whether to keep the forces as dump text in [`ScenarioCheck::dump`].
    pub want_dump: bool,
}

impl SystemJob for ValidateJob {
    type Output = Result<ScenarioCheck, crate::run::RunError>;

    fn run<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        mut system: System<T, L, D>,
    ) -> Self::Output {
        if let crate::boundary::Boundary::Periodic { lo, hi } = system.boundary {
            shaken(
                &mut system.state,
                lo,
                hi,
                system.law.cutoff(),
                system.info.seed,
            );
        }
        let state = &system.state;
        let n = state.len();
        let (reference, abs_sum) = match system.boundary {
            crate::boundary::Boundary::Periodic { lo, hi } => {
                let side = std::array::from_fn(|d| (hi[d] - lo[d]).as_f64());
                let wide = state.convert::<f64>();
                let law = system.law.widen();
                let (f, _, mut abs_sum) = periodic::periodic_reference_forces(&law, &wide, side)
                    // Setup::validate checks the side in f64; in f32 a side within rounding of
                    // twice the cutoff can still fail, and says so.
                    .map_err(|e| {
                        crate::kernels::KernelError::BadParam(format!(
                            "{e} (at {} precision)",
                            T::NAME
                        ))
                    })?;
                // Pairs through the faces are rounded at the box's scale, differently by naive
                // and by the kernels: the bound allows twice that, in units of the bound.
                let delta = periodic::image_rounding_delta(
                    T::EPSILON_F64,
                    lo.map(|x| x.as_f64()),
                    hi.map(|x| x.as_f64()),
                );
                let image = periodic::image_rounding(&law, &wide, side, delta);
                for (a, e) in abs_sum.iter_mut().zip(image) {
                    *a += 2.0 * e / (EXACT_ULPS * T::EPSILON_F64);
                }
                (f, abs_sum)
            }
            _ => reference_forces(&system.law.widen(), &state.convert::<f64>()),
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.threads)
            .build()
            .map_err(|source| crate::run::RunError::Pool {
                threads: self.threads,
                source,
            })?;
        let mut checks = Vec::new();
        let mut dumped = Vec::new();
        // Exact kernels are held to naive in their own precision: both compute every pair's
        // separation and cutoff decision identically and differ only in summation order. An f32
        // run can also differ from the f64 reference where a pair sits within rounding of the
        // cutoff (the truncated force jumps there), which says nothing about the kernel.
        let mut naive = zero_field::<T, D>(n);
        let mut naive_kernel = system.kernel(KernelKind::Naive, &self.params)?;
        pool.install(|| naive_kernel.compute(state, &mut naive, false));
        for kind in KernelKind::ALL
            .into_iter()
            .filter(|k| k.supports(system.law.kind()))
        {
            // The fmm's expansions diverge at θ ≥ 1, where the octree still runs: the other
            // kernels are still worth checking at that θ.
            if kind.is_fmm() && !self.params.fmm_converges() {
                checks.push(KernelCheck::skipped(kind, "the fmm needs theta below 1"));
                continue;
            }
            if kind == KernelKind::Fmm && self.params.order > crate::kernels::MAX_FMM_ORDER {
                checks.push(KernelCheck::skipped(
                    kind,
                    "the fmm's Cartesian expansions stop at order 8 (fmm-harmonic goes on)",
                ));
                continue;
            }
            let mut kernel: Box<dyn ForceKernel<T, D>> = match system.kernel(kind, &self.params) {
                // Like a kernel of another law, one with no periodic form does not apply to
                // a periodic system (`list` shows which do).
                Err(crate::kernels::KernelError::NotPeriodic { .. }) => continue,
                // A list whose bins do not fit this small a box: said, not failed.
                Err(crate::kernels::KernelError::PeriodicBoxTooSmall(_)) => {
                    checks.push(KernelCheck::skipped(
                        kind,
                        "the periodic box is too small for it",
                    ));
                    continue;
                }
                built => built?,
            };
            let mut forces = zero_field::<T, D>(n);
            pool.install(|| kernel.compute(state, &mut forces, false));
            checks.push(check(
                kind,
                system.law.kind(),
                &self.params,
                &forces,
                &naive,
                &reference,
                &abs_sum,
                matches!(system.boundary, crate::boundary::Boundary::Periodic { .. }),
            ));
            if self.want_dump {
                dumped.push((kind.name(), forces));
            }
        }
        let dump = self.want_dump.then(|| {
            let header = format!(
                "scenario {} dim {D} precision {} n {n} seed {} theta {}",
                system.info.scenario.name(),
                T::NAME,
                system.info.seed,
                self.params.theta
            );
            let law = system.law.parameters();
            crate::output::dump::force_dump(&header, &law, state, &reference, &dumped)
        });
        Ok(ScenarioCheck {
            scenario: system.info.scenario.name(),
            n,
            precision: T::NAME,
            theta: self.params.theta,
            kernels: checks,
            dump,
        })
    }
}

/// Moves every particle of a periodic system by up to a twenty-fifth of the cutoff on each
/// axis (a tenth of σ for Lennard-Jones), seeded, wrapped back into the box: on a perfect
/// lattice every force cancels by symmetry, and a check of forces that are all zero checks
/// nothing.
fn shaken<T: Real, const D: usize>(
    state: &mut State<T, D>,
    lo: [T; D],
    hi: [T; D],
    cutoff: Option<T>,
    seed: u64,
) {
    use rand::{Rng, SeedableRng};
    let Some(rc) = cutoff else { return };
    let amplitude = rc.as_f64() / 25.0;
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    for i in 0..state.len() {
        for d in 0..D {
            let (low, side) = (lo[d].as_f64(), (hi[d] - lo[d]).as_f64());
            let x = state.pos[d][i].as_f64() + amplitude * (2.0 * rng.random::<f64>() - 1.0);
            let x = T::of(low + (x - low).rem_euclid(side));
            // Rounding may land on the upper face, the image of the lower.
            state.pos[d][i] = if x >= hi[d] { lo[d] } else { x };
        }
    }
}

/// The naive pair sum in f64, and per particle the sum of the magnitudes of its pair forces
/// (the scale of the rounding error any summation order can make).
pub fn reference_forces<L: PairLaw<f64>, const D: usize>(
    law: &L,
    state: &State<f64, D>,
) -> (Field<f64, D>, Vec<f64>) {
    let n = state.len();
    let mut forces = zero_field::<f64, D>(n);
    Naive::new(*law).compute(state, &mut forces, false);
    let abs_sum = (0..n)
        .map(|i| {
            let xi = state.position(i);
            (0..n)
                .filter(|&j| j != i)
                .map(|j| {
                    let dx: [f64; D] = std::array::from_fn(|d| state.pos[d][j] - xi[d]);
                    let f = crate::physics::pair_force(law, dx, state.source[i], state.source[j]);
                    f.iter().map(|c| c * c).sum::<f64>().sqrt()
                })
                .sum()
        })
        .collect();
    (forces, abs_sum)
}

fn norm<const D: usize>(v: [f64; D]) -> f64 {
    v.iter().map(|c| c * c).sum::<f64>().sqrt()
}

fn check<T: Real, const D: usize>(
    kind: KernelKind,
    law: crate::physics::LawKind,
    params: &KernelParams,
    forces: &Field<T, D>,
    naive: &Field<T, D>,
    reference: &Field<f64, D>,
    abs_sum: &[f64],
    periodic: bool,
) -> KernelCheck {
    let theta = params.theta;
    let n = abs_sum.len();
    let ref_norm: Vec<f64> = (0..n)
        .map(|i| norm::<D>(std::array::from_fn(|d| reference[d][i])))
        .collect();
    let rms = (ref_norm.iter().map(|x| x * x).sum::<f64>() / n.max(1) as f64).sqrt();
    let floor = (1e-6 * rms).max(f64::MIN_POSITIVE);
    let mut rel = Vec::with_capacity(n);
    let mut max_ratio = 0.0f64;
    for i in 0..n {
        let err = norm::<D>(std::array::from_fn(|d| {
            forces[d][i].as_f64() - reference[d][i]
        }));
        rel.push(err / ref_norm[i].max(floor));
        let err_naive = norm::<D>(std::array::from_fn(|d| {
            forces[d][i].as_f64() - naive[d][i].as_f64()
        }));
        let ratio = if abs_sum[i] > 0.0 {
            err_naive / abs_sum[i]
        } else if err_naive > 0.0 {
            f64::INFINITY
        } else {
            0.0
        };
        max_ratio = max_ratio.max(ratio);
    }
    let max_rel = rel.iter().copied().fold(0.0, f64::max);
    let median_rel = median(&rel).unwrap_or(0.0);
    let exact_bound = EXACT_ULPS * T::EPSILON_F64;
    let (passed, criterion) = if kind.is_exact() || theta == 0.0 {
        (
            max_ratio <= exact_bound,
            format!(
                "exact: |F - F_naive| <= {exact_bound:.1e} x sum|F_ij|{} per particle (worst \
                 {max_ratio:.2e})",
                if periodic {
                    " + 2 x image rounding"
                } else {
                    ""
                }
            ),
        )
    } else {
        let (tol, setting) = match kind {
            k if k.is_fmm() => (
                fmm_tolerance(theta, params.order),
                format!("theta = {theta}, order {}", params.order),
            ),
            _ => (octree_tolerance(law, theta), format!("theta = {theta}")),
        };
        (
            median_rel <= tol,
            format!("approximate: median relative error <= {tol:.1e} at {setting}"),
        )
    };
    KernelCheck {
        kernel: kind.name(),
        max_rel_error: max_rel,
        median_rel_error: median_rel,
        max_rounding_ratio: max_ratio,
        passed,
        skipped: false,
        criterion,
    }
}

/// Relative force error against the f64 direct sum on `m` particles drawn with `seed`
/// (all particles when m ≥ n): (median, max) of |F − F_ref| / |F_ref|. O(m·n), for checking
/// large runs where the full reference would be too slow.
pub fn sampled_force_error<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    state: &State<T, D>,
    forces: &Field<T, D>,
    m: usize,
    seed: u64,
) -> (f64, f64) {
    use crate::kernels::rows::{Exclude, Sources, Target, gather_excluding};
    use rand::{Rng, SeedableRng};
    let n = state.len();
    let wide = state.convert::<f64>();
    let law = law.widen();
    let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
    let picks: Vec<usize> = if m >= n {
        (0..n).collect()
    } else {
        (0..m).map(|_| rng.random_range(0..n)).collect()
    };
    let all = Sources::range(&wide.pos, &wide.source, 0, n);
    let rel: Vec<f64> = picks
        .iter()
        .filter_map(|&i| {
            let t = Target {
                x: wide.position(i),
                s: wide.source[i],
            };
            let f = gather_excluding::<f64, _, D, false>(&law, &t, &all, Exclude::index(i)).force;
            let size = norm::<D>(f);
            let err = norm::<D>(std::array::from_fn(|d| forces[d][i].as_f64() - f[d]));
            (size > 0.0).then_some(err / size)
        })
        .collect();
    (
        median(&rel).unwrap_or(0.0),
        rel.iter().copied().fold(0.0, f64::max),
    )
}
