//! `octree`: Barnes-Hut with opening angle θ (an octree in 3-D, a quadtree in 2-D), nodes as
//! quadrupoles by default or as monopoles at the centre of strength ([`Multipole`]), O(n log n).
//!
//! Each step: Morton keys over the current bounding cube, one sort, and a compressed tree in a
//! flat arena ([`tree`]); then a grouped walk ([`walk`]): each group of up to [`GROUP_SIZE`]
//! neighbouring particles builds one interaction list (accepted nodes as monopoles, opened
//! leaves as particles), which the group's particles take in tiles of SIMD lanes with every entry
//! broadcast (`broadcast::tile_forces`). At quadrupole order the accepted nodes go to a separate node list
//! ([`nodes`]) with their second moments ([`moments`], computed at every build), evaluated by
//! a loop of its own; opened leaves stay in the particle list. A node of side `s` is accepted when `s/d < θ`, with `d` the distance
//! from its centre of strength to the nearest point of the group's bounding box, so θ = 0 gives
//! the direct sum. Sources of each sign get their own tree (Coulomb), and every group walks all
//! trees. Parallel over groups; the forces do not depend on the thread count.
//! The opening test is `Node::far_from_box`; [`TreeView`] exposes a built tree, with that same
//! test, to the locally essential tree of `decomp::essential`.
//!
//! Counters: `nodes_accepted` and `nodes_opened` count, summed over groups, the nodes whose test
//! passed and failed (a failed node is split into its children, or its particles are used
//! directly if it is a leaf or lies inside the group); `pair_checks` counts the particle-
//! particle and particle-node interactions evaluated (of either order), padding excluded.
//!
//! Memory, all reused from step to step: a sorted copy of positions and strengths, the keys
//! (16 B per particle), the nodes (fewer than 2n, as every internal node has two children or
//! more; ~0.43 n on a Plummer sphere at leaf size 8), a sorted force buffer, and one
//! interaction list per thread (a few thousand entries). The quadrupole order adds
//! D(D+1)/2 + 1 values per node (Q and T) and a node list per thread.

mod m2p;
mod moments;
mod node;
mod nodes;
mod tree;
mod view;
mod walk;

#[cfg(test)]
mod tests;

use super::{ForceKernel, ForceReport, KernelKind, WorkCounters, worth_parallel};
use crate::par::chunk_len;
use crate::physics::PairLaw;
use crate::real::Real;
use crate::state::{Field, State};
pub(crate) use node::far_from_box;
use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::Instant;
use tree::Group;
/// The tree build, shared with the fast multipole kernel.
pub(in crate::kernels) use tree::Tree;
pub use view::TreeView;
use walk::{Scratch, Totals, eval_groups, for_group_runs};

/// Most particles in a target group sharing one interaction list. Larger groups walk the
/// tree fewer times but gather from longer lists (the box is larger, so fewer nodes pass).
/// On a Plummer sphere of 1e5 at θ = 0.5 and leaf size 8, 16 and 32 are within 2 % of each
/// other; 8 is 15 % slower (more walks), 64 is 7 % slower (longer lists).
pub(crate) const GROUP_SIZE: usize = 32;

/// The order of the expansion of accepted nodes.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize,
)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "kebab-case")]
pub enum Multipole {
    /// Total strength at the centre of strength: the node acts as one particle. The default
    /// when reading files written before the order was recorded (the default order of a new
    /// run is `KernelParams`'s).
    #[default]
    Monopole,
    /// Monopole plus the second moments about the centre (the dipole vanishes there).
    Quadrupole,
}

impl Multipole {
    /// Both orders, lowest first.
    pub const ALL: [Multipole; 2] = [Multipole::Monopole, Multipole::Quadrupole];

    /// The order's name on the command line and in results.
    pub fn name(self) -> &'static str {
        match self {
            Multipole::Monopole => "monopole",
            Multipole::Quadrupole => "quadrupole",
        }
    }
}

/// The `octree` kernel (a quadtree in 2-D) for the inverse-square law `L`: Barnes-Hut with opening
/// angle θ.
pub struct Octree<L, T, const D: usize> {
    law: L,
    tree: Tree<T, D>,
    /// Forces in sorted (tree) order, scattered back to the caller's order after the walk.
    sorted_forces: [Vec<T>; D],
    /// One interaction list per rayon thread, picked by thread index (never contended).
    lists: Vec<Mutex<Scratch<T, D>>>,
    /// Pair checks of the previous step: the estimate that decides whether to fork.
    last_pairs: Option<u64>,
    /// With [`Octree::record_target_costs`]: each sorted slot's interaction count during a
    /// walk, and each target's of the last [`ForceKernel::compute_targets`], in target order.
    sorted_costs: Vec<AtomicU32>,
    target_costs: Option<Vec<u32>>,
}

impl<L, T: Real, const D: usize> Octree<L, T, D> {
    /// Takes `theta ≥ 0` and `1 ≤ leaf_size` as given: outside this module the tree is only
    /// built by `KernelKind::build`, which checks them first (`KernelParams::validate`); the
    /// module's own tests pass valid values.
    pub fn new(law: L, theta: f64, leaf_size: usize) -> Self {
        Self::with_multipole(law, theta, leaf_size, Multipole::Monopole)
    }

    /// [`Octree::new`] at the given expansion order.
    pub fn with_multipole(law: L, theta: f64, leaf_size: usize, multipole: Multipole) -> Self {
        Octree {
            law,
            tree: Tree::new(
                theta,
                leaf_size,
                GROUP_SIZE,
                multipole == Multipole::Quadrupole,
            ),
            sorted_forces: std::array::from_fn(|_| Vec::new()),
            lists: Vec::new(),
            last_pairs: None,
            sorted_costs: Vec::new(),
            target_costs: None,
        }
    }

    /// From now on [`ForceKernel::compute_targets`] also records each target's interaction
    /// count (the list it gathered from, less itself: its share of `pair_checks`), for a
    /// decomposition that weighs bodies by their cost.
    pub fn record_target_costs(&mut self) {
        self.target_costs.get_or_insert_with(Vec::new);
    }

    /// Each target's interaction count in the last `compute_targets` (index `i` for target
    /// `targets.start + i`), when recording.
    pub fn target_costs(&self) -> Option<&[u32]> {
        self.target_costs.as_deref()
    }

    /// Builds the tree of `state` (Morton keys, sort, nodes, target groups) without computing
    /// any force: the build phase of [`ForceKernel::compute`] alone, for benchmarks.
    pub fn build(&mut self, state: &State<T, D>) {
        self.tree.build(state);
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for Octree<L, T, D> {
    fn kind(&self) -> KernelKind {
        KernelKind::Octree
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
        let started = Instant::now();
        self.build(state);
        let build_s = started.elapsed().as_secs_f64();

        for f in &mut self.sorted_forces {
            f.resize(n, T::zero());
        }
        let threads = rayon::current_num_threads().max(1);
        if self.lists.len() < threads {
            self.lists
                .resize_with(threads, || Mutex::new(Scratch::new()));
        }
        let (law, tree, lists) = (&self.law, &self.tree, &self.lists);
        let mut out = self.sorted_forces.each_mut().map(|f| f.as_mut_slice());
        // A poisoned lock only means another thread panicked mid-walk; the list is rebuilt
        // from scratch by every group, so its contents are never relied upon.
        let list = |slot: usize| {
            lists[slot % lists.len()]
                .lock()
                .unwrap_or_else(|e| e.into_inner())
        };
        let estimate = self.last_pairs.unwrap_or((n as u64) * (n as u64 - 1));
        let totals = if probe {
            eval_groups::<T, L, D, true>(law, tree, &tree.groups, 0, &mut out, &mut list(0), &[])
        } else if worth_parallel(estimate) {
            for_group_runs(
                &tree.groups,
                out,
                0,
                chunk_len(n),
                &|groups, offset, mut part| {
                    let mut list = list(rayon::current_thread_index().unwrap_or(0));
                    let no_costs = &[];
                    eval_groups::<T, L, D, false>(
                        law, tree, groups, offset, &mut part, &mut list, no_costs,
                    )
                },
            )
        } else {
            eval_groups::<T, L, D, false>(law, tree, &tree.groups, 0, &mut out, &mut list(0), &[])
        };
        self.last_pairs = Some(totals.work.pair_checks);

        // Back to the caller's order.
        for d in 0..D {
            let (dst, src) = (&mut forces[d], &self.sorted_forces[d]);
            for (&i, &f) in self.tree.order.iter().zip(src.iter()) {
                dst[i as usize] = f;
            }
        }
        report(totals, build_s, probe)
    }

    /// The tree holds every particle; only the groups that contain a target walk it.
    fn compute_targets(
        &mut self,
        state: &State<T, D>,
        targets: Range<usize>,
        out: [&mut [T]; D],
    ) -> ForceReport {
        let n = state.len();
        if targets.is_empty() {
            return ForceReport::default();
        }
        let started = Instant::now();
        self.tree.build(state);
        let build_s = started.elapsed().as_secs_f64();
        for f in &mut self.sorted_forces {
            f.resize(n, T::zero());
        }
        let threads = rayon::current_num_threads().max(1);
        if self.lists.len() < threads {
            self.lists
                .resize_with(threads, || Mutex::new(Scratch::new()));
        }
        let order = &self.tree.order;
        let wanted = |g: &Group| {
            order[g.start as usize..g.end as usize]
                .iter()
                .any(|&i| targets.contains(&(i as usize)))
        };
        let groups: Vec<Group> = self.tree.groups.iter().copied().filter(wanted).collect();
        let recording = self.target_costs.is_some();
        if recording {
            self.sorted_costs.resize_with(n, || AtomicU32::new(0));
        }
        let costs: &[AtomicU32] = if recording { &self.sorted_costs } else { &[] };
        let (law, tree, lists) = (&self.law, &self.tree, &self.lists);
        let list = |slot: usize| {
            lists[slot % lists.len()]
                .lock()
                .unwrap_or_else(|e| e.into_inner())
        };
        let mut sorted = self.sorted_forces.each_mut().map(|f| f.as_mut_slice());
        // The last full step's pair checks, scaled to the targets' share.
        let estimate = self
            .last_pairs
            .unwrap_or((n as u64) * (n as u64 - 1))
            .saturating_mul(targets.len() as u64)
            / n as u64;
        // The selected groups are in sorted order with gaps; the runs split at group starts,
        // so each part of the sorted force arrays still holds its groups.
        let totals = if worth_parallel(estimate) {
            for_group_runs(
                &groups,
                sorted,
                0,
                chunk_len(targets.len()),
                &|gs, offset, mut part| {
                    let mut list = list(rayon::current_thread_index().unwrap_or(0));
                    eval_groups::<T, L, D, false>(
                        law, tree, gs, offset, &mut part, &mut list, costs,
                    )
                },
            )
        } else {
            eval_groups::<T, L, D, false>(law, tree, &groups, 0, &mut sorted, &mut list(0), costs)
        };
        if let Some(t) = &mut self.target_costs {
            t.clear();
            t.resize(targets.len(), 0);
        }
        for g in &groups {
            for k in g.start as usize..g.end as usize {
                let i = self.tree.order[k] as usize;
                if targets.contains(&i) {
                    for d in 0..D {
                        out[d][i - targets.start] = self.sorted_forces[d][k];
                    }
                    if let Some(t) = &mut self.target_costs {
                        t[i - targets.start] = self.sorted_costs[k].load(Ordering::Relaxed);
                    }
                }
            }
        }
        report(totals, build_s, false)
    }

    /// Tree order: Morton order within each sign class (pure Morton order for gravity), which
    /// makes the next builds' gathers sequential.
    fn spatial_order(&mut self, state: &State<T, D>) -> Option<Vec<u32>> {
        self.tree.sort(state);
        Some(self.tree.sorted_order())
    }
}

fn report(totals: Totals, build_s: f64, probe: bool) -> ForceReport {
    let Totals {
        work,
        energy,
        interacting,
    } = totals;
    ForceReport {
        // Every pair of particles is seen from both ends; a particle-node interaction stands
        // for pairs seen from both ends in the same approximation.
        energy: probe.then_some(0.5 * energy),
        build_s,
        work: WorkCounters {
            pairs_interacting: if probe { interacting / 2 } else { 0 },
            ..work
        },
    }
}
