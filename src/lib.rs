//! nbody-bench: an engine of interchangeable N-body force kernels and a harness that measures
//! how they scale.

pub mod kernels;
pub mod physics;
pub mod real;
pub mod simd;
pub mod state;
#[doc(hidden)]
pub mod testing;
