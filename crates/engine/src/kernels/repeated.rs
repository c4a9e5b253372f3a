//! A kernel made slower on purpose: every timed force computation takes `factor` times as
//! long, with the forces and work counters of one computation. The whole part of the factor
//! repeats the computation, a fractional part spins for that share of the last repetition's
//! time, so a factor of 1.2 is a 20 % slower force computation (the step, which also
//! integrates, slows a little less). The regression gate's tests use it (through the
//! harness's `NBODY_BENCH_TEST_SLOWDOWN`) to have a genuinely slower build to find.

use super::decorator::KernelDecorator;
use super::{ForceKernel, ForceReport, KernelKind};
use crate::real::Real;
use crate::state::{Field, State};

/// Each timed force computation `.0` times as long: the decorator a stepper is built with
/// (`stepper::decorated_stepper`) to be a genuinely slower build for the gate's tests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Repeat(pub f64);

impl KernelDecorator for Repeat {
    fn decorate<T: Real, const D: usize>(
        self,
        kernel: Box<dyn ForceKernel<T, D>>,
    ) -> Box<dyn ForceKernel<T, D>> {
        repeated(kernel, self.0)
    }
}

/// `inner` made `factor` times as slow when `factor` > 1, else `inner` itself.
pub fn repeated<T: Real, const D: usize>(
    inner: Box<dyn ForceKernel<T, D>>,
    factor: f64,
) -> Box<dyn ForceKernel<T, D>> {
    if factor > 1.0 {
        Box::new(Repeated { inner, factor })
    } else {
        inner
    }
}

/// A kernel whose timed computations take `factor` times as long; probes (untimed) run once.
struct Repeated<T: Real, const D: usize> {
    inner: Box<dyn ForceKernel<T, D>>,
    factor: f64,
}

impl<T: Real, const D: usize> ForceKernel<T, D> for Repeated<T, D> {
    fn kind(&self) -> KernelKind {
        self.inner.kind()
    }

    fn compute(
        &mut self,
        state: &State<T, D>,
        forces: &mut Field<T, D>,
        probe: bool,
    ) -> ForceReport {
        if probe {
            return self.inner.compute(state, forces, true);
        }
        let whole = self.factor.floor();
        for _ in 1..whole as u32 {
            self.inner.compute(state, forces, false);
        }
        let start = std::time::Instant::now();
        let report = self.inner.compute(state, forces, false);
        let extra = start.elapsed().mul_f64(self.factor - whole);
        let spin = std::time::Instant::now();
        while spin.elapsed() < extra {
            std::hint::spin_loop();
        }
        report
    }

    fn spatial_order(&mut self, state: &State<T, D>) -> Option<Vec<u32>> {
        self.inner.spatial_order(state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernels::KernelParams;
    use crate::physics::Gravity;
    use crate::state::zero_field;
    use crate::testing::{SEED_1, random_state};

    #[test]
    fn keeps_the_kind_forces_and_work_of_one_computation() {
        let law = Gravity::<f64>::new(1.0, 0.05);
        let state = random_state::<f64, 3>(64, 1.0, false, SEED_1);
        let build = || {
            KernelKind::Symmetric
                .build::<f64, _, 3>(law, &KernelParams::default())
                .unwrap()
        };
        let mut plain = build();
        let mut slow = repeated(build(), 3.0);
        assert_eq!(slow.kind(), KernelKind::Symmetric);
        let (mut f1, mut f2) = (zero_field::<f64, 3>(64), zero_field::<f64, 3>(64));
        let a = plain.compute(&state, &mut f1, false);
        let b = slow.compute(&state, &mut f2, false);
        assert_eq!(a.work, b.work, "work counters of one computation");
        assert_eq!(f1, f2);
        let p = slow.compute(&state, &mut f2, true);
        assert_eq!(p.work, plain.compute(&state, &mut f1, true).work);
    }
}
