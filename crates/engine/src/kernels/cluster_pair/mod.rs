//! `cluster-pair`: the Verlet list of a dense system, made of clusters of four particles rather
//! than of particles (the scheme of GROMACS's nbnxm). Particles are sorted into clusters of
//! neighbours ([`layout`]); the list holds, for each cluster, runs of consecutive clusters (four
//! in 2-D, two in 3-D) that cover those whose bounding boxes come within the cutoff plus a skin
//! ([`list`]); each particle of the cluster meets a run's particles (16 in 2-D, 8 in 3-D) in one
//! SIMD block ([`tile`]; in 3-D for Lennard-Jones, the intrinsics loop of [`batched`]). It is
//! kept, like the `verlet` list, until some particle has moved more than half the skin since
//! the build, so the forces are exact at every step.
//!
//! Against a list of particle pairs it computes more pairs (those of a run beyond the cutoff)
//! but each far more cheaply: one contiguous load per array instead of gathers, the i-cluster's forces
//! in registers across its list, no branch per pair. The dense liquid, with about eight
//! partners per particle, is its case; in a dilute gas most lanes are empty and
//! `verlet` is the better list.
//!
//! - Half list: each cluster pair once (j at or after i), both ends updated; within the
//!   cluster itself only the pairs `j > i` act (lane masks, see [`list`]).
//! - A long list is cut into parts (ranges of i-clusters, as many whatever the threads) of
//!   two colours whose runs touch disjoint clusters ([`crate::kernels::teamed`]): the threads
//!   run one colour's parts at a time, adding straight into the forces, and every thread count
//!   adds the same contributions in the same order.
//! - At a rebuild the particles are re-sorted into cluster order ([`ForceKernel::sort_every`]
//!   is 1, [`ForceKernel::spatial_order`] answers exactly when a rebuild is due), so the copy of
//!   the positions into the padded slots reads the state in order.
//! - In a periodic box ([`ForceKernel::set_periodic`]) the columns tile the box, the search
//!   meets the columns beyond the faces as images and each run keeps its shift ([`list`]); the
//!   padded copy holds positions continued from the build, as the `verlet` list's loops read
//!   them ([`crate::kernels::images`]), so a wrap neither forces a rebuild nor meets the wrong
//!   image.
//!
//! Memory, kept between rebuilds: per padded slot (at most one slot of padding per column) its
//! particle, position, strength and force; per particle its position at the build and its
//! slot (and in a periodic box its continued position); per cluster its box; per run 13 bytes
//! (its first cluster, shift and four lane masks).

#[cfg_attr(not(target_arch = "x86_64"), allow(unused))]
mod batched;
#[cfg(all(test, target_arch = "x86_64"))]
mod batched_tests;
mod layout;
mod list;
#[cfg(test)]
mod periodic_tests;
mod plan;
#[cfg(test)]
mod tests;
mod tile;

use super::images::Images;
use super::teamed::{Colors, TeamPlan, cut_at_layers, parts_at_layers};
use super::verlet::{list_cutoff, moved_too_far};
use super::{ForceKernel, ForceReport, KernelError, KernelKind, MIN_PARALLEL_PAIRS, WorkCounters};
use crate::par::gather;
use crate::par::team::SharedSlice;
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State};
use batched::add_forces;
use layout::Layout;
use layout::{CLUSTER, Region, group_of};
use list::Part;
use plan::{Plan, add_part};
use rayon::prelude::*;
use std::time::Instant;
use tile::{Clusters, Out, TileSum, run_forces};

/// Relative margin of the list radius (as the `verlet` list's): boxes are compared in f64 at
/// the build and pairs rounded in `T` at every step.
const LIST_MARGIN: f64 = 1e-5;

/// Most parts of a split list, and fewest i-clusters in one: enough parts that the workers
/// of a colour even out parts of unequal density, wide enough that a part's runs reach no
/// further than the next part's clusters (the colouring of [`crate::kernels::teamed`]).
const PARTS: usize = 16;
const MIN_PART_CLUSTERS: usize = 128;

/// Cost of one run (`CLUSTER` times its lanes of pair evaluations and the reactions) in `D`
/// dimensions, in naive pair evaluations, the unit of `worth_parallel`.
const fn run_cost(d: usize) -> u64 {
    (CLUSTER * CLUSTER * group_of(d)) as u64
}

/// The positions of a build: the state's, or in a periodic box wrapped into it (written to
/// `into`).
fn build_positions<'s, T: Real, const D: usize>(
    images: Option<&Images<T, D>>,
    state: &'s State<T, D>,
    into: &'s mut [Vec<T>; D],
) -> [&'s [T]; D] {
    match images {
        Some(images) => {
            images.wrap_all(state, into);
            into.each_ref().map(|x| x.as_slice())
        }
        None => state.pos.each_ref().map(|x| x.as_slice()),
    }
}

/// The `cluster-pair` kernel for the short-range law `L`: a Verlet list of 4-particle clusters.
pub struct ClusterPair<L, T, const D: usize> {
    law: L,
    skin: f64,
    /// The cutoff plus the skin, and its square with the margin.
    radius: f64,
    radius2: f64,
    layout: Layout<T, D>,
    parts: Vec<Part>,
    /// Whether the list matches the layout (false before the first build).
    built: bool,
    /// `spatial_order` handed out the layout's order: the next build starts from it.
    handed_out: bool,
    /// Each state slot's position at the last build.
    at_build: [Vec<T>; D],
    /// Forces per padded slot.
    force: [Vec<T>; D],
    /// The colours of the parts.
    colors: Colors,
    /// The periodic box, if any.
    periodic: Option<Images<T, D>>,
    /// In a periodic box: each state slot's position continued from its place at the build
    /// (as of the last displacement test).
    continued: [Vec<T>; D],
}

impl<L: PairLaw<T>, T: Real, const D: usize> ClusterPair<L, T, D> {
    /// The kernel for `law` with list skin `skin` (length units); refused without a finite cutoff
    /// or a positive skin.
    pub fn new(law: L, skin: f64) -> Result<Self, KernelError> {
        let rc = list_cutoff::<T, L, D>(&law, skin, "the cluster-pair list")?;
        let radius = rc + skin;
        Ok(ClusterPair {
            law,
            skin,
            radius,
            radius2: radius * radius * (1.0 + LIST_MARGIN),
            layout: Layout::new(),
            parts: Vec::new(),
            built: false,
            handed_out: false,
            at_build: std::array::from_fn(|_| Vec::new()),
            force: std::array::from_fn(|_| Vec::new()),
            colors: Colors::default(),
            periodic: None,
            continued: std::array::from_fn(|_| Vec::new()),
        })
    }

    /// Runs of the current list.
    pub fn runs(&self) -> u64 {
        self.parts.iter().map(|p| p.runs() as u64).sum()
    }

    /// Whether the list is missing or some slot moved more than half the skin since the
    /// build; in a periodic box, the slots' continued positions are left in `continued`.
    fn due(&mut self, state: &State<T, D>) -> bool {
        if !self.built {
            return true;
        }
        match &self.periodic {
            Some(images) => {
                images.continue_all(state, &self.at_build, self.skin, &mut self.continued)
            }
            None => moved_too_far(state, &self.at_build, self.skin),
        }
    }

    /// Sorts `state` into clusters.
    fn build_layout(&mut self, state: &State<T, D>) {
        let region = match &self.periodic {
            Some(images) => {
                let lo = images.lo64();
                let side = images.side64();
                Region {
                    lo,
                    hi: std::array::from_fn(|d| lo[d] + side[d]),
                    periodic: true,
                }
            }
            None => {
                let bounds = simd::dispatch(
                    #[inline(always)]
                    || state.bounding_box(),
                );
                Region {
                    lo: bounds.lo.map(|x| x.as_f64()),
                    hi: bounds.hi.map(|x| x.as_f64()),
                    periodic: false,
                }
            }
        };
        let pos = build_positions(self.periodic.as_ref(), state, &mut self.at_build);
        self.layout.build(pos, &state.source, region, self.radius);
    }

    /// Brings the list up to date with `state`; returns the boxes compared by a rebuild, or
    /// `None` when the list was kept (the padded copy is refreshed either way).
    fn refresh(&mut self, state: &State<T, D>) -> Option<u64> {
        if self.handed_out {
            self.handed_out = false;
            if self.layout.adopt(state) {
                let pos = state.pos.each_ref().map(|x| x.as_slice());
                self.layout.refresh(pos, &state.source);
            } else {
                self.build_layout(state);
            }
            return Some(self.rebuild(state));
        }
        if self.due(state) {
            self.build_layout(state);
            return Some(self.rebuild(state));
        }
        let pos = match self.periodic {
            Some(_) => self.continued.each_ref().map(|x| x.as_slice()),
            None => state.pos.each_ref().map(|x| x.as_slice()),
        };
        self.layout.refresh(pos, &state.source);
        None
    }

    /// Builds the list over the current layout, in parts on the pool's threads, and takes
    /// the positions of the build.
    fn rebuild(&mut self, state: &State<T, D>) -> u64 {
        let m = self.layout.filled();
        // The previous list's size tells the new one's; before the first build, a guess of
        // four runs per cluster.
        let runs = if self.built {
            self.runs()
        } else {
            4 * m as u64
        };
        let work = runs * run_cost(D) + state.len() as u64;
        // Never a function of the threads: the parts fix the order in which forces are added.
        let mut count = if work >= MIN_PARALLEL_PAIRS {
            (m / MIN_PART_CLUSTERS).clamp(1, PARTS)
        } else {
            1
        };
        let periodic = self.periodic.is_some();
        let layers = self.layout.layers();
        let by_layers = cut_at_layers::<D>(periodic);
        // A cluster's runs reach `reach` layers on (and, in the first layers, back across the
        // faces into the last ones), and a run's last clusters a little past its window: parts
        // of `reach + 1` layers keep the parts of a colour apart, and the last part, which
        // the first reaches into, gets `reach` layers more.
        let reach = (self.radius / self.layout.width[D.saturating_sub(2)]) as usize + 1;
        let extra = if periodic { reach } else { 0 };
        if by_layers {
            let most = layers.saturating_sub(extra) / (reach + 1);
            count = parts_at_layers(count.min(most), layers, periodic);
        }
        self.parts.resize_with(count, Part::default);
        let (layout, radius, radius2) = (&self.layout, self.radius, self.radius2);
        let images = self.periodic.as_ref();
        // Equal parts where the last is long enough (2 · reach layers) that the first's reach
        // back across the faces misses the part before it; else the last one longer.
        let spread = match layers / count.max(1) >= 2 * reach {
            true => layers,
            false => layers.saturating_sub(extra),
        };
        let cut = |k: usize| match (by_layers, k == count) {
            (true, false) => layout.layer_start(k * spread / count),
            (true, true) => layout.layer_start(layers),
            (false, _) => k * m / count,
        };
        let build = |(k, part): (usize, &mut Part)| {
            let range = cut(k)..cut(k + 1);
            list::build(layout, images, radius, radius2, range, part)
        };
        let compared = if count > 1 {
            self.parts.par_iter_mut().enumerate().map(build).sum()
        } else {
            build((0, &mut self.parts[0]))
        };
        let slots = |r: &std::ops::Range<usize>| r.start * CLUSTER..r.end * CLUSTER;
        self.colors = Colors::of_sets(
            self.parts
                .iter()
                .map(|p| [slots(&(p.clusters.start..p.end)), slots(&p.far)]),
        );
        match &self.periodic {
            Some(images) => images.wrap_all(state, &mut self.at_build),
            None => {
                for d in 0..D {
                    self.at_build[d].clear();
                    self.at_build[d].extend_from_slice(&state.pos[d]);
                }
            }
        }
        self.built = true;
        compared
    }

    /// The forces per padded slot, from every part on this thread; with `PROBE`, also the
    /// energy and the pairs inside the cutoff.
    fn serial<const PROBE: bool>(&mut self) -> TileSum {
        let slots = self.layout.clusters() * CLUSTER;
        let mut force = std::mem::replace(&mut self.force, std::array::from_fn(|_| Vec::new()));
        for f in force.iter_mut() {
            f.clear();
            f.resize(slots, T::zero());
        }
        let mut out = Out::whole(force.each_mut().map(|f| f.as_mut_slice()));
        let (law, clusters) = (&self.law, Clusters::of(&self.layout));
        let images = self.periodic.as_ref();
        for k in self.colors.order() {
            add_forces(law, &clusters, &self.parts[k], images, &mut out);
        }
        self.force = force;
        let mut sum = TileSum::default();
        if PROBE {
            // The energy in a second pass, whose forces are dropped: a probe step moves the
            // particles by the same forces as any other (the batched loop's, where it runs,
            // differ in the last bits from this one's). Probe steps are not timed: this loop is
            // compiled once, for the baseline instruction set.
            let mut scratch: [Vec<T>; D] = std::array::from_fn(|_| vec![T::zero(); slots]);
            let mut out = Out::whole(scratch.each_mut().map(|f| f.as_mut_slice()));
            for k in self.colors.order() {
                let s =
                    run_forces::<T, L, D, true>(law, &clusters, &self.parts[k], images, &mut out);
                sum.energy += s.energy;
                sum.interacting += s.interacting;
            }
        }
        sum
    }

    /// The forces per padded slot, one colour at a time, its parts on the pool's threads: the
    /// serial loop's additions in the serial loop's order.
    fn parallel(&mut self) {
        let slots = self.layout.clusters() * CLUSTER;
        for f in self.force.iter_mut() {
            f.clear();
            f.resize(slots, T::zero());
        }
        let (law, clusters) = (&self.law, Clusters::of(&self.layout));
        let images = self.periodic.as_ref();
        let out = SharedSlice::each(self.force.each_mut().map(|f| f.as_mut_slice()));
        for c in 0..2 {
            let parts: Vec<usize> = self.colors.of_color(c).collect();
            parts.par_iter().for_each(|&k| {
                // SAFETY: the parts of one colour touch disjoint slots (the caller checked
                // `colors.disjoint()`), and nothing else uses `out` until the colour is done.
                unsafe { add_part(law, &clusters, &self.parts[k], images, &out) }
            });
        }
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for ClusterPair<L, T, D> {
    fn kind(&self) -> KernelKind {
        KernelKind::ClusterPair
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        let n = state.len();
        if n == 0 {
            return ForceReport {
                energy: probe.then_some(0.0),
                ..Default::default()
            };
        }
        let clock = Instant::now();
        let compared = self.refresh(state);
        let build_s = clock.elapsed().as_secs_f64();
        let runs = self.runs();
        let parallel = !probe
            && self.parts.len() > 1
            && self.colors.disjoint()
            && rayon::current_num_threads() > 1;
        let sum = if parallel {
            self.parallel();
            TileSum::default()
        } else if probe {
            self.serial::<true>()
        } else {
            self.serial::<false>()
        };
        for d in 0..D {
            gather(&self.force[d], &self.layout.padded_of, &mut forces[d]);
        }
        ForceReport {
            energy: probe.then_some(sum.energy),
            build_s,
            work: WorkCounters {
                pair_checks: runs * run_cost(D) + compared.unwrap_or(0),
                pairs_interacting: sum.interacting,
                rebuilds: u64::from(compared.is_some()),
                list_entries: runs,
                ..Default::default()
            },
        }
    }

    /// The cluster order, exactly when the list is due for a rebuild; between rebuilds a new
    /// order would only force one.
    fn spatial_order(&mut self, state: &State<T, D>) -> Option<Vec<u32>> {
        if !self.due(state) && !self.handed_out {
            return None;
        }
        self.build_layout(state);
        self.handed_out = true;
        Some(self.layout.order.clone())
    }

    fn sort_every(&self) -> u64 {
        1
    }

    fn team_plan(&mut self, n: usize) -> Option<Box<dyn TeamPlan<T, D> + '_>> {
        if !self.built || self.handed_out || self.at_build[0].len() != n {
            return None;
        }
        let slots = self.layout.clusters() * CLUSTER;
        if self.layout.slot_of.len() != slots || self.layout.pos[0].len() != slots {
            return None;
        }
        for f in self.force.iter_mut() {
            f.resize(slots, T::zero());
        }
        let runs = self.runs();
        let layout = &mut self.layout;
        Some(Box::new(Plan {
            law: &self.law,
            parts: &self.parts,
            colors: &self.colors,
            images: self.periodic.as_ref(),
            at_build: self.at_build.each_ref().map(|x| x.as_slice()),
            skin: self.skin,
            runs,
            slot_of: &layout.slot_of,
            padded_of: &layout.padded_of,
            pos: SharedSlice::each(layout.pos.each_mut().map(|x| x.as_mut_slice())),
            src: SharedSlice::new(&mut layout.src),
            force: SharedSlice::each(self.force.each_mut().map(|f| f.as_mut_slice())),
        }))
    }

    /// Refused when a side is shorter than twice the cutoff plus the skin (a pair could then
    /// meet within the cutoff through two images).
    fn set_periodic(&mut self, lo: [T; D], hi: [T; D]) -> Result<(), KernelError> {
        let images = Images::new(lo, hi);
        let least = 2.0 * self.radius;
        if let Some(d) = (0..D).find(|&d| images.side64()[d] < least || images.side64()[d].is_nan())
        {
            return Err(KernelError::PeriodicBoxTooSmall(format!(
                "cluster-pair in a periodic box needs a side of at least twice the cutoff plus \
                 the skin ({least:.6}); side {d} is {:.6}: use more particles, a smaller skin, \
                 or naive",
                images.side64()[d]
            )));
        }
        self.periodic = Some(images);
        self.built = false;
        Ok(())
    }
}
