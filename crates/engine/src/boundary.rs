//! What happens at the edge of the simulated region.

use crate::geometry::Bounds;
use crate::par::{chunks_of, pass_chunk, worth_forking};
use crate::real::{Real, select};
use crate::simd;
use crate::state::State;
use rayon::prelude::*;
use thiserror::Error;

/// The boundary condition of a scenario.
#[derive(Clone, Copy, Debug)]
pub enum Boundary<T, const D: usize> {
    /// Elastic walls at `lo` and `hi` in every dimension.
    Reflecting {
        /// Lower wall on each axis.
        lo: [T; D],
        /// Upper wall on each axis.
        hi: [T; D],
    },
    /// Unbounded space: particles go anywhere; the bounding box is tracked each step.
    Open,
    /// Periodic in every dimension: the box `[lo, hi)` tiles space, so a particle that leaves
    /// through one face comes back through the opposite one with its velocity unchanged.
    Periodic {
        /// Lower face on each axis (inside the box).
        lo: [T; D],
        /// Upper face on each axis (outside: the image of `lo`).
        hi: [T; D],
    },
}

/// A particle the boundary phase cannot place, usually because the time step is too large.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum BoundaryError {
    /// A particle is still outside the walls after one reflection (it crossed more than the box in
    /// a step).
    #[error(
        "step {step}: particle {id} is still outside the box after one reflection \
         (coordinate {dim} = {value}); the time step is too large for these velocities — reduce --dt"
    )]
    MultipleReflection {
        /// The step being taken, counted from 1.
        step: u64,
        /// The particle's id.
        id: u32,
        /// The axis it is outside on.
        dim: usize,
        /// Its coordinate on that axis after the reflection.
        value: f64,
    },
    /// A particle is more than one box length outside a periodic box (it crossed more than the
    /// box in a step).
    #[error(
        "step {step}: particle {id} moved more than the periodic box's side in one step \
         (coordinate {dim} = {value}); the time step is too large for these velocities — reduce --dt"
    )]
    Overshot {
        /// The step being taken, counted from 1.
        step: u64,
        /// The particle's id.
        id: u32,
        /// The axis it is outside on.
        dim: usize,
        /// Its coordinate on that axis after one wrap.
        value: f64,
    },
    /// A particle's position is NaN or infinite.
    #[error(
        "step {step}: particle {id} has a non-finite position; the simulation blew up — \
         reduce --dt or check the initial state"
    )]
    NonFinite {
        /// The step being taken, counted from 1.
        step: u64,
        /// The particle's id.
        id: u32,
    },
}

impl<T: Real, const D: usize> Boundary<T, D> {
    /// Applies the boundary after a drift and returns the particles' bounding box. On the
    /// pool's threads when the particles are many; the result is the same at any thread count.
    pub fn apply(&self, state: &mut State<T, D>, step: u64) -> Result<Bounds<T, D>, BoundaryError> {
        let n = state.len();
        let c = if worth_forking(n * D) {
            pass_chunk(n)
        } else {
            n.max(1)
        };
        let pos = state.pos.each_mut().map(|x| &mut x[..n]);
        let vel = state.vel.each_mut().map(|v| &mut v[..n]);
        let (xs, vs) = (chunks_of(pos, c), chunks_of(vel, c));
        let pass = |(x, v)| self.apply_block(x, v);
        let found = if xs.len() > 1 {
            xs.into_par_iter()
                .zip(vs)
                .map(pass)
                .reduce(BlockCheck::empty, BlockCheck::join)
        } else {
            xs.into_iter()
                .zip(vs)
                .map(pass)
                .fold(BlockCheck::empty(), BlockCheck::join)
        };
        self.conclude(state, step, found)
    }

    /// The boundary on one block of particles (positions `x`, velocities `v`): what
    /// [`Boundary::conclude`] needs of it, joined over the blocks with [`BlockCheck::join`].
    pub(crate) fn apply_block(&self, x: [&mut [T]; D], v: [&mut [T]; D]) -> BlockCheck<T, D> {
        match *self {
            Boundary::Reflecting { lo, hi } => BlockCheck {
                outside: simd::dispatch(
                    #[inline(always)]
                    || reflect(x, v, lo, hi),
                ),
                extent: Extent::empty(),
            },
            Boundary::Periodic { lo, hi } => BlockCheck {
                outside: simd::dispatch(
                    #[inline(always)]
                    || wrap(x, lo, hi),
                ),
                extent: Extent::empty(),
            },
            Boundary::Open => BlockCheck {
                outside: [false; D],
                extent: simd::dispatch(
                    #[inline(always)]
                    || extent(x.each_ref().map(|x| &**x)),
                ),
            },
        }
    }

    /// The bounding box after the boundary, from what every block found, or the first
    /// particle at fault.
    pub(crate) fn conclude(
        &self,
        state: &State<T, D>,
        step: u64,
        found: BlockCheck<T, D>,
    ) -> Result<Bounds<T, D>, BoundaryError> {
        match *self {
            Boundary::Reflecting { lo, hi } => {
                if let Some(d) = (0..D).find(|&d| found.outside[d]) {
                    let (lo, hi) = (lo[d], hi[d]);
                    let e = first_offender(state, step, d, |x| !(x >= lo && x <= hi));
                    return Err(e);
                }
                Ok(Bounds { lo, hi })
            }
            Boundary::Periodic { lo, hi } => {
                if let Some(d) = (0..D).find(|&d| found.outside[d]) {
                    let (lo, hi) = (lo[d], hi[d]);
                    return Err(
                        match first_offender(state, step, d, |x| !(x >= lo && x < hi)) {
                            BoundaryError::MultipleReflection {
                                step,
                                id,
                                dim,
                                value,
                            } => BoundaryError::Overshot {
                                step,
                                id,
                                dim,
                                value,
                            },
                            e => e,
                        },
                    );
                }
                Ok(Bounds { lo, hi })
            }
            Boundary::Open => {
                // No particle, nothing to check (a rank of a distributed run may own none).
                if state.is_empty() {
                    return Ok(state.bounding_box());
                }
                let (Bounds { lo, hi }, poison) = found.extent;
                for d in 0..D {
                    if !(lo[d].is_finite() && hi[d].is_finite() && poison[d].is_finite()) {
                        return Err(first_offender(state, step, d, |x| !x.is_finite()));
                    }
                }
                Ok(Bounds { lo, hi })
            }
        }
    }
}

/// What the boundary found on some blocks of particles: per dimension whether a particle is
/// still outside a wall after one reflection, and (open space) their extent.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BlockCheck<T, const D: usize> {
    outside: [bool; D],
    extent: Extent<T, D>,
}

impl<T: Real, const D: usize> BlockCheck<T, D> {
    /// What no block found.
    pub fn empty() -> Self {
        BlockCheck {
            outside: [false; D],
            extent: Extent::empty(),
        }
    }

    /// What either found.
    pub fn join(a: Self, b: Self) -> Self {
        BlockCheck {
            outside: std::array::from_fn(|d| a.outside[d] | b.outside[d]),
            extent: Extent::join(a.extent, b.extent),
        }
    }

    /// Whether [`Boundary::conclude`] will name a particle at fault: one outside a wall, or a
    /// coordinate that is not finite.
    pub fn fails(&self) -> bool {
        self.outside.iter().any(|&o| o) || self.extent.1.iter().any(|p| !p.is_finite())
    }
}

/// Elastic walls for one chunk of particles; per dimension, whether a particle is still
/// outside after one reflection.
#[inline(always)]
fn reflect<T: Real, const D: usize>(
    x: [&mut [T]; D],
    v: [&mut [T]; D],
    lo: [T; D],
    hi: [T; D],
) -> [bool; D] {
    let mut bad = [false; D];
    for (d, (x, v)) in x.into_iter().zip(v).enumerate() {
        let (lo, hi) = (lo[d], hi[d]);
        let two = T::one() + T::one();
        for (x, v) in x.iter_mut().zip(v.iter_mut()) {
            // Written with selects, not branches: almost no particle is at a wall.
            let below = *x < lo;
            let above = *x > hi;
            let nx = select(below, two * lo - *x, select(above, two * hi - *x, *x));
            *v = select(below | above, -*v, *v);
            *x = nx;
            bad[d] |= !(nx >= lo && nx <= hi);
        }
    }
    bad
}

/// Periodic wrapping for one chunk of positions; per dimension, whether a particle is still
/// outside `[lo, hi)` after one wrap (it moved more than a box length, or is not finite).
#[inline(always)]
fn wrap<T: Real, const D: usize>(x: [&mut [T]; D], lo: [T; D], hi: [T; D]) -> [bool; D] {
    let mut bad = [false; D];
    for (d, x) in x.into_iter().enumerate() {
        let (lo, hi) = (lo[d], hi[d]);
        let side = hi - lo;
        for x in x.iter_mut() {
            // Selects, not branches: almost no particle crosses a face in a step.
            let below = *x < lo;
            let above = *x >= hi;
            let nx = select(below, *x + side, select(above, *x - side, *x));
            // A coordinate just below `lo` can round up to `hi` itself, which is `lo`'s image.
            let nx = select(nx == hi, lo, nx);
            *x = nx;
            bad[d] |= !(nx >= lo && nx < hi);
        }
    }
    bad
}

/// Bounding box and a finiteness probe (`Σ x·0`: NaN when some coordinate is NaN or ±∞) of a
/// chunk of positions. The box skips NaN, so the probe is what catches it.
type Extent<T, const D: usize> = (Bounds<T, D>, [T; D]);

trait Join: Sized {
    fn empty() -> Self;
    fn join(a: Self, b: Self) -> Self;
}

impl<T: Real, const D: usize> Join for Extent<T, D> {
    fn empty() -> Self {
        (Bounds::empty(), [T::zero(); D])
    }

    fn join(a: Self, b: Self) -> Self {
        (a.0.union(b.0), std::array::from_fn(|d| a.1[d] + b.1[d]))
    }
}

#[inline(always)]
fn extent<T: Real, const D: usize>(pos: [&[T]; D]) -> Extent<T, D> {
    let mut probe = [T::zero(); D];
    for (d, x) in pos.into_iter().enumerate() {
        for &x in x {
            probe[d] += x * T::zero();
        }
    }
    (Bounds::of_columns(pos), probe)
}

/// Names the first particle whose coordinate `d` fails `is_bad` (NaN is reported as non-finite).
fn first_offender<T: Real, const D: usize>(
    state: &State<T, D>,
    step: u64,
    d: usize,
    is_bad: impl Fn(T) -> bool,
) -> BoundaryError {
    let i = state.pos[d]
        .iter()
        .position(|&x| is_bad(x) || !x.is_finite())
        .unwrap_or(0);
    let x = state.pos[d][i];
    if x.is_finite() {
        BoundaryError::MultipleReflection {
            step,
            id: state.id[i],
            dim: d,
            value: x.as_f64(),
        }
    } else {
        BoundaryError::NonFinite {
            step,
            id: state.id[i],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn box2() -> Boundary<f64, 2> {
        Boundary::Reflecting {
            lo: [0.0, 0.0],
            hi: [1.0, 2.0],
        }
    }

    #[test]
    fn reflects_outside_particles_back_in() {
        let mut s = State::<f64, 2>::new(3);
        s.pos = [vec![-0.1, 1.05, 0.5], vec![0.5, 1.0, 2.3]];
        s.vel = [vec![-1.0, 2.0, 0.0], vec![0.5, 0.0, 3.0]];
        box2().apply(&mut s, 7).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        assert!(close(s.pos[0][0], 0.1) && s.vel[0][0] == 1.0 && s.vel[1][0] == 0.5);
        assert!(close(s.pos[0][1], 0.95) && s.vel[0][1] == -2.0);
        assert!(close(s.pos[1][2], 1.7) && s.vel[1][2] == -3.0);
        // Particles inside are untouched.
        assert_eq!((s.pos[1][0], s.pos[0][2]), (0.5, 0.5));
    }

    #[test]
    fn double_reflection_is_an_error_naming_step_and_particle() {
        let mut s = State::<f64, 2>::new(2);
        s.pos = [vec![0.5, 2.5], vec![0.5, 0.5]];
        s.id = vec![10, 11];
        let err = box2().apply(&mut s, 42).unwrap_err();
        assert_eq!(
            err,
            BoundaryError::MultipleReflection {
                step: 42,
                id: 11,
                dim: 0,
                value: -0.5
            }
        );
        assert!(err.to_string().contains("step 42") && err.to_string().contains("--dt"));
    }

    #[test]
    fn periodic_faces_wrap_positions_and_keep_velocities() {
        let b = Boundary::Periodic {
            lo: [0.0, -1.0],
            hi: [1.0, 1.0],
        };
        let mut s = State::<f64, 2>::new(4);
        s.pos = [vec![-0.25, 1.0, 0.5, 0.999], vec![0.0, 0.0, 1.5, -1.0]];
        s.vel = [vec![-1.0, 2.0, 0.0, 1.0], vec![0.5, 0.0, 3.0, -1.0]];
        let v = s.vel.clone();
        let bounds = b.apply(&mut s, 1).unwrap();
        assert_eq!(
            s.pos,
            [vec![0.75, 0.0, 0.5, 0.999], vec![0.0, 0.0, -0.5, -1.0]]
        );
        assert_eq!(s.vel, v);
        assert_eq!((bounds.lo, bounds.hi), ([0.0, -1.0], [1.0, 1.0]));
    }

    #[test]
    fn a_coordinate_that_rounds_onto_the_upper_face_is_its_image_at_the_lower() {
        let b = Boundary::Periodic {
            lo: [0.0f32],
            hi: [10.0],
        };
        let mut s = State::<f32, 1>::new(1);
        s.pos[0][0] = -1e-7;
        assert_eq!(-1e-7f32 + 10.0, 10.0);
        b.apply(&mut s, 1).unwrap();
        assert_eq!(s.pos[0][0], 0.0);
    }

    #[test]
    fn a_particle_past_a_whole_periodic_box_is_an_error_naming_it() {
        let b = Boundary::Periodic {
            lo: [0.0; 3],
            hi: [1.0; 3],
        };
        let mut s = State::<f64, 3>::new(2);
        s.pos[2][1] = 2.5;
        s.id = vec![4, 9];
        let err = b.apply(&mut s, 8).unwrap_err();
        assert_eq!(
            err,
            BoundaryError::Overshot {
                step: 8,
                id: 9,
                dim: 2,
                value: 1.5
            }
        );
        assert!(err.to_string().contains("--dt"));
        s.pos[2][1] = f64::NAN;
        assert_eq!(
            b.apply(&mut s, 9).unwrap_err(),
            BoundaryError::NonFinite { step: 9, id: 9 }
        );
    }

    #[test]
    fn non_finite_positions_are_reported() {
        let mut s = State::<f32, 3>::new(2);
        s.pos[2][1] = f32::NAN;
        let err = Boundary::<f32, 3>::Open.apply(&mut s, 3).unwrap_err();
        assert_eq!(err, BoundaryError::NonFinite { step: 3, id: 1 });
        let mut s = State::<f32, 2>::new(1);
        s.pos[0][0] = f32::INFINITY;
        let b = Boundary::<f32, 2>::Reflecting {
            lo: [0.0; 2],
            hi: [1.0; 2],
        };
        assert_eq!(
            b.apply(&mut s, 5).unwrap_err(),
            BoundaryError::NonFinite { step: 5, id: 0 }
        );
    }

    #[test]
    fn the_chunked_passes_give_the_serial_results() {
        let n = 60_000;
        let mut s = State::<f32, 3>::new(n);
        for i in 0..n {
            for d in 0..3 {
                s.pos[d][i] = ((i * (2 * d + 3)) % 1001) as f32 * 1e-3 - 0.01;
                s.vel[d][i] = (i % 7) as f32 - 3.0;
            }
        }
        s.pos[1][45_678] = 2.5;
        let walls = Boundary::Reflecting {
            lo: [0.0; 3],
            hi: [1.0; 3],
        };
        let pool = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
        };
        let serial = {
            let mut s = s.clone();
            let r = walls.apply(&mut s, 1);
            (r, s.pos, s.vel)
        };
        assert!(serial.0.is_err(), "the particle at y = 2.5 stays outside");
        for threads in [2, 3] {
            let mut t = s.clone();
            let r = pool(threads).install(|| walls.apply(&mut t, 1));
            assert_eq!((r, t.pos, t.vel), serial.clone(), "{threads} threads");
        }
        // Open space: the box, and the first non-finite particle named.
        let open = Boundary::<f32, 3>::Open;
        let expect = open.apply(&mut s.clone(), 2);
        s.pos[2][50_001] = f32::NAN;
        s.pos[2][59_999] = f32::INFINITY;
        for threads in [1, 2, 3] {
            let mut t = s.clone();
            let mut u = s.clone();
            u.pos[2][50_001] = 0.5;
            u.pos[2][59_999] = 0.5;
            let pool = pool(threads);
            assert_eq!(
                pool.install(|| open.apply(&mut t, 2)),
                Err(BoundaryError::NonFinite {
                    step: 2,
                    id: 50_001
                })
            );
            assert_eq!(pool.install(|| open.apply(&mut u, 2)), expect);
        }
    }

    #[test]
    fn open_boundary_reports_bounding_box() {
        let mut s = State::<f64, 2>::new(2);
        s.pos = [vec![-3.0, 4.0], vec![1.0, -2.0]];
        let Bounds { lo, hi } = Boundary::<f64, 2>::Open.apply(&mut s, 0).unwrap();
        assert_eq!((lo, hi), ([-3.0, -2.0], [4.0, 1.0]));
        // A rank of a distributed run may own no particle: nothing to report, no error.
        let mut none = State::<f64, 2>::new(0);
        assert!(Boundary::<f64, 2>::Open.apply(&mut none, 0).is_ok());
    }
}
