//! Force kernels: interchangeable ways of visiting the pairs of one configuration.
//!
//! A kernel owns its scratch memory (buffers, cells, trees), allocated on first use and reused
//! on every later step, and computes the forces of a [`PairLaw`] on every particle. The
//! physics lives in the law; kernels contain traversal only. The kernel is chosen once per run
//! through [`KernelKind::build`] (one dynamic call per step); the pair loops inside are
//! monomorphized for the law, precision and dimension.

mod broadcast;
mod cell_list;
mod cluster_pair;
mod compiled;
mod counting_sort;
pub mod decorator;
mod fmm;
pub mod footprint;
mod images;
#[cfg(target_arch = "x86_64")]
mod lanes;
mod naive;
mod octree;
mod per_thread;
#[cfg(feature = "test-slowdown")]
pub mod repeated;
pub mod rows;
mod share;
mod symmetric;
pub mod teamed;
mod triangle;
pub mod verlet;

pub use cell_list::CellList;
pub use cluster_pair::ClusterPair;
pub use compiled::CompiledKernels;
pub use fmm::harmonic::MAX_HARMONIC_ORDER as MAX_FMM_HARMONIC_ORDER;
pub use fmm::{Fmm, MAX_ORDER as MAX_FMM_ORDER};
pub use naive::Naive;
pub(crate) use octree::far_from_box;
pub use octree::{Multipole, Octree, TreeView};
pub use per_thread::PerThread;
pub use share::Share;
pub use symmetric::Symmetric;
pub use teamed::{StateView, TeamPlan};
pub use verlet::Verlet;

use crate::physics::{LawKind, PairLaw};
use crate::real::Real;
use crate::state::{Field, State, zero_field};
use serde::Serialize;
use std::ops::Range;
use thiserror::Error;

/// The eight kernels. `ALL` drives `list`, `validate`, the tests and the sweeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum KernelKind {
    /// Every particle against every other (n(n−1) pair evaluations).
    Naive,
    /// Each pair once with Newton's third law (n(n−1)/2), single thread.
    Symmetric,
    /// Symmetric pairs split over rayon threads, each with its own force buffer, then reduced.
    PerThread,
    /// Bins of side ≥ rc, particles sorted by bin, neighbours from adjacent bins (O(n)).
    CellList,
    /// Barnes-Hut tree (octree in 3-D, quadtree in 2-D) with opening angle θ (O(n log n)).
    Octree,
    /// Half neighbour list within the cutoff plus a skin, rebuilt from cell-list bins only when
    /// some particle has moved more than half the skin (O(n)).
    Verlet,
    /// Verlet list of 4-particle clusters (GROMACS nbnxm style), each against runs of 16
    /// particles (8 in 3-D) in one SIMD block, for dense systems (O(n)).
    ClusterPair,
    /// Fast multipole method (falcON style): mutual cell–cell interactions of Cartesian
    /// order p between cells that pass the opening test with θ, near leaves directly (O(n)).
    Fmm,
    /// The fmm on complex solid harmonics of order p up to 20, each translation O(p³) by
    /// rotation to the z-axis: for high accuracy on the unsoftened 1/r law (Coulomb) (O(n)).
    FmmHarmonic,
}

impl KernelKind {
    /// Every kernel, in the order `list`, `validate` and the sweeps go through them.
    pub const ALL: [KernelKind; 9] = [
        KernelKind::Naive,
        KernelKind::Symmetric,
        KernelKind::PerThread,
        KernelKind::CellList,
        KernelKind::Octree,
        KernelKind::Verlet,
        KernelKind::ClusterPair,
        KernelKind::Fmm,
        KernelKind::FmmHarmonic,
    ];

    /// The kernel's name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            KernelKind::Naive => "naive",
            KernelKind::Symmetric => "symmetric",
            KernelKind::PerThread => "per-thread",
            KernelKind::CellList => "cell-list",
            KernelKind::Octree => "octree",
            KernelKind::Verlet => "verlet",
            KernelKind::ClusterPair => "cluster-pair",
            KernelKind::Fmm => "fmm",
            KernelKind::FmmHarmonic => "fmm-harmonic",
        }
    }

    /// Whether the kernel is a fast multipole method (θ below 1, an expansion order p).
    pub fn is_fmm(self) -> bool {
        matches!(self, KernelKind::Fmm | KernelKind::FmmHarmonic)
    }

    /// Whether the kernel computes the exact pair sum (to rounding) rather than an approximation.
    pub fn is_exact(self) -> bool {
        !matches!(
            self,
            KernelKind::Octree | KernelKind::Fmm | KernelKind::FmmHarmonic
        )
    }

    /// Whether the kernel can compute forces for a law of this family.
    pub fn supports(self, law: LawKind) -> bool {
        match self {
            KernelKind::Naive | KernelKind::Symmetric | KernelKind::PerThread => true,
            KernelKind::CellList | KernelKind::Verlet | KernelKind::ClusterPair => law.has_cutoff(),
            KernelKind::Octree | KernelKind::Fmm => law.is_inverse_square(),
            // Its harmonics expand 1/r: no softening, so not the softened gravity.
            KernelKind::FmmHarmonic => law == LawKind::Coulomb,
        }
    }

    /// How the kernel's work per step grows with n (the README's pair-work column), so that a
    /// time measured at one n can be carried to another (the sweep's estimate, `sweep --dry-run`).
    pub fn complexity(self) -> Complexity {
        match self {
            KernelKind::Naive | KernelKind::Symmetric | KernelKind::PerThread => {
                Complexity::Quadratic
            }
            KernelKind::CellList
            | KernelKind::Verlet
            | KernelKind::ClusterPair
            | KernelKind::Fmm
            | KernelKind::FmmHarmonic => Complexity::Linear,
            KernelKind::Octree => Complexity::NLogN,
        }
    }

    /// Whether the force computation is split over the threads of the rayon pool it runs in
    /// (above [`MIN_PARALLEL_PAIRS`]); the symmetric kernel runs on one thread whatever the pool.
    pub fn uses_threads(self) -> bool {
        !matches!(self, KernelKind::Symmetric)
    }

    /// Whether a step of `work` naive pair evaluations per process (the unit of
    /// [`worth_parallel`]) is split over a pool of several threads: the kernel uses threads
    /// and the step is worth a fork. The one statement of that rule outside the kernels, for
    /// the sweep's estimate and for the tables and figures that say a case ran on one thread.
    pub fn forks_at(self, work: f64) -> bool {
        self.uses_threads() && work >= MIN_PARALLEL_PAIRS as f64
    }

    /// Whether the pair checks a step counts are exactly the work the kernel weighs before it
    /// forks, so that [`KernelKind::forks_at`] on them tells what a measured step did: naive
    /// and per-thread count the pairs they evaluate, the octree the last step's pair checks,
    /// and symmetric never forks. The list and cell kernels add a cost per particle row and
    /// the fmm its cell-cell terms, which the work counters do not give: for them the pair
    /// checks only approximate the rule.
    pub fn forks_on_pair_checks(self) -> bool {
        matches!(
            self,
            KernelKind::Naive | KernelKind::Symmetric | KernelKind::PerThread | KernelKind::Octree
        )
    }

    /// Whether the kernel sums pairs through periodic boundaries
    /// ([`ForceKernel::set_periodic`] succeeds).
    pub fn periodic_form(self) -> bool {
        matches!(
            self,
            KernelKind::Naive | KernelKind::CellList | KernelKind::Verlet | KernelKind::ClusterPair
        )
    }

    /// Whether the build phase (binning and sorting) runs on the pool's threads when the
    /// particles are many (from `par::MIN_FORK_ELEMENTS` on).
    pub fn parallel_build(self) -> bool {
        matches!(
            self,
            KernelKind::CellList | KernelKind::Verlet | KernelKind::ClusterPair
        )
    }

    /// Builds the kernel for `law`, or explains which combinations exist. The kernel is one
    /// this crate compiled ([`CompiledKernels`]): a caller in another crate instantiates none.
    pub fn build<T: Real, L: CompiledKernels<T, D>, const D: usize>(
        self,
        law: L,
        params: &KernelParams,
    ) -> Result<Box<dyn ForceKernel<T, D>>, KernelError> {
        law.build_kernel(self, params)
    }

    /// [`KernelKind::build`] for any law and dimension, instantiated where it is called.
    pub(crate) fn instantiate<T: Real, L: PairLaw<T>, const D: usize>(
        self,
        law: L,
        params: &KernelParams,
    ) -> Result<Box<dyn ForceKernel<T, D>>, KernelError> {
        if !self.supports(law.kind()) {
            return Err(KernelError::Incompatible {
                kernel: self.name(),
                law: law.kind().name(),
                supported: supported_for(law.kind()),
            });
        }
        params.validate()?;
        Ok(match self {
            KernelKind::Naive => Box::new(Naive::new(law)),
            KernelKind::Symmetric => Box::new(Symmetric::new(law)),
            KernelKind::PerThread => Box::new(PerThread::new(law)),
            KernelKind::CellList => Box::new(CellList::new(law)?),
            KernelKind::Octree => Box::new(Octree::with_multipole(
                law,
                params.theta,
                params.leaf_size,
                params.multipole,
            )),
            KernelKind::Verlet => Box::new(Verlet::new(law, params.skin)?),
            KernelKind::ClusterPair => Box::new(ClusterPair::new(law, params.skin)?),
            KernelKind::Fmm => {
                params.validate_fmm::<D>(self)?;
                Box::new(Fmm::new(
                    law,
                    params.theta,
                    params.order,
                    params.fmm_leaf_size,
                ))
            }
            KernelKind::FmmHarmonic => {
                params.validate_fmm::<D>(self)?;
                let kernel = Fmm::harmonic(law, params.theta, params.order, params.fmm_leaf_size);
                Box::new(kernel.ok_or_else(|| {
                    KernelError::BadParam(
                        "fmm-harmonic expands the unsoftened 1/r potential, and this law is \
                         softened or not 1/r: use the fmm kernel"
                            .into(),
                    )
                })?)
            }
        })
    }
}

/// A kernel's complexity class in n: how its work per step grows with the particle count.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Complexity {
    /// O(n): the cell list at fixed density.
    Linear,
    /// O(n log n): the Barnes-Hut tree.
    NLogN,
    /// O(n²): every pair.
    Quadratic,
}

impl Complexity {
    /// Work at `to` particles over work at `from` (counts below 2 count as 2, so that
    /// n log n never divides by zero).
    pub fn ratio(self, from: usize, to: usize) -> f64 {
        let (a, b) = (from.max(2) as f64, to.max(2) as f64);
        match self {
            Complexity::Linear => b / a,
            Complexity::NLogN => (b * b.ln()) / (a * a.ln()),
            Complexity::Quadratic => (b / a) * (b / a),
        }
    }
}

/// The kernels that support a law, as a readable list.
pub fn supported_for(law: LawKind) -> String {
    KernelKind::ALL
        .iter()
        .filter(|k| k.supports(law))
        .map(|k| k.name())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Tuning parameters shared by the kernels that use them.
#[derive(Clone, Copy, Debug, Serialize, serde::Deserialize, PartialEq)]
pub struct KernelParams {
    /// Barnes-Hut opening angle: a node of side `s` at distance `d` is used whole when `s/d < θ`.
    pub theta: f64,
    /// Most particles in a tree leaf.
    pub leaf_size: usize,
    /// Verlet list skin, in the scenario's length unit: pairs within the cutoff plus the skin
    /// enter the list, which stays exact until some particle has moved half the skin.
    #[serde(default = "default_skin")]
    pub skin: f64,
    /// Barnes-Hut expansion order of accepted nodes.
    #[serde(default)]
    pub multipole: Multipole,
    /// Expansion order p of the fast multipole kernel (1 to `fmm::MAX_ORDER`).
    #[serde(default = "default_order")]
    pub order: usize,
    /// Most particles in a leaf of the fast multipole kernel's tree.
    #[serde(default = "default_fmm_leaf_size")]
    pub fmm_leaf_size: usize,
}

fn default_order() -> usize {
    fmm::DEFAULT_ORDER
}

fn default_fmm_leaf_size() -> usize {
    fmm::DEFAULT_LEAF_SIZE
}

/// The Verlet skin by default: 0.3σ of the LJ scenarios.
fn default_skin() -> f64 {
    0.3 * crate::physics::LJ_SIGMA
}

impl Default for KernelParams {
    fn default() -> Self {
        KernelParams {
            theta: 0.5,
            leaf_size: 8,
            skin: default_skin(),
            // Cheaper than monopoles at equal error (REPORT.md, accuracy section).
            multipole: Multipole::Quadrupole,
            order: default_order(),
            fmm_leaf_size: default_fmm_leaf_size(),
        }
    }
}

impl KernelParams {
    /// Checks every parameter is in its range (θ ≥ 0, leaf sizes 1 to 4096, order 1 to
    /// `fmm::MAX_ORDER`, skin > 0).
    pub fn validate(&self) -> Result<(), KernelError> {
        if !(self.theta.is_finite() && self.theta >= 0.0) {
            return Err(KernelError::BadParam(format!(
                "theta must be a finite number >= 0 (got {}); 0.5 is the usual choice",
                self.theta
            )));
        }
        if self.leaf_size == 0 || self.leaf_size > 4096 {
            return Err(KernelError::BadParam(format!(
                "--leaf-size must be between 1 and 4096 for the octree kernel (got {}); {} is \
                 its default",
                self.leaf_size,
                KernelParams::default().leaf_size
            )));
        }
        if !(1..=fmm::harmonic::MAX_HARMONIC_ORDER).contains(&self.order) {
            return Err(KernelError::BadParam(format!(
                "order must be between 1 and {} (the fmm kernel's up to {}; got {}); {} is the \
                 default",
                fmm::harmonic::MAX_HARMONIC_ORDER,
                fmm::MAX_ORDER,
                self.order,
                default_order()
            )));
        }
        if self.fmm_leaf_size == 0 || self.fmm_leaf_size > 4096 {
            return Err(KernelError::BadParam(format!(
                "--leaf-size must be between 1 and 4096 for the fmm kernel (got {}); {} is its \
                 default",
                self.fmm_leaf_size,
                default_fmm_leaf_size()
            )));
        }
        if !(self.skin.is_finite() && self.skin > 0.0) {
            return Err(KernelError::BadParam(format!(
                "skin must be a finite number > 0 (got {}); {} (0.3σ) is the default",
                self.skin,
                default_skin()
            )));
        }
        Ok(())
    }
}

impl KernelParams {
    /// Whether θ is below 1, where the fmm's expansions converge (the fmm refuses the rest).
    pub(crate) fn fmm_converges(&self) -> bool {
        self.theta < 1.0
    }

    /// What the fast multipole kernel needs beyond [`KernelParams::validate`]: θ below 1 (the
    /// expansions converge only there) and three dimensions (its expansions are 3-D).
    fn validate_fmm<const D: usize>(&self, kind: KernelKind) -> Result<(), KernelError> {
        if !self.fmm_converges() {
            return Err(KernelError::BadParam(format!(
                "theta must be below 1 for the fmm kernel (got {}): two cells interact through \
                 their expansions when their radii add up to less than theta times their \
                 distance, and the expansions converge only where that sum is below the \
                 distance; 0.5 is the usual choice",
                self.theta
            )));
        }
        if D != 3 {
            return Err(KernelError::Dimension {
                kernel: kind.name(),
                dim: D,
            });
        }
        if kind == KernelKind::Fmm && self.order > fmm::MAX_ORDER {
            return Err(KernelError::BadParam(format!(
                "order must be between 1 and {} for the fmm kernel's Cartesian expansions (got \
                 {}); fmm-harmonic runs orders up to {}",
                fmm::MAX_ORDER,
                self.order,
                fmm::harmonic::MAX_HARMONIC_ORDER
            )));
        }
        Ok(())
    }
}

/// Why a kernel cannot be built for a system.
#[derive(Debug, Error)]
pub enum KernelError {
    /// The kernel cannot compute forces of the system's law (no cutoff for a cell list, not
    /// inverse-square for a tree).
    #[error("kernel `{kernel}` does not apply to the {law} law; kernels for {law}: {supported}")]
    Incompatible {
        /// The kernel's name.
        kernel: &'static str,
        /// The law's name.
        law: &'static str,
        /// The kernels that do apply to the law, comma-separated.
        supported: String,
    },
    /// A kernel parameter is out of range; holds the message, which names the range and the
    /// default.
    #[error("{0}")]
    BadParam(String),
    /// The kernel has no periodic form (yet): the system's box is periodic.
    #[error(
        "kernel `{kernel}` does not sum pairs through periodic boundaries; kernels that do: naive, cell-list, verlet, cluster-pair"
    )]
    NotPeriodic {
        /// The kernel's name.
        kernel: &'static str,
    },
    /// The periodic box is too small for the kernel's search (a list needs three bins of the
    /// cutoff plus the skin along each side); holds the message, which says what to change.
    #[error("{0}")]
    PeriodicBoxTooSmall(String),
    /// The fmm kernel was asked for a system that is not 3-D.
    #[error(
        "kernel `{kernel}` runs in three dimensions only and this system has {dim}; the long-range \
         scenarios (coulomb, galaxy) are 3-D, and the octree handles 2-D systems"
    )]
    Dimension {
        /// The kernel's name.
        kernel: &'static str,
        /// The system's dimension.
        dim: usize,
    },
}

/// Steps between the spatial re-orderings a kernel may ask for (cell or Morton order), unless
/// the kernel asks more often ([`ForceKernel::sort_every`]: the Verlet list, at its rebuilds).
pub(crate) const SORT_EVERY: u64 = 20;

/// Deterministic work done by one force computation.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct WorkCounters {
    /// Pair distance evaluations (candidate pairs examined).
    pub pair_checks: u64,
    /// Pairs that interact (inside the cutoff / outside the quench); counted on probe steps only.
    pub pairs_interacting: u64,
    /// Cells whose particles were visited (cell list).
    pub cells_visited: u64,
    /// Tree nodes opened (split into children) during the walk.
    pub nodes_opened: u64,
    /// Tree nodes accepted as a monopole.
    pub nodes_accepted: u64,
    /// Neighbour lists built (Verlet list).
    #[serde(default)]
    pub rebuilds: u64,
    /// Neighbour-list entries evaluated (Verlet list; also counted in `pair_checks`).
    #[serde(default)]
    pub list_entries: u64,
}

impl WorkCounters {
    /// Every counter, in declaration order: the one list `+=` and `-` walk.
    fn fields_mut(&mut self) -> [&mut u64; 7] {
        [
            &mut self.pair_checks,
            &mut self.pairs_interacting,
            &mut self.cells_visited,
            &mut self.nodes_opened,
            &mut self.nodes_accepted,
            &mut self.rebuilds,
            &mut self.list_entries,
        ]
    }
}

impl std::ops::AddAssign for WorkCounters {
    fn add_assign(&mut self, mut other: WorkCounters) {
        for (a, b) in self.fields_mut().into_iter().zip(other.fields_mut()) {
            *a += *b;
        }
    }
}

impl std::ops::Add for WorkCounters {
    type Output = WorkCounters;

    fn add(mut self, other: WorkCounters) -> WorkCounters {
        self += other;
        self
    }
}

/// The work done between two snapshots of the same running sum: `later - earlier`. Counters
/// only grow, so a field that went down (a snapshot of another sum) saturates at zero.
impl std::ops::Sub for WorkCounters {
    type Output = WorkCounters;

    fn sub(mut self, mut earlier: WorkCounters) -> WorkCounters {
        for (a, b) in self.fields_mut().into_iter().zip(earlier.fields_mut()) {
            *a = a.saturating_sub(*b);
        }
        self
    }
}

/// What a force computation reports besides the forces.
#[derive(Clone, Copy, Debug, Default)]
pub struct ForceReport {
    /// Potential energy (probe computations only).
    pub energy: Option<f64>,
    /// Seconds spent building cells, trees or sort orders, part of the force phase.
    pub build_s: f64,
    /// Work counted during the computation.
    pub work: WorkCounters,
}

/// Computes the forces of one configuration.
pub trait ForceKernel<T: Real, const D: usize>: Send {
    /// Which of the eight kernels this is.
    fn kind(&self) -> KernelKind;

    /// Overwrites `forces` with the force on every particle. With `probe`, also returns the
    /// potential energy and counts interacting pairs (slower; used outside the timed steps).
    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport;

    /// A particle order that makes this kernel's memory access local (cell or space-filling
    /// curve order), as `order[new_slot] = old_slot`, if the kernel benefits from one.
    fn spatial_order(&mut self, _state: &State<T, D>) -> Option<Vec<u32>> {
        None
    }

    /// Steps between the calls of [`ForceKernel::spatial_order`] by drivers that re-order
    /// periodically. A kernel that re-sorts only when it rebuilds its own structure asks every
    /// step and answers `None` in between.
    fn sort_every(&self) -> u64 {
        SORT_EVERY
    }

    /// Makes every pair meet through its nearest image in the periodic box `[lo, hi)` (each
    /// side more than twice the law's cutoff), or says the kernel cannot. A kernel sums pairs
    /// in open space (or between walls) until this is called.
    fn set_periodic(&mut self, _lo: [T; D], _hi: [T; D]) -> Result<(), KernelError> {
        Err(KernelError::NotPeriodic {
            kernel: self.kind().name(),
        })
    }

    /// The kernel's step as the phases of a team region ([`teamed`]), when its structure
    /// (a list) exists for `n` particles; `None` when it does not or the kernel has no such
    /// plan, and the engine calls [`ForceKernel::compute`] instead.
    fn team_plan(&mut self, _n: usize) -> Option<Box<dyn TeamPlan<T, D> + '_>> {
        None
    }

    /// The forces on the particles in slots `targets` only, from every particle of `state`:
    /// `out[d][k]` receives component `d` of the force on slot `targets.start + k` (the timed
    /// path: no energy). Drivers that split the targets between processes use it.
    ///
    /// The default computes every force and copies the range (correct, but no cheaper);
    /// kernels that can visit only the targets' pairs override it.
    fn compute_targets(
        &mut self,
        state: &State<T, D>,
        targets: Range<usize>,
        out: [&mut [T]; D],
    ) -> ForceReport {
        let mut all = zero_field(state.len());
        let report = self.compute(state, &mut all, false);
        for (d, o) in out.into_iter().enumerate() {
            o.copy_from_slice(&all[d][targets.clone()]);
        }
        report
    }

    /// Overwrites `forces` (length n) with `share`'s part of the forces: summed over all the
    /// shares, `forces` is what [`ForceKernel::compute`] gives.
    ///
    /// The default gives the targets of `share.block(n)` their whole force and every other
    /// particle zero. The symmetric kernels override it to split the pair work instead: each
    /// share evaluates a balanced part of the pairs, once each, and adds the force to both ends.
    fn compute_share(
        &mut self,
        state: &State<T, D>,
        share: Share,
        forces: &mut Field<T, D>,
    ) -> ForceReport {
        let block = share.block(state.len());
        for f in forces.iter_mut() {
            f.fill(T::zero());
        }
        let out = forces.each_mut().map(|f| &mut f[block.clone()]);
        self.compute_targets(state, block, out)
    }
}

/// Smallest number of pair evaluations per step for which forking threads pays off
/// (one rayon fork/join costs ~20 µs on the reference machine; a pair costs ~0.4 ns).
pub const MIN_PARALLEL_PAIRS: u64 = 400_000;

/// Whether a step of `pairs` evaluations should run on the current rayon pool's threads.
pub fn worth_parallel(pairs: u64) -> bool {
    rayon::current_num_threads() > 1 && pairs >= MIN_PARALLEL_PAIRS
}
