//! The kernels of the systems the scenarios build, compiled once, here.
//!
//! A generic function is compiled again in every crate that instantiates it, and every kernel
//! behind [`KernelKind::build`] is a few thousand lines of pair loops per law, precision and
//! dimension. The laws below build their kernels through a method that is not generic, so a
//! crate that builds kernels (the MPI drivers, the integration tests) links to the code
//! compiled here instead of compiling every kernel for every system type again.

use super::{ForceKernel, KernelError, KernelKind, KernelParams};
use crate::physics::{Coulomb, Gravity, LennardJones, PairLaw};
use crate::real::Real;

/// A pair law in `D` dimensions whose kernels this crate compiles: the laws and dimensions of
/// the scenarios (Lennard-Jones in 2-D and 3-D, Coulomb and gravity in 3-D), in f32 and f64.
pub trait CompiledKernels<T: Real, const D: usize>: PairLaw<T> {
    /// The kernel `kind` for this law, or why the combination does not exist.
    fn build_kernel(
        self,
        kind: KernelKind,
        params: &KernelParams,
    ) -> Result<Box<dyn ForceKernel<T, D>>, KernelError>;
}

macro_rules! compiled {
    ($($law:ident<$t:ty>, $d:literal;)*) => {$(
        impl CompiledKernels<$t, $d> for $law<$t> {
            // Never inlined into a caller: that would compile the kernels there again.
            #[inline(never)]
            fn build_kernel(
                self,
                kind: KernelKind,
                params: &KernelParams,
            ) -> Result<Box<dyn ForceKernel<$t, $d>>, KernelError> {
                kind.instantiate::<$t, Self, $d>(self, params)
            }
        }
    )*};
}

compiled! {
    LennardJones<f32>, 2;
    LennardJones<f64>, 2;
    LennardJones<f32>, 3;
    LennardJones<f64>, 3;
    Coulomb<f32>, 3;
    Coulomb<f64>, 3;
    Gravity<f32>, 3;
    Gravity<f64>, 3;
}
