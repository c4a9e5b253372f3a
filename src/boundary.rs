//! What happens at the edge of the simulated region.

use crate::real::{Real, select};
use crate::state::State;
use thiserror::Error;

/// The boundary condition of a scenario.
#[derive(Clone, Copy, Debug)]
pub enum Boundary<T, const D: usize> {
    /// Elastic walls at `lo` and `hi` in every dimension.
    Reflecting { lo: [T; D], hi: [T; D] },
    /// Unbounded space: particles go anywhere; the bounding box is tracked each step.
    Open,
}

#[derive(Debug, Error, PartialEq)]
pub enum BoundaryError {
    #[error(
        "step {step}: particle {id} is still outside the box after one reflection \
         (coordinate {dim} = {value}); the time step is too large for these velocities — reduce --dt"
    )]
    MultipleReflection {
        step: u64,
        id: u32,
        dim: usize,
        value: f64,
    },
    #[error(
        "step {step}: particle {id} has a non-finite position; the simulation blew up — \
         reduce --dt or check the initial state"
    )]
    NonFinite { step: u64, id: u32 },
}

impl<T: Real, const D: usize> Boundary<T, D> {
    /// Applies the boundary after a drift and returns the particles' bounding box.
    pub fn apply(
        &self,
        state: &mut State<T, D>,
        step: u64,
    ) -> Result<([T; D], [T; D]), BoundaryError> {
        match *self {
            Boundary::Reflecting { lo, hi } => {
                for d in 0..D {
                    let (lo, hi) = (lo[d], hi[d]);
                    let two = T::one() + T::one();
                    let mut bad = false;
                    for (x, v) in state.pos[d].iter_mut().zip(state.vel[d].iter_mut()) {
                        // Written with selects, not branches: almost no particle is at a wall.
                        let below = *x < lo;
                        let above = *x > hi;
                        let nx = select(below, two * lo - *x, select(above, two * hi - *x, *x));
                        *v = select(below | above, -*v, *v);
                        *x = nx;
                        bad |= !(nx >= lo && nx <= hi);
                    }
                    if bad {
                        return Err(first_offender(state, step, d, |x| !(x >= lo && x <= hi)));
                    }
                }
                Ok((lo, hi))
            }
            Boundary::Open => {
                let (lo, hi) = state.bounding_box();
                // No particle, nothing to check (a rank of a distributed run may own none).
                if state.is_empty() {
                    return Ok((lo, hi));
                }
                for d in 0..D {
                    // min/max skip NaN, so test finiteness separately: x·0 is NaN for NaN and ±∞.
                    let poison = state.pos[d]
                        .iter()
                        .fold(T::zero(), |acc, &x| acc + x * T::zero());
                    if !(lo[d].is_finite() && hi[d].is_finite() && poison.is_finite()) {
                        return Err(first_offender(state, step, d, |x| !x.is_finite()));
                    }
                }
                Ok((lo, hi))
            }
        }
    }
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
    fn open_boundary_reports_bounding_box() {
        let mut s = State::<f64, 2>::new(2);
        s.pos = [vec![-3.0, 4.0], vec![1.0, -2.0]];
        let (lo, hi) = Boundary::<f64, 2>::Open.apply(&mut s, 0).unwrap();
        assert_eq!((lo, hi), ([-3.0, -2.0], [4.0, 1.0]));
        // A rank of a distributed run may own no particle: nothing to report, no error.
        let mut none = State::<f64, 2>::new(0);
        assert!(Boundary::<f64, 2>::Open.apply(&mut none, 0).is_ok());
    }
}
