//! nbody-bench: an engine of interchangeable N-body force kernels and a harness that measures
//! how they scale.
//!
//! Layers, bottom up: [`real`], [`simd`] and [`par`] (precision, instruction set, threads), [`state`] and
//! [`physics`] (particles and pair laws), [`kernels`] (ways of visiting the pairs),
//! [`scenario`], [`integrator`], [`boundary`] and [`engine`] (a running simulation),
//! [`run`] and [`validate`] (measured runs and force checks), [`output`]; above them the
//! experiment runner, the analysis, its rendering and the gate. The command line is the binary
//! crate's (`src/main.rs`, `src/cli/`), so nothing here can depend on it.

// First, so that its `outln!` and `out!` macros are in scope in every module below.
#[macro_use]
pub mod console;

pub mod analysis;
pub mod boundary;
pub mod calibrate;
pub mod children;
pub mod clock;
pub mod decomp;
pub mod engine;
pub mod experiment;
pub mod export;
pub mod fit;
pub mod gate;
pub mod input;
pub mod integrator;
pub mod kernels;
#[cfg(feature = "mpi")]
pub mod mpi;
pub mod output;
pub mod par;
pub mod physics;
pub mod plot;
pub mod real;
pub mod render;
pub mod report;
pub mod run;
pub mod scenario;
pub mod simd;
pub mod state;
pub mod stats;
#[doc(hidden)]
pub mod testing;
pub mod units;
pub mod validate;
