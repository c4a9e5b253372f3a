//! The cell list in a periodic box: every particle within the cutoff of a face is copied across
//! it (a *ghost*, shifted by one side along each axis it crosses: faces, edges and corners), so
//! that the open-space bins and force loop meet every pair through its nearest image, with no
//! rounding per pair. Only the sources grow, by the layer of width rc around the box; the
//! targets are the particles themselves, the first slots of the sources.

use crate::kernels::images::{Images, code_of};
use crate::real::Real;
use crate::state::State;

/// The periodic box and the sources of the last step: the particles wrapped into the box, then
/// their ghosts.
pub(super) struct Ghosts<T: Real, const D: usize> {
    images: Images<T, D>,
    /// How far from a face a particle is copied across it: the cutoff with the bins' margin
    /// (a copy a little beyond the cutoff costs one pair check; the law's cutoff decides).
    reach: f64,
    /// The sources (positions, strengths; masses only for their count).
    pub sources: State<T, D>,
}

impl<T: Real, const D: usize> Ghosts<T, D> {
    /// The box `[lo, hi)` for a cutoff `rc`, or its narrowest side when a side is not more than
    /// twice the reach: a pair could then meet through two images.
    pub fn new(lo: [T; D], hi: [T; D], rc: f64) -> Result<Self, (usize, f64)> {
        let images = Images::new(lo, hi);
        let reach = rc * (1.0 + super::grid::SIDE_MARGIN);
        if let Some(d) = (0..D).find(|&d| images.side64()[d] <= 2.0 * reach) {
            return Err((d, 2.0 * reach));
        }
        Ok(Ghosts {
            images,
            reach,
            sources: State {
                pos: std::array::from_fn(|_| Vec::new()),
                vel: std::array::from_fn(|_| Vec::new()),
                mass: Vec::new(),
                source: Vec::new(),
                id: Vec::new(),
            },
        })
    }

    /// Rebuilds the sources from `state`: its particles wrapped into the box in its slots, then
    /// their ghosts. Buffers only grow.
    pub fn fill(&mut self, state: &State<T, D>) {
        let (images, out) = (&self.images, &mut self.sources);
        let n = state.len();
        for d in 0..D {
            out.pos[d].clear();
            out.pos[d].extend(state.pos[d][..n].iter().map(|&x| images.wrapped(x, d)));
        }
        out.source.clear();
        out.source.extend_from_slice(&state.source[..n]);
        let (lo, side) = (images.lo64(), images.side64());
        for i in 0..n {
            // Per axis: within reach of the low face (copied one side up), of the high face
            // (copied one side down).
            let mut near = [[false; 2]; D];
            let mut any = false;
            for d in 0..D {
                let u = out.pos[d][i].as_f64() - lo[d];
                near[d] = [u < self.reach, side[d] - u <= self.reach];
                any |= near[d][0] | near[d][1];
            }
            if !any {
                continue;
            }
            // Every non-empty combination of the axes' crossings: 0 none, 1 up, 2 down.
            for combination in 1..3usize.pow(D as u32) {
                let mut wraps = [0i8; D];
                let mut c = combination;
                let mut reached = true;
                for d in 0..D {
                    match c % 3 {
                        0 => {}
                        1 => (wraps[d], reached) = (1, reached & near[d][0]),
                        _ => (wraps[d], reached) = (-1, reached & near[d][1]),
                    }
                    c /= 3;
                }
                if !reached {
                    continue;
                }
                let shift = images.shift_of(code_of(wraps));
                for d in 0..D {
                    let x = out.pos[d][i] + shift[d];
                    out.pos[d].push(x);
                }
                out.source.push(out.source[i]);
            }
        }
        out.mass.resize(out.pos[0].len(), T::one());
    }
}
