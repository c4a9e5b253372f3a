//! `fmm`: a fast multipole method in Dehnen's falcON style, O(n), for the 1/r² laws (gravity
//! with Plummer softening, Coulomb) in 3-D.
//!
//! Each step: the octree's Morton tree over all sources in one class (leaves of at most
//! `fmm_leaf_size` particles; charges of both signs share the tree), then per cell an
//! expansion centre, a radius and a Cartesian multipole of order p ([`tree`], [`expansion`]);
//! a mutual dual-tree walk ([`walk`]) that finds each pair of cells once: well-separated ones
//! (`r_A + r_B < θ |z_A − z_B|`) become cell–cell interactions (M2L into both cells' local
//! expansions, each cell computing the derivative tensor at its own ±R from its own list: the
//! same bits up to sign, twice the tensor work for thread-independent sums), pairs of near
//! leaves direct particle–particle sums ([`near`], into both leaves); then the local
//! expansions are carried down the tree (L2L) and evaluated at the particles (L2P). Newton's
//! third law holds for cells as for particles, so the total force is zero to rounding.
//!
//! The force error falls as θ^p; θ = 0 accepts no cell pair and gives the direct sum. θ must
//! stay below 1 (the expansions converge only there).
//!
//! Parallel over cells (M2L) and leaves (P2M, near field, L2P): each sums what acts on it in
//! a fixed order, so the forces are the same bits at every thread count (see [`walk`]). The
//! expansions are computed in f64 whatever the precision of the particles, the cell–cell
//! interactions of a cell with `LANES` partners at a time in SIMD lanes; the near field runs
//! in the state's precision. Both run intrinsics for AVX-512 or AVX2 where the machine has
//! them (the cell–cell loop in [`m2l`], the near field of a 1/r² law in `broadcast`), whose
//! last bits differ between instruction sets, and portable loops at the baseline.
//!
//! Counters: `pair_checks` counts the particle pairs of the near field (each pair once),
//! `nodes_accepted` the cell–cell interactions, `nodes_opened` the pairs of cells split.
//!
//! Memory, reused from step to step: the tree's (as the octree's at monopole order), sorted
//! forces, and per cell a centre, a radius, bounds and 2 (p+1)(p+2)(p+3)/6 expansion
//! coefficients (70 at p = 4); the interaction lists, 16 B per pair of cells or leaves (the
//! pair and its entry in both cells' lists). `footprint` has the measured totals.

mod expansion;
mod family;
pub mod harmonic;
mod m2l;
mod near;
mod tree;
mod walk;

#[cfg(test)]
mod tests;

use super::octree::Tree;
use super::rows::LANES;
use super::{ForceKernel, ForceReport, KernelKind, WorkCounters, worth_parallel};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State};
pub use expansion::MAX_ORDER;
use expansion::{Batch, Expansion, Lanes};
use family::Family;
use rayon::prelude::*;
use std::ops::Range;
use std::time::Instant;
use tree::Cells;
use walk::Walk;

/// The expansion order by default: at a median force error near 1e-3, the usual accuracy of
/// these studies, order 4 was the cheapest on `galaxy` and level with orders 5 and 6 on
/// `coulomb`; towards 1e-4 the higher orders at a larger θ cost less (REPORT.md's long-range
/// accuracy section, `configs/octree-accuracy.toml`, has the sweep).
pub(crate) const DEFAULT_ORDER: usize = 4;

/// Most particles in a leaf by default: on `galaxy` 32 and 128 were about 1.3 times slower
/// per particle-step than 64 at equal θ and order; on `coulomb` (uniform charges, whose octree
/// cells grow by 8 per level) 64 and 128 build the same tree, and 32 tripled the error for no
/// gain.
pub(crate) const DEFAULT_LEAF_SIZE: usize = 64;

/// Cells (M2L) or leaves (near field, L2P) per parallel task.
const CELLS_PER_TASK: usize = 16;

/// The `fmm` kernel for the inverse-square law `L` (see the module doc).
pub struct Fmm<L: PairLaw<T>, T: Real, const D: usize> {
    law: L,
    /// The law in f64, for the expansions.
    wide: L::Wide,
    theta: f64,
    exp: Family,
    tree: Tree<T, D>,
    cells: Cells,
    walk: Walk,
    sorted_forces: [Vec<T>; D],
    /// The previous step's near pairs plus cell pairs: the estimate that decides whether to
    /// fork.
    last_work: Option<u64>,
}

impl<L: PairLaw<T>, T: Real, const D: usize> Fmm<L, T, D> {
    /// Takes `0 ≤ theta < 1`, `1 ≤ order ≤ MAX_ORDER` and `leaf_size ≥ 1` as given (a bad
    /// order panics): `KernelKind::build` checks them first (`KernelParams::validate`), and
    /// users outside the crate go through it, as this is the crate's own.
    pub(crate) fn new(law: L, theta: f64, order: usize, leaf_size: usize) -> Self {
        Self::of_family(
            law,
            theta,
            Family::Cartesian(Expansion::new(order)),
            leaf_size,
        )
    }

    /// The kernel on solid harmonics of order `1 ≤ order ≤ MAX_HARMONIC_ORDER` (a bad order
    /// panics, as in [`Fmm::new`]); `None` for a law with softening or no 1/r potential,
    /// which these harmonics cannot expand.
    pub(crate) fn harmonic(law: L, theta: f64, order: usize, leaf_size: usize) -> Option<Self> {
        let law_1r = law.widen().inverse_square()?;
        if law_1r.eps2 != 0.0 {
            return None;
        }
        // The pair force coefficient is k/r³ for a potential −k s_i s_j / r: κ = −k.
        let family = Family::Harmonic(Box::new(harmonic::Harmonic::new(order)), -law_1r.k);
        Some(Self::of_family(law, theta, family, leaf_size))
    }

    fn of_family(law: L, theta: f64, exp: Family, leaf_size: usize) -> Self {
        Fmm {
            law,
            wide: law.widen(),
            theta,
            exp,
            tree: Tree::one_class(leaf_size),
            cells: Cells::new(),
            walk: Walk::new(),
            sorted_forces: std::array::from_fn(|_| Vec::new()),
            last_work: None,
        }
    }

    /// Builds the tree, centres, radii and multipoles of `state` without computing any force:
    /// the build phase of [`ForceKernel::compute`] alone, for benchmarks.
    pub fn build(&mut self, state: &State<T, D>) {
        self.build_on(state, crate::par::worth_forking(state.len()));
    }

    fn build_on(&mut self, state: &State<T, D>, parallel: bool) {
        self.tree.build(state);
        self.cells.upward(&self.tree, &self.exp, parallel);
    }

    /// The far field: every cell's local expansion from its M2L partners (from order 1 on,
    /// or with `probe` from the potential on), the cells on the pool's threads when
    /// `parallel`.
    fn far_field(&mut self, parallel: bool, probe: bool) {
        let len = self.exp.len();
        let mut local = std::mem::take(&mut self.cells.local);
        match &self.exp {
            Family::Cartesian(exp) => {
                let first = if probe { 0 } else { 1 };
                let (wide, cells, lists) = (&self.wide, &self.cells, &self.walk.far);
                let cell = |batch: &mut Batch, (c, local): (usize, &mut [f64])| {
                    let partners = lists.of(c);
                    if partners.is_empty() {
                        return;
                    }
                    simd::dispatch(
                        #[inline(always)]
                        || far_of_cell(exp, wide, cells, c, partners, first, batch, local),
                    );
                };
                if parallel {
                    local
                        .par_chunks_mut(len)
                        .enumerate()
                        .with_min_len(CELLS_PER_TASK)
                        .for_each_init(|| Batch::new(len), cell);
                } else {
                    let mut batch = Batch::new(len);
                    local
                        .chunks_mut(len)
                        .enumerate()
                        .for_each(|item| cell(&mut batch, item));
                }
            }
            Family::Harmonic(h, kappa) => {
                let (cells, lists, isa) = (&self.cells, &self.walk.far, m2l::isa());
                let cell = |scratch: &mut harmonic::Scratch, (c, local): (usize, &mut [f64])| {
                    let partners = lists.of(c);
                    if partners.is_empty() {
                        local.fill(0.0);
                        return;
                    }
                    harmonic::batch::far(
                        &h.plan,
                        *kappa,
                        isa,
                        cells.centre[c],
                        partners,
                        &cells.centre,
                        &cells.multipole,
                        local,
                        &mut scratch.batch,
                    );
                };
                if parallel {
                    local
                        .par_chunks_mut(len)
                        .enumerate()
                        .with_min_len(CELLS_PER_TASK)
                        .for_each_init(|| h.scratch(), cell);
                } else {
                    let mut scratch = h.scratch();
                    local
                        .chunks_mut(len)
                        .enumerate()
                        .for_each(|item| cell(&mut scratch, item));
                }
            }
        }
        self.cells.local = local;
    }

    /// The near field and L2P of every leaf into the sorted forces, the leaves on the pool's
    /// threads when `parallel`. With `PROBE`, returns the near pairs' energy (each pair from
    /// both ends), Σ s ψ of the far field and the interacting pairs seen from both ends.
    fn leaves<const PROBE: bool>(&mut self, parallel: bool) -> (f64, f64, u64) {
        let n = self.tree.src.len();
        for f in &mut self.sorted_forces {
            f.clear();
            f.resize(n, T::zero());
        }
        let (law, exp, cells, tree) = (&self.law, &self.exp, &self.cells, &self.tree);
        let near = &self.walk.near;
        // The force arrays cut at the leaves' slot ranges (the leaves tile the sorted slots).
        let mut parts: Vec<[&mut [T]; D]> = Vec::with_capacity(cells.leaves.len());
        let mut rest = self.sorted_forces.each_mut().map(|f| f.as_mut_slice());
        for &leaf in &cells.leaves {
            let node = &tree.nodes[leaf as usize];
            let size = (node.end - node.start) as usize;
            let mut cut = rest.map(|r| {
                let (a, b) = r.split_at_mut(size);
                (Some(a), Some(b))
            });
            parts.push(std::array::from_fn(|d| cut[d].0.take().expect("cut once")));
            rest = std::array::from_fn(|d| cut[d].1.take().expect("cut once"));
        }
        let leaf = |(ranges, scratch): &mut (Vec<Range<usize>>, family::Scratch),
                    (&i, out): (&u32, &mut [&mut [T]; D])| {
            let i = i as usize;
            let node = &tree.nodes[i];
            let slots = node.start as usize..node.end as usize;
            ranges.clear();
            ranges.extend(near.of(i).iter().map(|&b| {
                let b = &tree.nodes[b as usize];
                b.start as usize..b.end as usize
            }));
            let (pos, src) = (&tree.pos, &tree.src);
            let (energy, interacting) = if PROBE {
                simd::dispatch(
                    #[inline(always)]
                    || near::probe_leaf(law, pos, src, slots.clone(), ranges, out),
                )
            } else {
                simd::dispatch(
                    #[inline(always)]
                    || near::leaf_forces(law, pos, src, slots.clone(), ranges, out),
                );
                (0.0, 0)
            };
            let potential = tree::evaluate(exp, cells, tree, i, PROBE, out, scratch);
            (energy, potential, interacting)
        };
        let add = |a: (f64, f64, u64), b: (f64, f64, u64)| (a.0 + b.0, a.1 + b.1, a.2 + b.2);
        if parallel {
            cells
                .leaves
                .par_iter()
                .zip(parts.par_iter_mut())
                .with_min_len(CELLS_PER_TASK)
                .for_each_init(
                    || (Vec::new(), exp.scratch()),
                    |buffers, item| {
                        leaf(buffers, item);
                    },
                );
            (0.0, 0.0, 0)
        } else {
            let mut buffers = (Vec::new(), exp.scratch());
            cells
                .leaves
                .iter()
                .zip(parts.iter_mut())
                .map(|item| leaf(&mut buffers, item))
                .fold((0.0, 0.0, 0), add)
        }
    }
}

/// The local expansion of cell `c` from its M2L `partners`, `LANES` at a time, into `local`
/// (overwritten). Each lane sums its partners in list order, and the lanes are added at the
/// end by [`lane_sum`](crate::kernels::rows::lane_sum)'s pairwise tree: a fixed order
/// whatever runs it.
#[inline(always)]
fn far_of_cell<W: PairLaw<f64>>(
    exp: &Expansion,
    wide: &W,
    cells: &Cells,
    c: usize,
    partners: &[u32],
    first: usize,
    batch: &mut Batch,
    local: &mut [f64],
) {
    let len = exp.len;
    let eps2 = wide.softening2();
    let z = cells.centre[c];
    let isa = m2l::isa();
    for row in &mut batch.la[..len] {
        *row = [0.0; LANES];
    }
    for group in partners.chunks(LANES) {
        let r = &mut batch.r;
        for (l, &b) in group.iter().enumerate() {
            let b = b as usize;
            for d in 0..3 {
                r[d][l] = z[d] - cells.centre[b][d];
            }
            let m = &cells.multipole[b * len..(b + 1) * len];
            for (row, &v) in batch.mb[..len].iter_mut().zip(m) {
                row[l] = v;
            }
        }
        // Lanes past the partners repeat the first one's offset with a zero multipole.
        for l in group.len()..LANES {
            for d in 0..3 {
                r[d][l] = r[d][0];
            }
            for row in &mut batch.mb[..len] {
                row[l] = 0.0;
            }
        }
        let r2: Lanes =
            std::array::from_fn(|l| r[0][l] * r[0][l] + r[1][l] * r[1][l] + r[2][l] * r[2][l]);
        let coeff: Lanes = std::array::from_fn(|l| wide.coeff(r2[l], 1.0, 1.0));
        let soft: Lanes = std::array::from_fn(|l| r2[l] + eps2);
        expansion::scaled_derivatives(&coeff, &soft, exp.p, &mut batch.dj);
        // SAFETY: `m2l::isa()` has checked the CPU.
        unsafe { m2l::m2l_batch(isa, exp, batch, first) };
    }
    for (out, lanes) in local.iter_mut().zip(&batch.la[..len]) {
        *out = crate::kernels::rows::lane_sum(*lanes);
    }
}

impl<L: PairLaw<T>, T: Real, const D: usize> ForceKernel<T, D> for Fmm<L, T, D> {
    fn kind(&self) -> KernelKind {
        KernelKind::Fmm
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        let n = state.len();
        for f in forces.iter() {
            assert_eq!(f.len(), n, "force field length must equal n");
        }
        if n == 0 {
            return ForceReport {
                energy: probe.then_some(0.0),
                ..Default::default()
            };
        }
        // The probe sums energies, which a parallel run would add in a thread-dependent order.
        let parallel = !probe && worth_parallel(self.last_work.unwrap_or((n as u64).pow(2)));
        let started = Instant::now();
        self.build_on(state, parallel);
        let build_s = started.elapsed().as_secs_f64();

        let counts = self
            .walk
            .run(&self.tree, &self.cells, self.theta, &self.wide);
        self.far_field(parallel, probe);
        self.cells.downward(&self.tree, &self.exp);
        let (near_energy, potential, interacting) = if probe {
            self.leaves::<true>(false)
        } else {
            self.leaves::<false>(parallel)
        };

        for d in 0..D {
            let (dst, src) = (&mut forces[d], &self.sorted_forces[d]);
            for (&i, &f) in self.tree.order.iter().zip(src.iter()) {
                dst[i as usize] = f;
            }
        }
        let nodes = &self.tree.nodes;
        let size = |a: usize| (nodes[a].end - nodes[a].start) as u64;
        // Near pairs, each once: Σ over leaves of |leaf| · |its near particles|, less the
        // self-pairs, halved.
        let seen: u64 = self
            .cells
            .leaves
            .iter()
            .map(|&a| {
                let a = a as usize;
                size(a)
                    * self
                        .walk
                        .near
                        .of(a)
                        .iter()
                        .map(|&b| size(b as usize))
                        .sum::<u64>()
            })
            .sum();
        let pairs = (seen - n as u64) / 2;
        // A cell pair counts as many particle pairs as its contraction has terms (210 at order
        // 4, about what one costs there; 7 at order 1, 3003 at order 8): its work grows with
        // the order as they do.
        self.last_work = Some(pairs + self.exp.m2l_work() as u64 * counts.m2l);
        ForceReport {
            // Every pair is seen from both ends, near or far.
            energy: probe.then_some(0.5 * (near_energy + potential)),
            build_s,
            work: WorkCounters {
                pair_checks: pairs,
                pairs_interacting: if probe { interacting / 2 } else { 0 },
                nodes_opened: counts.opened,
                nodes_accepted: counts.m2l,
                ..Default::default()
            },
        }
    }

    /// Tree order: Morton order over all particles, which makes the next builds' gathers
    /// sequential.
    fn spatial_order(&mut self, state: &State<T, D>) -> Option<Vec<u32>> {
        self.tree.sort(state);
        Some(self.tree.sorted_order())
    }
}

/// A point of the sorted positions in 3-D (zero past the state's dimension).
#[inline(always)]
fn point<T: Real, const D: usize>(pos: &[Vec<T>; D], k: usize) -> [f64; 3] {
    std::array::from_fn(|d| if d < D { pos[d][k].as_f64() } else { 0.0 })
}
