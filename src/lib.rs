//! nbody-bench: a harness that measures how N-body force kernels and other programs scale.
//!
//! The simulation (kernels, scenarios, measured runs, force checks) is the `nbody-engine`
//! crate, re-exported here under the same module names ([`kernels`], [`scenario`], [`run`],
//! ...). This crate adds, bottom up: [`stats`]-based [`fit`]s of scaling models and the
//! machine's [`calibrate`]d peaks; the [`experiment`] runner (plans, rounds, results files,
//! external programs, launchers); the [`analysis`] of results, its [`render`]ing to tables and
//! [`plot`]s, the [`report`] and the regression [`gate`]; the MPI drivers ([`mpi`], feature
//! `mpi`). The command line is the binary crate's (`src/main.rs`, `src/cli/`), so nothing here
//! can depend on it.

// First, so that its `outln!` and `out!` macros are in scope in every module below.
#[macro_use]
pub mod console;

pub use nbody_engine::{
    boundary, clock, decomp, engine, export, geometry, input, integrator, kernels, output, par,
    physics, real, run, scenario, simd, state, stats, stepper, validate,
};

pub mod analysis;
pub mod calibrate;
pub mod children;
pub mod experiment;
pub mod fit;
pub mod gate;
pub mod history;
#[cfg(feature = "mpi")]
pub use nbody_mpi::mpi;
pub use nbody_mpi::ranks;
pub mod plot;
pub mod records;
pub mod render;
pub mod report;
pub mod units;
