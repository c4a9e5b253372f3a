//! What a stepper does to the kernel it has built before the simulation takes it
//! (`stepper::decorated_stepper`): nothing ([`Plain`]), or, in the regression gate's test
//! builds only, make its force computations slower (`repeated::Repeat`, feature
//! `test-slowdown`).

use super::ForceKernel;
use crate::real::Real;

/// A wrapper around a built kernel.
pub trait KernelDecorator: Copy {
    /// The kernel the simulation runs instead of `kernel`.
    fn decorate<T: Real, const D: usize>(
        self,
        kernel: Box<dyn ForceKernel<T, D>>,
    ) -> Box<dyn ForceKernel<T, D>>;
}

/// The kernel as built.
#[derive(Clone, Copy, Debug)]
pub struct Plain;

impl KernelDecorator for Plain {
    fn decorate<T: Real, const D: usize>(
        self,
        kernel: Box<dyn ForceKernel<T, D>>,
    ) -> Box<dyn ForceKernel<T, D>> {
        kernel
    }
}
