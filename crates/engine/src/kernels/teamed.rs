//! The pair work of a list kernel as a team of workers runs it inside one region per step
//! ([`crate::engine`]), and the order that makes its forces the same bits at any worker count.
//!
//! A list is cut into parts (ranges of rows) whose number depends on the list's size only,
//! never on the threads. Parts are coloured alternately; after a re-sort they are bands of
//! space, each touching its own rows and the edge of the next band, so two parts of one colour
//! touch disjoint places ([`Colors::disjoint`], checked at every build). The workers then add
//! each colour's parts straight into the forces, without buffers or a reduction: colour 0's
//! parts on every worker, a barrier, colour 1's. A place receives its contributions part by
//! part in one fixed order (the parts of colour 0 in order, then those of colour 1) however
//! many workers there are — and the kernel's own `compute`, serial or on the rayon pool, adds
//! them in the same order, so the step is bitwise the same on 1, 2 or 3 workers.

use super::WorkCounters;
use crate::par::team::{SharedSlice, Worker};
use crate::real::Real;
use std::ops::Range;

/// The parts of a list in their two colours.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Colors {
    parts: usize,
    /// Whether the parts of each colour touch disjoint places (else they run one at a time).
    disjoint: bool,
}

impl Colors {
    /// The colouring of parts whose touched places are `spans` (in part order).
    pub fn of(spans: impl Iterator<Item = Range<usize>>) -> Colors {
        Self::of_sets(spans.map(|s| [s]))
    }

    /// The colouring of parts each touching the places of `K` ranges (a list in a periodic box
    /// reaches across the faces to places far from its other ones).
    pub fn of_sets<const K: usize>(sets: impl Iterator<Item = [Range<usize>; K]>) -> Colors {
        let sets: Vec<[Range<usize>; K]> = sets.collect();
        let parts = sets.len();
        let meet = |a: &Range<usize>, b: &Range<usize>| {
            !a.is_empty() && !b.is_empty() && a.start < b.end && b.start < a.end
        };
        let apart =
            |p: usize, q: usize| sets[p].iter().all(|a| sets[q].iter().all(|b| !meet(a, b)));
        let disjoint = (0..parts).all(|p| (p + 2..parts).step_by(2).all(|q| apart(p, q)));
        Colors { parts, disjoint }
    }

    /// Number of parts, both colours together.
    pub fn parts(&self) -> usize {
        self.parts
    }

    /// Whether the parts of each colour touch disjoint places, so that a colour's parts can run at
    /// once.
    pub fn disjoint(&self) -> bool {
        self.disjoint
    }

    /// The parts of colour `c` (0 or 1), in order.
    pub fn of_color(&self, c: usize) -> impl Iterator<Item = usize> + Clone + use<> {
        (c..self.parts).step_by(2)
    }

    /// The `k`-th part of colour `c`, if the colour has that many.
    pub fn nth_of_color(&self, c: usize, k: usize) -> Option<usize> {
        let part = c + 2 * k;
        (part < self.parts).then_some(part)
    }

    /// Every part in the order their contributions are added: colour 0, then colour 1.
    pub fn order(&self) -> impl Iterator<Item = usize> + use<> {
        self.of_color(0).chain(self.of_color(1))
    }
}

/// Whether a half list in `D` dimensions is cut into parts at the layers of its grid across
/// the slowest axis: in 3-D and in a periodic box, where a row's pairs reach past the next
/// layers' start (its neighbours one row back there, or across the faces of the middle axis),
/// so parts cut anywhere else would need more layers each to keep parts two apart disjoint.
pub(crate) fn cut_at_layers<const D: usize>(periodic: bool) -> bool {
    D >= 2 && (D == 3 || periodic)
}

/// `count` parts cut at the `layers` layers of a grid: at most one per layer; in a periodic box,
/// whose first part reaches across the faces into the last layer, an even number (those two
/// parts of two colours), and a multiple of four from four on (two workers then share each
/// colour's parts evenly: six parts would leave one worker a part idle per colour). A
/// function of the grid only, never of the threads.
pub(crate) fn parts_at_layers(count: usize, layers: usize, periodic: bool) -> usize {
    let count = count.min(layers).max(1);
    match (periodic, count) {
        (false, _) | (true, 0..=1) => count,
        (true, 2..=3) => 2,
        (true, _) => count - count % 4,
    }
}

/// Read-only inputs of the pair work, valid between the barriers of a phase.
#[derive(Clone, Copy)]
pub struct StateView<'s, T, const D: usize> {
    /// Positions, one slice per coordinate, in slot order.
    pub pos: [&'s [T]; D],
    /// Source strengths, in slot order.
    pub source: &'s [T],
}

/// A kernel's step as the phases of a team region (see [`crate::engine`] for the region):
/// made by [`super::ForceKernel::team_plan`] when the kernel's structure exists, and used for
/// one step.
pub trait TeamPlan<T: Real, const D: usize>: Sync {
    /// Whether the structure still serves the slots `block`, whose positions are now `pos`
    /// (a worker's own block, right after its drift): the displacement test of a list.
    fn keeps(&self, pos: [&[T]; D], block: Range<usize>) -> bool;

    /// The parts of the pair work and their colours.
    fn colors(&self) -> &Colors;

    /// This worker's share of what precedes the pair work (zeroing the forces, copying
    /// positions into the kernel's own order), once every block kept the structure.
    ///
    /// # Safety
    /// Called once by every worker between the same two barriers, with `forces` not accessed
    /// otherwise in that phase; `state` is not written in it.
    unsafe fn prepare(
        &self,
        worker: &Worker,
        state: StateView<'_, T, D>,
        forces: &[SharedSlice<'_, T>; D],
    );

    /// Adds the forces of `part` (both ends of each pair).
    ///
    /// # Safety
    /// Between two barriers only parts of one colour run, each once, and only when
    /// [`Colors::disjoint`] holds or on one worker; nothing else touches `forces` then.
    unsafe fn interact(
        &self,
        part: usize,
        state: StateView<'_, T, D>,
        forces: &[SharedSlice<'_, T>; D],
    );

    /// This worker's share of what follows the pair work: its block of `forces` final.
    ///
    /// # Safety
    /// Called once by every worker between the same two barriers, after every part ran.
    unsafe fn finish(&self, worker: &Worker, forces: &[SharedSlice<'_, T>; D]);

    /// The work of one step on the kept structure.
    fn work(&self) -> WorkCounters;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_that_touch_their_neighbours_only_are_disjoint_per_colour() {
        let spans = [0..12, 10..25, 20..31, 30..40, 40..41];
        let c = Colors::of(spans.iter().cloned());
        assert_eq!(c.parts(), 5);
        assert!(c.disjoint());
        assert_eq!(c.order().collect::<Vec<_>>(), vec![0, 2, 4, 1, 3]);
        for colour in 0..2 {
            let nth: Vec<usize> = (0..5).map_while(|k| c.nth_of_color(colour, k)).collect();
            assert_eq!(nth, c.of_color(colour).collect::<Vec<_>>());
        }
    }

    #[test]
    fn a_part_reaching_past_its_neighbour_is_not_disjoint() {
        // Part 0 reaches into part 2's places; part 2 into part 4's.
        let c = Colors::of([0..21, 10..25, 20..31].into_iter());
        assert!(!c.disjoint());
        let c = Colors::of([0..50, 10..12, 20..22, 30..32, 40..42].into_iter());
        assert!(!c.disjoint());
        // Empty parts touch nothing.
        let c = Colors::of([0..10, 5..5, 10..20, 15..15].into_iter());
        assert!(c.disjoint());
    }

    #[test]
    fn periodic_parts_come_in_pairs_and_then_in_fours() {
        let periodic = |count| parts_at_layers(count, 40, true);
        let counts: Vec<usize> = (1..=9).map(periodic).collect();
        assert_eq!(counts, [1, 2, 2, 4, 4, 4, 4, 8, 8]);
        assert_eq!(parts_at_layers(16, 12, true), 12, "at most one per layer");
        assert_eq!(
            parts_at_layers(6, 40, false),
            6,
            "an open box takes the count"
        );
    }

    #[test]
    fn a_part_reaching_across_the_faces_meets_the_parts_of_its_colour_there() {
        // Four bands of 10 places; the first reaches into the last across the faces.
        let bands = |wrap: Range<usize>| {
            [
                [0..15, wrap],
                [10..25, 0..0],
                [20..35, 0..0],
                [30..40, 0..0],
            ]
            .into_iter()
        };
        // The last band is of the other colour: disjoint.
        assert!(Colors::of_sets(bands(35..40)).disjoint());
        // Reaching into the third band (the first's colour) is not.
        assert!(!Colors::of_sets(bands(30..40)).disjoint());
    }
}
