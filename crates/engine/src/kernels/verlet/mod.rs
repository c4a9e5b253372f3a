//! `verlet`: a neighbour list of the pairs within the cutoff plus a skin, built from cell-list
//! bins and kept for as long as no particle has moved more than half the skin since the build.
//! Two particles then moved together at most the skin, so every pair now inside the cutoff was
//! within the cutoff plus the skin at the build and is in the list: the forces are exact at
//! every step, not approximately so.
//!
//! - The list is a half list (each pair once) evaluated with Newton's third law, its forces
//!   added straight into the output. A long list is cut into parts (bands of rows, as many
//!   whatever the threads) of two colours whose pairs touch disjoint slots
//!   ([`crate::kernels::teamed`]): the threads run one colour's parts at a time, and every
//!   thread count adds the same contributions in the same order. Measured against a full list
//!   (every pair from both ends, gathered without reactions) at 2 threads, n = 1e5, mean step
//!   of `run` on the 2-vCPU AMD EPYC under load: 20–26 against 54–64 ns per particle-step on
//!   the gas, 79–124 against 139–220 on the liquid; the full list pays twice the entries in
//!   every step and rebuild.
//! - At a rebuild the particles are re-sorted by bin: [`ForceKernel::sort_every`] is 1, and
//!   [`ForceKernel::spatial_order`] answers with the bin order exactly when a rebuild is due,
//!   so the engine permutes the state right before the list is rebuilt (and the bins of that
//!   sort are reused rather than sorted again).
//! - The test that keeps the list is made on slots, not particle ids: each slot's position is
//!   compared with the position the slot had at the build. Whatever moved a particle into a
//!   slot (a re-ordering the kernel did not ask for, an MPI driver that replaced particles),
//!   the list stays right as long as every slot is within half the skin of where it was.
//! - [`ForceKernel::compute_targets`] keeps a full list of the targets' partners instead (the
//!   replicated-data MPI driver computes a block of targets every step).
//! - In a periodic box ([`ForceKernel::set_periodic`]) the bins tile the box, the search meets
//!   the bins beyond the faces as images, and the loops read positions continued from the
//!   build rather than wrapped ([`images`]).
//!
//! Memory, kept between rebuilds: the positions at the build and a sorted copy (2·D values per
//! particle), the bins and the sort (at most 4 bins and 4 values of 4 bytes per particle), and
//! 8 bytes per list entry (partner and target slots).

mod bins;
mod list;
mod loops;
#[cfg(test)]
mod periodic_tests;
mod search_periodic;
#[cfg(test)]
mod tests;
mod work;

use super::teamed::{Colors, StateView, TeamPlan, cut_at_layers, parts_at_layers};
use super::{ForceKernel, ForceReport, KernelError, KernelKind, WorkCounters};
use crate::kernels::cell_list::grid::{Grid, PERIODIC_MIN_BINS};
use crate::kernels::images::Images;
use crate::par::team::{SharedSlice, Worker, shared};
use crate::par::{pass_chunk, worth_forking};
use crate::physics::PairLaw;
use crate::real::Real;
use crate::simd;
use crate::state::{Field, State};
use bins::Bins;
use list::{BuildWork, Cover, Part};
use loops::{Slots, Split, Window};
use rayon::prelude::*;
use std::ops::Range;
use std::time::Instant;
pub use work::{parts_for, step_work};

/// Relative margin of the list radius: pair distances are rounded in `T` at every step and
/// computed in f64 at the build; a pair that `T` rounding puts just inside the cutoff must
/// still be in the list (f32 rounds `r²` by a few parts in 1e7).
const LIST_MARGIN: f64 = 1e-5;

/// The `verlet` kernel for the short-range law `L`: a half neighbour list within the cutoff plus a
/// skin.
pub struct Verlet<L, T, const D: usize> {
    law: L,
    skin: f64,
    /// The cutoff plus the skin, and its square with the margin (the test of the build).
    radius: f64,
    radius2: f64,
    bins: Bins<T, D>,
    parts: Vec<Part>,
    /// What the list holds; `None` before the first build.
    cover: Option<Cover>,
    /// Each slot's position at the last build.
    at_build: [Vec<T>; D],
    /// `spatial_order` handed out the order of `bins`: the next build starts from it.
    handed_out: bool,
    /// The colours of the half list's parts.
    colors: Colors,
    /// The periodic box, if any.
    periodic: Option<Images<T, D>>,
    /// In a periodic box: each slot's position continued from its place at the build (the
    /// positions the loops read), or scratch for the wrapped positions of a sort.
    continued: [Vec<T>; D],
}

impl<L: PairLaw<T>, T: Real, const D: usize> Verlet<L, T, D> {
    /// The kernel for `law` with list skin `skin` (length units); refused without a finite cutoff
    /// or a positive skin.
    pub fn new(law: L, skin: f64) -> Result<Self, KernelError> {
        let rc = list_cutoff::<T, L, D>(&law, skin, "the Verlet list")?;
        let radius = rc + skin;
        Ok(Verlet {
            law,
            skin,
            radius,
            radius2: radius * radius * (1.0 + LIST_MARGIN),
            bins: Bins::new(),
            parts: Vec::new(),
            cover: None,
            at_build: std::array::from_fn(|_| Vec::new()),
            handed_out: false,
            colors: Colors::default(),
            periodic: None,
            continued: std::array::from_fn(|_| Vec::new()),
        })
    }

    /// Sorts `state` into bins and builds its half list without computing any force: the
    /// build alone, for benchmarks.
    pub fn build(&mut self, state: &State<T, D>) {
        self.handed_out = false;
        self.rebuild(state, Cover::Half);
    }

    /// Entries of the current list.
    pub fn entries(&self) -> u64 {
        self.parts.iter().map(|p| p.entries() as u64).sum()
    }

    /// Makes the list hold `cover` for `state`, rebuilding it when it holds something else,
    /// was handed out for a re-ordering, or some slot moved too far; returns the build's work.
    fn refresh(&mut self, state: &State<T, D>, cover: Cover) -> BuildWork {
        let kept =
            self.cover.as_ref() == Some(&cover) && !self.handed_out && !self.moved_too_far(state);
        if kept {
            return BuildWork::default();
        }
        self.rebuild(state, cover)
    }

    /// Whether some slot moved more than half the skin since the build; in a periodic box,
    /// the slots' continued positions are left in `continued`.
    fn moved_too_far(&mut self, state: &State<T, D>) -> bool {
        match &self.periodic {
            Some(images) => {
                images.continue_all(state, &self.at_build, self.skin, &mut self.continued)
            }
            None => moved_too_far(state, &self.at_build, self.skin),
        }
    }

    /// Sorts the bins from `state`: in a periodic box, from its positions wrapped into `into`.
    fn sort_bins(&mut self, state: &State<T, D>, wrapped_into_build: bool) {
        let side = self.radius * (1.0 + LIST_MARGIN);
        let Some(images) = &self.periodic else {
            return self.bins.sort(state, side);
        };
        let into = if wrapped_into_build {
            &mut self.at_build
        } else {
            &mut self.continued
        };
        images.wrap_all(state, into);
        self.bins
            .sort_periodic(into.each_ref().map(|x| x.as_slice()), images, side);
    }

    fn rebuild(&mut self, state: &State<T, D>, cover: Cover) -> BuildWork {
        let n = state.len();
        if let Some(images) = &self.periodic {
            images.wrap_all(state, &mut self.at_build);
        }
        if !(self.handed_out && self.bins.adopt(state)) {
            self.sort_bins(state, true);
        }
        self.handed_out = false;
        let rows = match &cover {
            Cover::Half => n,
            Cover::Targets(t) => t.len(),
        };
        // The previous list's size tells the new one's; before the first build, the bins do.
        let entries = if self.cover.as_ref() == Some(&cover) && self.at_build[0].len() == n {
            self.entries()
        } else {
            work::expected_entries(&self.bins, &cover)
        };
        let mut count = parts_for(rows, step_work(rows, entries));
        let periodic = self.periodic.is_some();
        let layers = self.bins.grid.dims[D - 1];
        let by_layers = cover == Cover::Half && cut_at_layers::<D>(periodic);
        if by_layers {
            count = parts_at_layers(count, layers, periodic);
        }
        self.parts.resize_with(count, Part::default);
        let (bins, radius2, images) = (&self.bins, self.radius2, self.periodic.as_ref());
        let slots: [&[T]; D] = match images {
            Some(_) => self.at_build.each_ref().map(|x| x.as_slice()),
            None => state.pos.each_ref().map(|x| x.as_slice()),
        };
        let cut = |k: usize| match by_layers {
            true => work::layer_start(bins, k * layers / count),
            false => k * rows / count,
        };
        let build = |(k, part): (usize, &mut Part)| {
            let range = cut(k)..cut(k + 1);
            simd::dispatch(
                #[inline(always)]
                || match images {
                    Some(images) => {
                        search_periodic::build(bins, images, slots, &cover, radius2, range, part)
                    }
                    None => list::build(bins, slots, &cover, radius2, range, part),
                },
            )
        };
        let mut work = if count > 1 {
            self.parts.par_iter_mut().enumerate().map(build).reduce(
                BuildWork::default,
                |mut a, b| {
                    a += b;
                    a
                },
            )
        } else {
            build((0, &mut self.parts[0]))
        };
        work.rebuilds = 1;
        self.colors = Colors::of_sets(self.parts.iter().map(|p| [p.span.clone(), p.wrap.clone()]));
        for d in 0..D {
            if self.periodic.is_some() {
                self.continued[d].clone_from(&self.at_build[d]);
            } else {
                self.at_build[d].clear();
                self.at_build[d].extend_from_slice(&state.pos[d]);
            }
        }
        self.cover = Some(cover);
        work
    }

    /// The positions the loops read: the slots' own, or in a periodic box their continued
    /// ones.
    fn slots<'s>(&'s self, state: &'s State<T, D>) -> Slots<'s, T, D> {
        match self.periodic {
            Some(_) => Slots::new(
                self.continued.each_ref().map(|x| x.as_slice()),
                &state.source,
            ),
            None => Slots::of(state),
        }
    }

    /// Adds the forces of the half list to `forces` (zeroed), on one thread, part by part in
    /// the colours' order.
    fn serial<const PROBE: bool>(
        &self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
    ) -> (f64, u64) {
        let (law, slots) = (&self.law, self.slots(state));
        let mut out = Window {
            out: forces.each_mut().map(|f| f.as_mut_slice()),
            base: 0,
        };
        let (mut energy, mut interacting) = (0.0, 0);
        for k in self.colors.order() {
            let part = &self.parts[k];
            let sum = match &self.periodic {
                Some(images) => simd::dispatch(
                    #[inline(always)]
                    || {
                        loops::half_pairs::<T, L, D, PROBE>(
                            law,
                            &slots,
                            part,
                            &mut out,
                            Some(images),
                        )
                    },
                ),
                None => simd::dispatch(
                    #[inline(always)]
                    || loops::half_pairs::<T, L, D, PROBE>(law, &slots, part, &mut out, None),
                ),
            };
            energy += sum.energy.as_f64();
            interacting += sum.interacting;
        }
        (energy, interacting)
    }

    /// Adds the forces of the half list to `forces` (zeroed), one colour at a time, its parts
    /// on the pool's threads: the serial loop's additions in the serial loop's order.
    fn parallel(&mut self, state: &State<T, D>, forces: &mut Field<T, D>) {
        let plan = self.plan(false);
        let view = StateView {
            pos: state.pos.each_ref().map(|x| x.as_slice()),
            source: &state.source,
        };
        let out = SharedSlice::each(forces.each_mut().map(|f| f.as_mut_slice()));
        for c in 0..2 {
            let parts: Vec<usize> = plan.colors.of_color(c).collect();
            parts.par_iter().for_each(|&k| {
                // SAFETY: the parts of one colour touch disjoint slots (the caller checked
                // `colors.disjoint()`), and nothing else uses `out` until the colour is done.
                unsafe { plan.interact(k, view, &out) }
            });
        }
    }

    /// The plan of a step on the list; on a team (`team`), in a periodic box, the workers
    /// write the continued positions of their blocks first.
    fn plan(&mut self, team: bool) -> Plan<'_, L, T, D> {
        let entries = self.entries();
        let Verlet {
            law,
            parts,
            colors,
            at_build,
            skin,
            periodic,
            continued,
            ..
        } = self;
        Plan {
            law,
            parts,
            colors,
            at_build: at_build.each_ref().map(|x| x.as_slice()),
            skin: *skin,
            entries,
            periodic: periodic.map(|images| Periodic {
                images,
                continued: SharedSlice::each(continued.each_mut().map(|c| c.as_mut_slice())),
                write: team,
            }),
        }
    }
}

/// A plan's periodic box: the positions its loops read, continued from the build.
struct Periodic<'k, T, const D: usize> {
    images: Images<T, D>,
    continued: [SharedSlice<'k, T>; D],
    /// Whether each worker writes its block of `continued` in `prepare` (the team's step) or
    /// `continued` is written already (the kernel's own `compute`).
    write: bool,
}

/// The half list's step in a team region: the displacement test on each worker's block, the
/// forces zeroed by blocks, the parts colour by colour.
struct Plan<'k, L, T, const D: usize> {
    law: &'k L,
    parts: &'k [Part],
    colors: &'k Colors,
    at_build: [&'k [T]; D],
    skin: f64,
    entries: u64,
    periodic: Option<Periodic<'k, T, D>>,
}

impl<T: Real, L: PairLaw<T>, const D: usize> TeamPlan<T, D> for Plan<'_, L, T, D> {
    fn keeps(&self, pos: [&[T]; D], block: Range<usize>) -> bool {
        let images = self.periodic.as_ref().map(|p| &p.images);
        block_kept_in(images, pos, self.at_build, block, self.skin)
    }

    fn colors(&self) -> &Colors {
        self.colors
    }

    unsafe fn prepare(
        &self,
        worker: &Worker,
        state: StateView<'_, T, D>,
        forces: &[SharedSlice<'_, T>; D],
    ) {
        let block = worker.block(forces[0].len());
        // SAFETY: each worker zeroes its own block (the caller's promise on `forces`).
        let out = unsafe { shared::ranges_mut(forces, block.clone()) };
        for f in out {
            f.fill(T::zero());
        }
        if let Some(p) = self.periodic.as_ref().filter(|p| p.write) {
            // SAFETY: each worker writes its own block, and nothing reads `continued` before
            // the barrier that ends this phase.
            let out = unsafe { shared::ranges_mut(&p.continued, block.clone()) };
            let now = state.pos.map(|x| &x[block.clone()]);
            let (at_build, skin) = (self.at_build, self.skin);
            simd::dispatch(
                #[inline(always)]
                || {
                    p.images
                        .block_kept(now, at_build, block.clone(), skin, Some(out))
                },
            );
        }
    }

    unsafe fn interact(
        &self,
        part: usize,
        state: StateView<'_, T, D>,
        forces: &[SharedSlice<'_, T>; D],
    ) {
        let part = &self.parts[part];
        let window = |range: Range<usize>| Window {
            // SAFETY: no other part running now touches the part's span or wrap (the
            // caller's promise), each of which is one window.
            out: unsafe { shared::ranges_mut(forces, range.clone()) },
            base: range.start,
        };
        let Some(p) = &self.periodic else {
            let slots = Slots::new(state.pos, state.source);
            let mut out = window(part.span.clone());
            simd::dispatch(
                #[inline(always)]
                || loops::half_pairs::<T, L, D, false>(self.law, &slots, part, &mut out, None),
            );
            return;
        };
        // SAFETY: `continued` is written before the pair work only (by `prepare` or before the
        // plan was made).
        let slots = Slots::new(unsafe { shared::wholes(&p.continued) }, state.source);
        let images = Some(&p.images);
        let (span, wrap) = (part.span.clone(), part.wrap.clone());
        let apart = !wrap.is_empty() && (wrap.start >= span.end || span.start >= wrap.end);
        if apart {
            let (low, high) = if wrap.start >= span.end {
                (span, wrap)
            } else {
                (wrap, span)
            };
            let mut out = Split {
                low: window(low),
                high: window(high),
            };
            simd::dispatch(
                #[inline(always)]
                || loops::half_pairs::<T, L, D, false>(self.law, &slots, part, &mut out, images),
            );
        } else {
            let whole = if wrap.is_empty() {
                span
            } else {
                span.start.min(wrap.start)..span.end.max(wrap.end)
            };
            let mut out = window(whole);
            simd::dispatch(
                #[inline(always)]
                || loops::half_pairs::<T, L, D, false>(self.law, &slots, part, &mut out, images),
            );
        }
    }

    unsafe fn finish(&self, _worker: &Worker, _forces: &[SharedSlice<'_, T>; D]) {}

    fn work(&self) -> WorkCounters {
        report(0.0, BuildWork::default(), self.entries, None, 0).work
    }
}

impl<T: Real, L: PairLaw<T>, const D: usize> ForceKernel<T, D> for Verlet<L, T, D> {
    fn kind(&self) -> KernelKind {
        KernelKind::Verlet
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
        let built = self.refresh(state, Cover::Half);
        let build_s = clock.elapsed().as_secs_f64();
        let mut energy = None;
        let mut interacting = 0;
        for f in forces.iter_mut() {
            f.fill(T::zero());
        }
        let split = self.colors.disjoint() && self.parts.len() > 1;
        if probe || !split || rayon::current_num_threads() < 2 {
            if probe {
                let (e, count) = self.serial::<true>(state, forces);
                (energy, interacting) = (Some(e), count);
            } else {
                self.serial::<false>(state, forces);
            }
        } else {
            self.parallel(state, forces);
        }
        report(build_s, built, self.entries(), energy, interacting)
    }

    /// A full list of the targets' partners, kept between calls like the half list.
    fn compute_targets(
        &mut self,
        state: &State<T, D>,
        targets: Range<usize>,
        out: [&mut [T]; D],
    ) -> ForceReport {
        if state.is_empty() || targets.is_empty() {
            return ForceReport::default();
        }
        let clock = Instant::now();
        let built = self.refresh(state, Cover::Targets(targets));
        let build_s = clock.elapsed().as_secs_f64();
        let (law, slots, images) = (&self.law, self.slots(state), self.periodic.as_ref());
        // Each part's rows, as its own slices of the output.
        let mut rest = out;
        let mut pieces = Vec::with_capacity(self.parts.len());
        for part in &self.parts {
            let mut cut = rest.map(|r| r.split_at_mut(part.rows.len()));
            let piece: [&mut [T]; D] = std::array::from_fn(|d| std::mem::take(&mut cut[d].0));
            rest = std::array::from_fn(|d| std::mem::take(&mut cut[d].1));
            pieces.push(piece);
        }
        let gather = |(part, piece): (&Part, &mut [&mut [T]; D])| {
            simd::dispatch(
                #[inline(always)]
                || loops::target_rows::<T, L, D>(law, &slots, part, piece, images),
            )
        };
        if self.parts.len() > 1 && rayon::current_num_threads() > 1 {
            self.parts
                .par_iter()
                .zip(pieces.par_iter_mut())
                .for_each(gather);
        } else {
            self.parts.iter().zip(pieces.iter_mut()).for_each(gather);
        }
        report(build_s, built, self.entries(), None, 0)
    }

    /// The bin order, exactly when the list is due for a rebuild; between rebuilds a new order
    /// would only force one.
    fn spatial_order(&mut self, state: &State<T, D>) -> Option<Vec<u32>> {
        if self.cover.is_some() && !self.handed_out && !self.moved_too_far(state) {
            return None;
        }
        // The list is rebuilt next: `continued` is free until then.
        self.sort_bins(state, false);
        self.handed_out = true;
        Some(self.bins.order.clone())
    }

    fn sort_every(&self) -> u64 {
        1
    }

    fn team_plan(&mut self, n: usize) -> Option<Box<dyn TeamPlan<T, D> + '_>> {
        let ready =
            self.cover == Some(Cover::Half) && !self.handed_out && self.at_build[0].len() == n;
        ready.then(|| Box::new(self.plan(true)) as Box<dyn TeamPlan<T, D> + '_>)
    }

    /// Refused when fewer than three bins of the cutoff plus the skin fit along a side (the
    /// search's images would repeat bins).
    fn set_periodic(&mut self, lo: [T; D], hi: [T; D]) -> Result<(), KernelError> {
        let images = Images::new(lo, hi);
        let side = self.radius * (1.0 + LIST_MARGIN);
        let fit = Grid::<D>::periodic_fit(images.side64(), side);
        if let Some(d) = (0..D).find(|&d| fit[d] < PERIODIC_MIN_BINS) {
            return Err(KernelError::PeriodicBoxTooSmall(format!(
                "verlet in a periodic box needs a side of at least {PERIODIC_MIN_BINS} times the \
                 cutoff plus the skin ({:.6}); side {d} is {:.6}: use more particles, a smaller \
                 skin, or naive",
                PERIODIC_MIN_BINS as f64 * side,
                images.side64()[d]
            )));
        }
        self.periodic = Some(images);
        self.cover = None;
        Ok(())
    }
}

/// The cutoff of `law` for a neighbour list (`what`) with this skin in `D` dimensions, or why
/// the combination has none.
pub(crate) fn list_cutoff<T: Real, L: PairLaw<T>, const D: usize>(
    law: &L,
    skin: f64,
    what: &str,
) -> Result<f64, KernelError> {
    let rc = match law.cutoff() {
        Some(rc) if rc.is_finite() && rc > T::zero() => rc.as_f64(),
        Some(rc) => {
            return Err(KernelError::BadParam(format!(
                "{what} needs a finite positive cutoff (got {rc})"
            )));
        }
        None => {
            return Err(KernelError::BadParam(format!(
                "{what} needs a law with a cutoff; {} has none",
                law.kind().name()
            )));
        }
    };
    if !(skin.is_finite() && skin > 0.0) {
        return Err(KernelError::BadParam(format!(
            "the skin of {what} must be a finite number > 0 (got {skin})"
        )));
    }
    if !(1..=3).contains(&D) {
        return Err(KernelError::BadParam(format!(
            "{what} works in 1 to 3 dimensions (got {D})"
        )));
    }
    Ok(rc)
}

/// Whether some slot of `state` is more than half the skin away from its position in
/// `at_build` (or the slots changed in number): the test that keeps a list. Computed in f64: a
/// particle that moved exactly half the skin keeps the list.
pub(crate) fn moved_too_far<T: Real, const D: usize>(
    state: &State<T, D>,
    at_build: &[Vec<T>; D],
    skin: f64,
) -> bool {
    let n = state.len();
    if at_build[0].len() != n {
        return true;
    }
    let at_build = at_build.each_ref().map(|x| x.as_slice());
    let part = |r: Range<usize>| {
        let now: [&[T]; D] = std::array::from_fn(|d| &state.pos[d][r.clone()]);
        !block_kept(now, at_build, r, skin)
    };
    if worth_forking(n * D) {
        let c = pass_chunk(n);
        (0..n.div_ceil(c))
            .into_par_iter()
            .any(|k| part(k * c..((k + 1) * c).min(n)))
    } else {
        part(0..n)
    }
}

/// Whether every slot of `block`, now at `pos` (the block's positions), is within half the
/// skin of its place in `at_build` (all slots), in f64: the displacement test of one block.
pub(crate) fn block_kept<T: Real, const D: usize>(
    pos: [&[T]; D],
    at_build: [&[T]; D],
    block: Range<usize>,
    skin: f64,
) -> bool {
    let then = at_build.map(|x| &x[block.clone()]);
    !simd::dispatch(
        #[inline(always)]
        || work::moved_beyond(pos, then, 0.25 * skin * skin),
    )
}

/// The displacement test of one block in an open box, or with `images` in a periodic one
/// (each slot continued from its place at the build).
pub(crate) fn block_kept_in<T: Real, const D: usize>(
    images: Option<&Images<T, D>>,
    pos: [&[T]; D],
    at_build: [&[T]; D],
    block: Range<usize>,
    skin: f64,
) -> bool {
    match images {
        Some(images) => simd::dispatch(
            #[inline(always)]
            || images.block_kept(pos, at_build, block.clone(), skin, None),
        ),
        None => block_kept(pos, at_build, block, skin),
    }
}

/// The report of one force computation: the list's entries are its pair checks, plus the
/// candidates of a rebuild.
fn report(
    build_s: f64,
    built: BuildWork,
    entries: u64,
    energy: Option<f64>,
    interacting: u64,
) -> ForceReport {
    ForceReport {
        energy,
        build_s,
        work: WorkCounters {
            pair_checks: entries + built.candidates,
            pairs_interacting: interacting,
            cells_visited: built.bins,
            rebuilds: built.rebuilds,
            list_entries: entries,
            ..Default::default()
        },
    }
}
