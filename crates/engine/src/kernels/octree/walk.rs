//! The grouped tree walk (Barnes' vectorized method): each target group builds one interaction
//! list from the root, and every particle of the group then gathers from that list.
//!
//! The list is a small SoA array of sources: the group's own particles first, then, in walk
//! order, the centres and total strengths of accepted nodes (a monopole acts exactly like one
//! particle there) and the particles of opened leaves. On the timed path the group's particles
//! are taken in tiles of `LANES` targets, and each list entry is broadcast to a whole tile
//! (`broadcast::tile_forces`), which does both the particle-node and the particle-particle
//! work; lane l skips the list slot that holds its own particle. The probe path gathers one
//! target at a time (`rows::gather`), splitting the run around the target, so the interaction
//! counts see only real sources.
//!
//! At quadrupole order the walk (monomorphized with `QUAD`) writes the accepted nodes' arena
//! indices instead, and each group's node list (`nodes::NodeList`) is filled from them; every
//! target then gathers from both lists.

use super::nodes::NodeList;
use super::tree::{Group, Tree};
use crate::geometry::Bounds;
use crate::kernels::WorkCounters;
use crate::kernels::broadcast::{Tile, tile_forces};
use crate::kernels::rows::{LANES, Sources, Target, gather};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use std::sync::atomic::{AtomicU32, Ordering};

/// Per-walk scratch: the interaction list of the current group (SoA, `len` entries in use;
/// the arrays only grow, so that entries can be written before deciding whether to keep
/// them) and the walk's stack of nodes to open.
pub(super) struct Scratch<T, const D: usize> {
    pos: [Vec<T>; D],
    src: Vec<T>,
    len: usize,
    stack: Vec<u32>,
    /// Quadrupole order: the arena indices of the accepted nodes, and their list.
    accepted: Vec<u32>,
    nodes: NodeList<T, D>,
}

impl<T: Real, const D: usize> Scratch<T, D> {
    pub fn new() -> Self {
        Scratch {
            pos: std::array::from_fn(|_| Vec::new()),
            src: Vec::new(),
            len: 0,
            stack: Vec::new(),
            accepted: Vec::new(),
            nodes: NodeList::new(),
        }
    }

    /// Makes room for `extra` more entries.
    #[inline(always)]
    fn reserve(&mut self, extra: usize) {
        let need = self.len + extra;
        if self.src.len() < need {
            // Grow geometrically: after the first steps this never happens again.
            let cap = need.max(2 * self.src.len()).max(256);
            for p in &mut self.pos {
                p.resize(cap, T::zero());
            }
            self.src.resize(cap, T::zero());
        }
    }

    /// Appends sorted particles `lo..hi` of the tree.
    #[inline(always)]
    fn push_range(&mut self, tree: &Tree<T, D>, lo: usize, hi: usize) {
        self.reserve(hi - lo);
        let k = self.len;
        for d in 0..D {
            self.pos[d][k..k + hi - lo].copy_from_slice(&tree.pos[d][lo..hi]);
        }
        self.src[k..k + hi - lo].copy_from_slice(&tree.src[lo..hi]);
        self.len += hi - lo;
    }

    /// Entries `lo..hi`.
    #[inline(always)]
    fn sources(&self, lo: usize, hi: usize) -> Sources<'_, T, D> {
        Sources::range(&self.pos, &self.src, lo, hi)
    }
}

/// What a run of groups adds to the step's totals.
#[derive(Clone, Copy, Default)]
pub(super) struct Totals {
    pub work: WorkCounters,
    /// Σ over targets of their energy with their sources (each pair counted from both ends).
    pub energy: f64,
    pub interacting: u64,
}

impl std::ops::AddAssign for Totals {
    fn add_assign(&mut self, o: Totals) {
        self.work += o.work;
        self.energy += o.energy;
        self.interacting += o.interacting;
    }
}

/// The group being listed: its particle range and bounding box.
struct GroupBox<T, const D: usize> {
    start: u32,
    end: u32,
    lo: [T; D],
    hi: [T; D],
}

/// Tests the nodes `family` against the group: accepted ones go to the list (as monopoles,
/// or with `QUAD` as indices for the node list), the others onto the stack to be opened.
/// Branch-free: every node is written to both and only one of the two lengths advances, so
/// the unpredictable accept/open outcome costs no mispredicted branches.
#[inline(always)]
fn test_family<T: Real, const D: usize, const QUAD: bool>(
    tree: &Tree<T, D>,
    family: std::ops::Range<usize>,
    g: &GroupBox<T, D>,
    list: &mut Scratch<T, D>,
    work: &mut WorkCounters,
) {
    let count = family.len();
    // Monopoles are written to the particle list, quadrupoles' indices to `accepted`.
    let (mono, quad) = if QUAD { (0, count) } else { (count, 0) };
    list.reserve(mono);
    let (base, sp, qp) = (list.len, list.stack.len(), list.accepted.len());
    list.stack.resize(sp + count, 0);
    list.accepted.resize(qp + quad, 0);
    // Local slices and counters, so that the loop keeps them in registers.
    let pos = list.pos.each_mut().map(|p| &mut p[base..base + mono]);
    let src = &mut list.src[base..base + mono];
    let stack = &mut list.stack[sp..sp + count];
    let accepted_nodes = &mut list.accepted[qp..qp + quad];
    let (mut accepted, mut opened) = (0, 0);
    for (c, node) in tree.nodes[family.clone()].iter().enumerate() {
        // A node holding some of the group's own particles is never accepted (it would count
        // them, and the self-pairs, twice); the criterion alone ensures it for θ < 1/√D only.
        let own = (node.start < g.end) & (node.end > g.start);
        let accept = node.far_from_box(&g.lo, &g.hi) & !own;
        if QUAD {
            accepted_nodes[accepted] = (family.start + c) as u32;
        } else {
            for d in 0..D {
                pos[d][accepted] = node.com[d];
            }
            src[accepted] = node.strength;
        }
        stack[opened] = (family.start + c) as u32;
        accepted += accept as usize;
        opened += !accept as usize;
    }
    if QUAD {
        list.accepted.truncate(qp + accepted);
    } else {
        list.len = base + accepted;
    }
    list.stack.truncate(sp + opened);
    work.nodes_accepted += accepted as u64;
    work.nodes_opened += opened as u64;
}

/// Builds the interaction list of a group: its own particles first (at slots 0..m, so target
/// k sits at slot k), then what a walk of every tree from its root accepts or opens; with
/// `QUAD`, the accepted nodes go to the node list instead.
fn interaction_list<T: Real, const D: usize, const QUAD: bool>(
    tree: &Tree<T, D>,
    g: &GroupBox<T, D>,
    list: &mut Scratch<T, D>,
    work: &mut WorkCounters,
) {
    list.len = 0;
    list.stack.clear();
    list.accepted.clear();
    list.push_range(tree, g.start as usize, g.end as usize);
    for &root in &tree.roots {
        test_family::<T, D, QUAD>(tree, root as usize..root as usize + 1, g, list, work);
    }
    // Every node is pushed at most once and the tree is finite, so this ends whatever the
    // values (NaN distances open nodes down to the leaves).
    while let Some(i) = list.stack.pop() {
        let node = &tree.nodes[i as usize];
        if node.start >= g.start && node.end <= g.end {
            // Inside the group: its particles are already listed.
            continue;
        }
        if node.children == 0 {
            // An opened leaf contributes its particles directly.
            list.push_range(tree, node.start as usize, node.end as usize);
        } else {
            let first = node.first as usize;
            test_family::<T, D, QUAD>(tree, first..first + node.children as usize, g, list, work);
        }
    }
    if QUAD {
        list.nodes.fill(tree, &list.accepted);
    }
}

/// Computes the forces on the particles of `groups` (contiguous in sorted order) into `out`,
/// whose first element is sorted slot `offset`. Unless `costs` is empty (one slot per sorted
/// particle), each particle's slot receives its interaction count: the length of its group's
/// list less itself, what `pair_checks` counts for it.
///
/// The walk runs at the baseline instruction set; only each group's target loop goes through
/// `simd::dispatch`. With the walk inlined into the same function as the pair loop, LLVM
/// scalarized the loop's lane accumulators (1.5× slower pair loop), so they are kept apart.
pub(super) fn eval_groups<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool>(
    law: &L,
    tree: &Tree<T, D>,
    groups: &[Group],
    offset: usize,
    out: &mut [&mut [T]; D],
    list: &mut Scratch<T, D>,
    costs: &[AtomicU32],
) -> Totals {
    if tree.quadrupole() {
        eval_order::<T, L, D, PROBE, true>(law, tree, groups, offset, out, list, costs)
    } else {
        eval_order::<T, L, D, PROBE, false>(law, tree, groups, offset, out, list, costs)
    }
}

/// [`eval_groups`] at one multipole order.
fn eval_order<T: Real, L: PairLaw<T>, const D: usize, const PROBE: bool, const QUAD: bool>(
    law: &L,
    tree: &Tree<T, D>,
    groups: &[Group],
    offset: usize,
    out: &mut [&mut [T]; D],
    list: &mut Scratch<T, D>,
    costs: &[AtomicU32],
) -> Totals {
    let mut totals = Totals::default();
    for g in groups {
        let (start, end) = (g.start as usize, g.end as usize);
        // The group's bounding box (tighter than its cells).
        let Bounds { lo, hi } = Bounds::of_columns(tree.pos.each_ref().map(|x| &x[start..end]));
        let group = GroupBox {
            start: g.start,
            end: g.end,
            lo,
            hi,
        };
        interaction_list::<T, D, QUAD>(tree, &group, list, &mut totals.work);
        let real = list.len;
        let nodes = if QUAD { list.nodes.len } else { 0 };
        totals.work.pair_checks += ((end - start) * (real - 1 + nodes)) as u64;
        if !costs.is_empty() {
            // Disjoint slots per group: the ordering of these stores does not matter.
            let each = u32::try_from(real - 1 + nodes).unwrap_or(u32::MAX);
            for c in &costs[start..end] {
                c.store(each, Ordering::Relaxed);
            }
        }
        let out = out.each_mut().map(|o| &mut o[start - offset..end - offset]);
        if PROBE {
            let (energy, interacting) = simd::dispatch(
                #[inline(always)]
                || probe_forces::<T, L, D, QUAD>(law, tree, start, real, list, out),
            );
            totals.energy += energy;
            totals.interacting += interacting;
        } else {
            simd::dispatch(
                #[inline(always)]
                || group_forces::<T, L, D, QUAD>(law, tree, start, list, out),
            );
        }
    }
    totals
}

/// Forces on the group's particles (sorted slots `start..start + out.len()`, list slots
/// `0..out.len()`) from its list (and with `QUAD` its node list): the particles in tiles of
/// `LANES`, each source of the list broadcast to a whole tile (`broadcast::tile_forces`).
#[inline(always)]
fn group_forces<T: Real, L: PairLaw<T>, const D: usize, const QUAD: bool>(
    law: &L,
    tree: &Tree<T, D>,
    start: usize,
    list: &Scratch<T, D>,
    out: [&mut [T]; D],
) {
    let sources = list.sources(0, list.len);
    for lo in (0..out[0].len()).step_by(LANES) {
        let len = LANES.min(out[0].len() - lo);
        let tile = Tile::load(&tree.pos, &tree.src, start + lo, start + lo + len);
        // The group's own particles are the list's first entries: lane l sits at slot lo + l.
        let force = tile_forces(law, &tile, &sources, lo);
        for d in 0..D {
            out[d][lo..lo + len].copy_from_slice(&force[d][..len]);
        }
    }
    if QUAD {
        // The nodes in the gather form, one target at a time: with each node broadcast to a
        // tile instead (its ten values each), the loop measured 10–15 % slower.
        for k in 0..out[0].len() {
            let i = start + k;
            let t = Target {
                x: std::array::from_fn(|d| tree.pos[d][i]),
                s: tree.src[i],
            };
            let force = list.nodes.forces(law, &t);
            for d in 0..D {
                out[d][k] += force[d];
            }
        }
    }
}

/// The probe's [`group_forces`]: one target at a time with the gather form, the run split
/// around the target so that the interaction counts see only real sources; returns the
/// energy and the interacting count.
#[inline(always)]
fn probe_forces<T: Real, L: PairLaw<T>, const D: usize, const QUAD: bool>(
    law: &L,
    tree: &Tree<T, D>,
    start: usize,
    real: usize,
    list: &Scratch<T, D>,
    out: [&mut [T]; D],
) -> (f64, u64) {
    let (mut energy, mut interacting) = (0.0, 0);
    for k in 0..out[0].len() {
        let i = start + k;
        let t = Target {
            x: std::array::from_fn(|d| tree.pos[d][i]),
            s: tree.src[i],
        };
        let mut sum = gather::<T, L, D, true>(law, &t, &list.sources(0, k));
        sum.add(&gather::<T, L, D, true>(
            law,
            &t,
            &list.sources(k + 1, real),
        ));
        if QUAD {
            sum.add(&list.nodes.gather::<L, true>(law, &t));
        }
        for d in 0..D {
            out[d][k] = sum.force[d];
        }
        energy += sum.energy.as_f64();
        interacting += sum.interacting;
    }
    (energy, interacting)
}

/// Calls `f(groups, offset, out)` on consecutive runs of groups with the matching disjoint
/// parts of the sorted-order force arrays, in parallel on the current rayon pool, splitting
/// at group boundaries down to about `min_len` particles. Returns the summed totals.
pub(super) fn for_group_runs<T: Send, const D: usize, F>(
    groups: &[Group],
    out: [&mut [T]; D],
    offset: usize,
    min_len: usize,
    f: &F,
) -> Totals
where
    F: Fn(&[Group], usize, [&mut [T]; D]) -> Totals + Sync,
{
    if groups.len() <= 1 || out[0].len() <= min_len.max(1) {
        return f(groups, offset, out);
    }
    let mid = groups.len() / 2;
    let split = groups[mid].start as usize - offset;
    let mut halves = out.map(|p| {
        let (a, b) = p.split_at_mut(split);
        (Some(a), Some(b))
    });
    let lo: [&mut [T]; D] = std::array::from_fn(|d| halves[d].0.take().expect("split once"));
    let hi: [&mut [T]; D] = std::array::from_fn(|d| halves[d].1.take().expect("split once"));
    let (mut a, b) = rayon::join(
        || for_group_runs(&groups[..mid], lo, offset, min_len, f),
        || for_group_runs(&groups[mid..], hi, offset + split, min_len, f),
    );
    a += b;
    a
}
