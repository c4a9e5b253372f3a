//! The periodic box of a neighbour list: which image of its partner each entry meets, and the
//! positions the force loop reads.
//!
//! The search finds a pair through a bin on the far side of a face and records, with the
//! entry, which image of the partner it met (a shift of −1, 0 or +1 box side per axis, two bits
//! each). The force loop adds that shift to the partner's position: no rounding per pair.
//!
//! The integrator wraps a particle that leaves the box to the opposite face, a jump of one side
//! that would both fail the displacement test and put the pair's recorded shift one side off.
//! So the list does not read the wrapped positions: it reads each slot's position *continued*
//! from its place at the build, the wrapped one moved back by whole sides until it is nearest
//! that place. A slot that did not wrap is read exactly as it is.

use crate::kernels::rows::LANES;
use crate::real::{Real, select};
use crate::state::State;
use rayon::prelude::*;
use std::ops::Range;

/// The periodic box `[lo, lo + side)`, in `T` for the force loop and in f64 for the search.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Images<T, const D: usize> {
    lo: [T; D],
    side: [T; D],
    inverse: [T; D],
    /// The sides in `T` widened to f64: the shifts of the search are those of the force loop.
    side64: [f64; D],
}

/// The code of an entry without a shift (every axis's two bits at 1).
pub(crate) fn no_shift<const D: usize>() -> u8 {
    (0..D).map(|d| 1u8 << (2 * d)).sum()
}

/// The code of the shifts `wraps` (each −1, 0 or +1 side).
pub(crate) fn code_of<const D: usize>(wraps: [i8; D]) -> u8 {
    (0..D).map(|d| ((wraps[d] + 1) as u8) << (2 * d)).sum()
}

/// Whether an entry of code `code` meets its partner across the faces of the slowest axis (the
/// last one): the only entries whose partner is far from its target in bin order.
pub(crate) fn crosses_slowest_axis<const D: usize>(code: u8) -> bool {
    (code >> (2 * (D - 1))) & 3 != 1
}

impl<T: Real, const D: usize> Images<T, D> {
    /// The box `[lo, hi)`.
    pub fn new(lo: [T; D], hi: [T; D]) -> Self {
        let side: [T; D] = std::array::from_fn(|d| hi[d] - lo[d]);
        Images {
            lo,
            side,
            inverse: side.map(|s| T::one() / s),
            side64: side.map(|s| s.as_f64()),
        }
    }

    pub fn lo64(&self) -> [f64; D] {
        self.lo.map(|x| x.as_f64())
    }

    pub fn side64(&self) -> [f64; D] {
        self.side64
    }

    /// The shift of the wraps `wraps`, in f64 (the search's).
    pub fn shift64(&self, wraps: [i8; D]) -> [f64; D] {
        std::array::from_fn(|d| f64::from(wraps[d]) * self.side64[d])
    }

    /// The shifts of a block of entries' codes, lane by lane: selects, which vectorize.
    #[inline(always)]
    pub fn shifts(&self, codes: &[u8; LANES]) -> [[T; LANES]; D] {
        let mut s = [[T::zero(); LANES]; D];
        for d in 0..D {
            let (minus, plus) = (-self.side[d], self.side[d]);
            for l in 0..LANES {
                let bits = (codes[l] >> (2 * d)) & 3;
                s[d][l] = select(bits == 0, minus, select(bits == 2, plus, T::zero()));
            }
        }
        s
    }

    /// The shift of the code `code`.
    #[inline(always)]
    pub fn shift_of(&self, code: u8) -> [T; D] {
        std::array::from_fn(|d| match (code >> (2 * d)) & 3 {
            0 => -self.side[d],
            2 => self.side[d],
            _ => T::zero(),
        })
    }

    /// `x` (on axis `d`) moved by whole sides into the box: itself when inside.
    #[inline(always)]
    pub fn wrapped(&self, x: T, d: usize) -> T {
        x - self.side[d] * ((x - self.lo[d]) * self.inverse[d]).floor()
    }

    /// `x` (on axis `d`) moved by whole sides to the image nearest `then`: itself when it is
    /// nearest already. (Rounded as `⌊v + ½⌋`, one vector instruction, where `round` is a call
    /// per element; they differ only at exactly half a side, far beyond any list's skin.)
    #[inline(always)]
    pub fn continued(&self, x: T, then: T, d: usize) -> T {
        x + self.side[d] * ((then - x) * self.inverse[d] + T::of(0.5)).floor()
    }

    /// Writes every slot's position wrapped into the box into `out` (the positions of a build).
    pub fn wrap_all(&self, state: &State<T, D>, out: &mut [Vec<T>; D]) {
        for d in 0..D {
            out[d].clear();
            out[d].extend(state.pos[d].iter().map(|&x| self.wrapped(x, d)));
        }
    }

    /// Whether every slot of `block` (now at `pos`, the block's positions) continued from its
    /// place in `at_build` (all slots) lies within half the skin of it, in f64; with `out`
    /// (the block's slots), the continued positions are written there.
    #[inline(always)]
    pub fn block_kept(
        &self,
        pos: [&[T]; D],
        at_build: [&[T]; D],
        block: Range<usize>,
        skin: f64,
        mut out: Option<[&mut [T]; D]>,
    ) -> bool {
        let limit = 0.25 * skin * skin;
        let then: [&[T]; D] = at_build.map(|x| &x[block.clone()]);
        let mut far = false;
        for i in 0..block.len() {
            let mut d2 = 0.0;
            for d in 0..D {
                let u = self.continued(pos[d][i], then[d][i], d);
                let dx = u.as_f64() - then[d][i].as_f64();
                d2 += dx * dx;
                if let Some(out) = out.as_mut() {
                    out[d][i] = u;
                }
            }
            far |= d2 > limit || d2.is_nan();
        }
        !far
    }

    /// Continues every slot of `state` from `at_build` into `out`, on the pool's threads when
    /// the slots are many; whether some slot moved more than half the skin (or the slots
    /// changed in number).
    pub fn continue_all(
        &self,
        state: &State<T, D>,
        at_build: &[Vec<T>; D],
        skin: f64,
        out: &mut [Vec<T>; D],
    ) -> bool {
        let n = state.len();
        if at_build[0].len() != n {
            return true;
        }
        for o in out.iter_mut() {
            o.resize(n, T::zero());
        }
        let then = at_build.each_ref().map(|x| x.as_slice());
        let chunk = crate::par::pass_chunk(n).max(1);
        let chunks = crate::par::chunks_of(out.each_mut().map(|o| o.as_mut_slice()), chunk);
        let pass = |(k, out): (usize, [&mut [T]; D])| {
            let block = k * chunk..k * chunk + out[0].len();
            let now: [&[T]; D] = std::array::from_fn(|d| &state.pos[d][block.clone()]);
            crate::simd::dispatch(
                #[inline(always)]
                || self.block_kept(now, then, block.clone(), skin, Some(out)),
            )
        };
        let kept = if crate::par::worth_forking(n * D) {
            chunks
                .into_par_iter()
                .enumerate()
                .map(pass)
                .reduce(|| true, |a, b| a && b)
        } else {
            chunks
                .into_iter()
                .enumerate()
                .map(pass)
                .filter(|&kept| !kept)
                .count()
                == 0
        };
        // Every chunk ran (no early exit): each writes its continued positions.
        !kept
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_say_which_image_and_which_cross_the_slowest_axis() {
        let images = Images::<f64, 3>::new([0.0; 3], [10.0, 20.0, 40.0]);
        let code = code_of([-1, 0, 1]);
        let mut block = [no_shift::<3>(); LANES];
        block[1] = code;
        let s = images.shifts(&block);
        assert_eq!((s[0][0], s[1][0], s[2][0]), (0.0, 0.0, 0.0));
        assert_eq!((s[0][1], s[1][1], s[2][1]), (-10.0, 0.0, 40.0));
        assert_eq!(images.shift64([-1, 0, 1]), [-10.0, 0.0, 40.0]);
        assert_eq!(images.shift_of(code), [-10.0, 0.0, 40.0]);
        assert_eq!(images.shift_of(no_shift::<3>()), [0.0; 3]);
        assert!(crosses_slowest_axis::<3>(code));
        assert!(!crosses_slowest_axis::<3>(code_of([1, -1, 0])));
        assert!(crosses_slowest_axis::<2>(code_of([0, -1])));
    }

    #[test]
    fn a_wrapped_slot_is_continued_from_its_build_and_an_unwrapped_one_is_read_as_it_is() {
        let images = Images::<f32, 1>::new([0.0], [10.0]);
        assert_eq!(images.wrapped(10.25, 0), 0.25);
        assert_eq!(images.wrapped(-0.5, 0), 9.5);
        assert_eq!(images.wrapped(3.3, 0), 3.3);
        // Built at 9.9, now wrapped to 0.05: continued to 10.05, 0.15 away.
        let mut out = [vec![0.0f32; 2]];
        let pos: [&[f32]; 1] = [&[0.05, 4.7]];
        let then: [&[f32]; 1] = [&[9.9, 4.6]];
        let [o] = &mut out;
        assert!(images.block_kept(pos, then, 0..2, 0.4, Some([o.as_mut_slice()])));
        assert!((out[0][0] - 10.05).abs() < 1e-5);
        assert_eq!(out[0][1], 4.7);
        // 0.25 away is more than half of a skin of 0.4.
        assert!(!images.block_kept([&[0.15, 4.7]], then, 0..2, 0.4, None));
    }
}
